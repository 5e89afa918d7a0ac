"""The same study gives the same rows, bit for bit (every column but cpu_s), serially in this
process, on a LocalCluster and on a real multi-process cluster on localhost; a worker killed in
the middle of a study costs no point; an interrupted study resumes where it stopped."""

import os
import signal
import subprocess
import time

from gearrattle.study.engine import batches
from support.study import STUDY, assert_same_rows, rows, study

# A small map in sine mode: 4 x 3 points of 0.3 s (statistics from 0.15 s, half the duration).
SMALL = ["map", "--x", "f_exc=30:60:4", "--y", "A_rms=100:500:3", "--duration", "0.3",
         "--record", "impacts_Fplus", "--record", "impacts_Fminus", "--record", "xi",
         "--record", "E_contact"]
# Long enough to be interrupted: 240 points of 4 s (about 10 ms of CPU each).
LONG = ["doe", "--param", "f_exc=30:60", "--param", "A_rms=100:700", "--design", "lhs",
        "--n", "240", "--duration", "4", "--record", "impacts_Fplus", "--record", "xi"]


def test_serial_local_cluster_and_localhost_cluster_agree(fmu, cluster, tmp_path):
    outs = {k: str(tmp_path / k) for k in ("serial", "local", "cluster")}
    study(*SMALL, "--fmu", fmu, "--out", outs["serial"], "--workers", "0")
    study(*SMALL, "--fmu", fmu, "--out", outs["local"], "--workers", "2")
    study(*SMALL, "--fmu", fmu, "--out", outs["cluster"], "--scheduler", cluster.address)
    ref = rows(outs["serial"])
    assert ref.num_rows == 12
    assert set(ref.column("status").to_pylist()) == {"ok"}
    assert_same_rows(rows(outs["local"]), ref)
    assert_same_rows(rows(outs["cluster"]), ref)


def _partials(out):
    d = os.path.join(out, "partial")
    return [f for f in os.listdir(d) if f.endswith(".parquet")] if os.path.isdir(d) else []


def _start_and_wait(args, out, n_files):
    """Start the study in the background; return it once n_files batches are stored."""
    p = subprocess.Popen([str(STUDY), *args, "--quiet"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while len(_partials(out)) < n_files:
        assert p.poll() is None, f"the study ended before it could be interrupted:\n{p.stderr.read()}"
        assert time.monotonic() < deadline, "no batch stored in 120 s"
        time.sleep(0.02)
    return p


def test_worker_killed_mid_study_loses_no_point(fmu, cluster, tmp_path):
    ref, out = str(tmp_path / "undisturbed"), str(tmp_path / "killed")
    study(*LONG, "--fmu", fmu, "--out", ref, "--workers", "0")
    victim = cluster.worker_pids()[0]
    p = _start_and_wait([*LONG, "--fmu", fmu, "--out", out, "--scheduler", cluster.address],
                        out, 2)
    os.kill(victim, signal.SIGKILL)
    stored_at_kill = len(_partials(out))
    _, err = p.communicate(timeout=300)
    assert p.returncode == 0, err[-3000:]
    assert stored_at_kill < len(batches(range(240), 2))  # the kill came mid-study
    got = rows(out)
    assert got.num_rows == 240
    assert_same_rows(got, rows(ref))
    cluster.wait_for_workers(2)  # the nanny restarted the killed worker
    assert victim not in cluster.worker_pids()


def test_interrupted_study_resumes_without_recomputing(fmu, tmp_path):
    ref, out = str(tmp_path / "whole"), str(tmp_path / "interrupted")
    study(*LONG, "--fmu", fmu, "--out", ref, "--workers", "0")
    p = _start_and_wait([*LONG, "--fmu", fmu, "--out", out, "--workers", "0"], out, 1)
    p.send_signal(signal.SIGKILL)
    p.wait(timeout=30)
    kept = len(_partials(out))
    assert not os.path.exists(os.path.join(out, "points.parquet"))
    again = subprocess.run([str(STUDY), *LONG, "--fmu", fmu, "--out", out, "--workers", "0"],
                           capture_output=True, text=True, timeout=300)
    assert again.returncode == 0, again.stderr[-3000:]
    assert "points already in" in again.stdout
    assert_same_rows(rows(out), rows(ref))
    assert len(_partials(out)) > kept


def _without_range(fmu, name, path):
    """A copy of the FMU whose model description states no range for `name` (neither min nor
    the description's statement): the study's checks let any value of it through, and the
    FMU's own check refuses the invalid ones."""
    import xml.etree.ElementTree as ET
    import zipfile

    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(path, "w") as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "modelDescription.xml":
                root = ET.fromstring(data)
                v = root.find(f"ModelVariables/ScalarVariable[@name='{name}']")
                v.set("description", v.get("description").split(" (range: ")[0])
                v[0].attrib.pop("min")
                data = ET.tostring(root, encoding="utf-8", xml_declaration=True)
            dst.writestr(item, data)
    return str(path)


def test_refused_points_are_rows_with_the_fmu_message(fmu, tmp_path):
    """G <= 0 passes the study's checks of an FMU that states no range for G, and the FMU
    refuses it: the point is a row with status refused and the FMU's message, the others are
    computed."""
    out = str(tmp_path / "doe")
    bare = _without_range(fmu, "G", tmp_path / "bare.fmu")
    study("doe", "--fmu", bare, "--out", out, "--workers", "0", "--param", "G=-1e-5:5e-5",
          "--design", "full", "--n", "4", "--duration", "0.2")
    t = rows(out).to_pylist()
    assert [r["status"] for r in t] == ["refused", "ok", "ok", "ok"]
    assert "G" in t[0]["message"] and "invalid" in t[0]["message"], t[0]["message"]