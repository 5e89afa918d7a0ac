"""Helpers of the study runner's tests (their fixtures are in tests/study/conftest.py): the
`gearrattle-study` command run as a user runs it, its results read back, and a real Dask
cluster on localhost (`dask scheduler` and two `dask worker` processes)."""

import os
import pathlib
import socket
import subprocess
import sys

import pyarrow.parquet as pq

BIN = pathlib.Path(sys.executable).parent
STUDY = BIN / "gearrattle-study"


def study(*args, check=True, **kw):
    """Run gearrattle-study with these arguments; the finished process."""
    p = subprocess.run([str(STUDY), *map(str, args), "--quiet"], capture_output=True,
                       text=True, timeout=300, **kw)
    if check and p.returncode != 0:
        raise AssertionError(f"gearrattle-study {' '.join(map(str, args))} failed "
                             f"({p.returncode}):\n{p.stderr[-3000:]}")
    return p


def rows(out):
    """The study's points without cpu_s (the one column allowed to differ between runs)."""
    return pq.read_table(os.path.join(out, "points.parquet")).drop(["cpu_s"])


def assert_same_rows(got, want):
    """Equal tables, or a message naming the first point and columns that differ."""
    if got.equals(want):
        return
    a, b = got.to_pylist(), want.to_pylist()
    assert len(a) == len(b), f"{len(a)} rows, expected {len(b)}"
    for x, y in zip(a, b):
        diff = {k: (x.get(k), y[k]) for k in y
                if x.get(k) != y[k] and not (x.get(k) != x.get(k) and y[k] != y[k])}  # NaN
        assert not diff, f"point {y['point']} differs (got, expected): {diff}"


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class LocalhostCluster:
    """`dask scheduler` and two `dask worker` processes on 127.0.0.1, each worker in its own
    empty directory (the FMU reaches them through the runner, not through a shared file)."""

    def __init__(self, tmp):
        self.port = free_port()
        self.address = f"tcp://127.0.0.1:{self.port}"
        dask = str(BIN / "dask")
        self.procs = [subprocess.Popen(
            [dask, "scheduler", "--host", "127.0.0.1", "--port", str(self.port),
             "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
        for k in range(2):
            cwd = tmp / f"worker{k}"
            cwd.mkdir()
            self.procs.append(subprocess.Popen(
                [dask, "worker", self.address, "--nworkers", "1", "--nthreads", "1",
                 "--host", "127.0.0.1", "--no-dashboard", "--local-directory", str(cwd)],
                cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        self.wait_for_workers(2)

    def client(self):
        from distributed import Client

        return Client(self.address, timeout="30s")

    def wait_for_workers(self, n, timeout=60):
        with self.client() as c:
            c.wait_for_workers(n, timeout=timeout)

    def worker_pids(self):
        with self.client() as c:
            return list(c.run(os.getpid).values())

    def close(self):
        for p in reversed(self.procs):
            p.terminate()
        for p in self.procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
