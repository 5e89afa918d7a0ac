"""Runs a validated study: its points in batches on Dask distributed (a LocalCluster with one
single-threaded worker process per core, or the cluster at --scheduler), or serially in this
process (workers = 0). Completed batches are stored as they arrive; points already stored are
skipped."""

import logging
import math
import os

from . import designs, results
from .model import STATS_FROM
from .worker import FMUPlugin, install_fmu, run_batch
from ..progress import Progress

TASKS_PER_WORKER = 8  # batches per worker: balances the load and bounds what a lost worker costs
BATCH_MAX = 100  # points per batch at most (about 0.3 s of work on one core)


class Plan:
    """The study's points with their full start values, identities and the result columns."""

    def __init__(self, st, model):
        self.st, self.model = st, model
        fixed = {n: v for n, (v, _) in st.fixed.items()}
        if st.stats_from is not None:
            fixed[STATS_FROM] = st.stats_from[0]
        varied = designs.points(st)
        self.values = [{**p, **fixed} for p in varied]
        names = list(varied[0]) if varied else []
        self.param_names = names + [n for n in fixed if n not in names]
        self.ids = [results.point_id(v, model.guid, st.duration) for v in self.values]
        self.schema = results.schema(self.param_names, model, st.record)

    def row(self, index, worker_row):
        """A complete result row: the worker's metrics and status with the point's values."""
        return {**worker_row, **self.values[index], "point": index, "duration": self.st.duration,
                "guid": self.model.guid, "point_id": self.ids[index]}


def batch_size(n_points, n_workers):
    return max(1, min(BATCH_MAX, math.ceil(n_points / (TASKS_PER_WORKER * max(n_workers, 1)))))


def execute(st, model, fmu_bytes, quiet=False):
    """Run what is missing of the study; return the consolidated pyarrow table."""
    plan = Plan(st, model)
    store = results.Store(st.out)
    done = store.done()
    todo, seen = [], set()
    for i, pid in enumerate(plan.ids):
        if pid not in done and pid not in seen:
            seen.add(pid)
            todo.append((i, pid, plan.values[i]))
    if not quiet and done:
        print(f"gearrattle-study: {len(plan.ids) - len(todo)} of {len(plan.ids)} points already "
              f"in {st.out}: running the other {len(todo)}", flush=True)
    computed = {}
    if todo:
        bar = None if quiet else Progress(len(todo), f"{st.kind} study")

        def store_batch(rows):
            full = [plan.row(r["point"], r) for r in rows]
            store.append(full, plan.schema)
            computed.update((r["point_id"], r) for r in full)
            if bar:
                refused = sum(r["status"] != "ok" for r in full)
                bar.update(len(full), f"{refused} refused" if refused else "")

        run = _run_serial if st.workers == 0 else _run_dask
        run(st, model, fmu_bytes, todo, store_batch)
        if bar:
            bar.close()
    rows = [dict(done.get(pid) or computed[pid]) for pid in plan.ids]
    for i, r in enumerate(rows):  # a stored point may sit at another index in this design
        r["point"] = i
    return store.consolidate(rows, plan.schema)


def _batches(todo, size):
    return [todo[k:k + size] for k in range(0, len(todo), size)]


def _run_serial(st, model, fmu_bytes, todo, store_batch):
    install_fmu(model.guid, fmu_bytes)
    for batch in _batches(todo, batch_size(len(todo), 1)):
        store_batch(run_batch(model.guid, st.duration, tuple(st.record), batch))


def _run_dask(st, model, fmu_bytes, todo, store_batch):
    from distributed import Client, LocalCluster, as_completed

    cluster = None
    if st.scheduler:
        client = Client(st.scheduler, timeout="30s")
    else:
        n = st.workers or os.cpu_count() or 1
        # no dashboards (no port to find); the study reports its own errors
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=None, worker_dashboard_address=None,
                               silence_logs=logging.CRITICAL)
        client = Client(cluster)
    try:
        plug = FMUPlugin(model.guid, fmu_bytes)
        client.register_plugin(plug)
        n_workers = max(len(client.scheduler_info()["workers"]), 1)
        record = tuple(st.record)
        futures = [client.submit(run_batch, model.guid, st.duration, record, b, pure=False,
                                 key=f"gearrattle-batch-{b[0][1]}-{len(b)}")
                   for b in _batches(todo, batch_size(len(todo), n_workers))]
        for fut in as_completed(futures):
            store_batch(fut.result())
        client.unregister_worker_plugin(plug.name)
    finally:
        client.close()
        if cluster is not None:
            cluster.close(timeout=10)
