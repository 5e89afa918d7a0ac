"""make bench-study: the study runner measured beside the sampled engine and the FMU stepped
from C, side by side in one run on this machine. Prints the figures and writes them, with the
machine and the commands, to --report (docs/STUDY_BENCH.md) and a figure beside it.

    .venv/bin/python benches/study/study_bench.py --fmu target/fmu/GearRattle.fmu \\
        --out target/bench-study --report docs/STUDY_BENCH.md

1. CPU per point on the paper's map grid (16 x 13, 1 s, statistics from 0.2 s): the sampled engine
   (fmpy's simulate_fmu sampling every 50 us, statistics from the samples:
   gearrattle.study.sampled) against the runner (`gearrattle-study map`, all its processes'
   CPU, start-up included, over the points), with the impact counts and run lengths compared
   point by point.
2. The runner's CPU per point (the worker's time.process_time around a point) against the same
   points stepped from C alone (step_points.c beside this file: one instance, the same calls).
3. A 10 000-point tolerance Monte Carlo of S1 (G, I_L, C, K_star varied) on 2 workers: wall time
   with the cluster's start-up.
4. The map on a grid four times finer (32 x 26 = 832 points): the sampled engine (2 processes) and
   the runner (2 workers), wall time with start-up.
5. Throughput (points per second, cluster already up) with 2 workers against 1: the median of
   PAIRS pairs, each measured one right after the other."""

import argparse
import os
import platform
import resource
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile

import numpy as np
import pyarrow.parquet as pq

from gearrattle.study import engine, sampled, spec
from gearrattle.study.model import read_model

GRID = ("f_exc=30:60:16", "A_rms=100:700:13")
FINE = ("f_exc=30:60:32", "A_rms=100:700:26")
S1 = {"excitation": 1, "f_exc": 30.0, "A_rms": 300.0}
TOLERANCES = ["G=truncnormal:25e-6:1.67e-6:20e-6:30e-6", "I_L=normal:0.32e-3:0.0064e-3",
              "C=normal:0.025:0.00167", "K_star=normal:3e6:0.1e6"]
T_FROM, DURATION = 0.2, 1.0
PAIRS = 3  # throughput pairs (1 worker, then 2): the machine's noise moves one ratio by +-0.05
HERE = os.path.dirname(os.path.abspath(__file__))
STUDY = os.path.join(os.path.dirname(sys.executable), "gearrattle-study")


def study(args, out):
    """Run gearrattle-study in a child process: (wall s, CPU s of it and all its children)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run([STUDY, *args, "--out", out, "--quiet"], capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if p.returncode:
        sys.exit(f"gearrattle-study {' '.join(args)} failed:\n{p.stderr[-3000:]}")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def grid_values(x, y):
    st = spec.Study(kind="map", fmu="", out="")
    st.axes = [spec.parse_axis(x, "x"), spec.parse_axis(y, "y")]
    return [{"excitation": 1, **p} for p in __import__(
        "gearrattle.study.designs", fromlist=["points"]).points(st)]


def run_sampled(fmu_dir, points, workers):
    """The sampled engine (gearrattle.study.sampled) over the points on `workers` processes:
    (statistics, CPU s, wall s)."""
    t0 = time.perf_counter()
    stats, cpu = sampled.run(fmu_dir, points, workers, DURATION, T_FROM)
    return stats, np.array(cpu), time.perf_counter() - t0


def from_c(fmu, fmu_dir, model, table, params, metrics, tmp):
    """The table's points stepped from C: (CPU s of the points, outputs per point)."""
    exe = os.path.join(tmp, "step_points")
    subprocess.run(["cc", "-O2", "-o", exe, os.path.join(HERE, "step_points.c"), "-ldl"],
                   check=True)
    lib = os.path.join(fmu_dir, "binaries", "linux64", model.model_identifier + ".so")
    P = model.parameters
    real = [n for n in params if P[n].type == "Real"]
    ints = [n for n in params if P[n].type != "Real"]
    mr = [m for m in metrics if model.outputs[m].type == "Real"]
    mi = [m for m in metrics if model.outputs[m].type != "Real"]
    lines = [" ".join(map(str, [len(v)] + [vr for vr in w])) for v, w in (
        (real, [P[n].vr for n in real]), (ints, [P[n].vr for n in ints]),
        (mr, [model.outputs[m].vr for m in mr]), (mi, [model.outputs[m].vr for m in mi]))]
    lines.append(repr(DURATION))
    cols = {n: table.column(n).to_pylist() for n in real + ints}
    for i in range(table.num_rows):
        lines.append(" ".join([repr(float(cols[n][i])) for n in real]
                              + [str(int(cols[n][i])) for n in ints]))
    uri = "file://" + os.path.join(fmu_dir, "resources")
    p = subprocess.run([exe, lib, model.guid, uri], input="\n".join(lines) + "\n",
                       capture_output=True, text=True, check=True)
    out = p.stdout.strip().splitlines()
    cpu = float(out[-1].split()[1])
    return cpu, [dict(zip(mr + mi, map(float, line.split()))) for line in out[:-1]]


def idle_share(seconds=2.0):
    """CPU of this process and its children (the local cluster) over `seconds` of doing
    nothing, as a share of one core: what the cluster's own housekeeping takes from the points."""
    import psutil

    procs = [psutil.Process()] + psutil.Process().children(recursive=True)
    cpu = lambda: sum(sum(p.cpu_times()[:2]) for p in procs)  # noqa: E731
    c0 = cpu()
    time.sleep(seconds)
    return (cpu() - c0) / seconds


def throughput(fmu, workers, n, tmp):
    """Points per second of an mc study of n points once the cluster is up, the share of the
    wall time the workers spent inside the points (below 1: waiting, or starved of a core by
    other processes on the machine), and the idle cluster's CPU as a share of one core."""
    st = spec.Study(kind="mc", fmu=fmu, out=os.path.join(tmp, f"tp{workers}"), n=n, seed=7,
                    workers=workers)
    st.dists = [spec.parse_dist(t, t) for t in TOLERANCES]
    st.fixed = {k: (float(v), "S1") for k, v in S1.items()}
    model = read_model(fmu)
    spec.validate(st, model)
    data = open(fmu, "rb").read()
    with engine.Session(st, model, data) as s:
        engine.execute(st, model, data, quiet=True, session=s,
                       points=[{"G": 25e-6 + 1e-9 * k} for k in range(2 * workers)])  # warm-up
        idle = idle_share()
        st.out += "-run"
        t0 = time.perf_counter()
        table = engine.execute(st, model, data, quiet=True, session=s)
        wall = time.perf_counter() - t0
    busy = sum(table.column("cpu_s").to_pylist()) / (wall * workers)
    return n / wall, busy, idle


def compare(table, stats):
    """Impact counts and run lengths, runner against the sampled engine, point by point."""
    ok = np.array(table.column("status").to_pylist()) == "ok"
    col = {n: np.array(table.column(n).to_pylist(), dtype=float) for n in
           ("stat_impacts_Fplus", "stat_impacts_Fminus", "stat_run_max_Fplus",
            "stat_run_max_Fminus", "stat_run_mean_Fplus", "stat_run_mean_Fminus")}
    n = len(stats)
    same_counts = sum(ok[i] and col["stat_impacts_Fplus"][i] == s["impacts_Fplus"]
                      and col["stat_impacts_Fminus"][i] == s["impacts_Fminus"]
                      for i, s in enumerate(stats))
    run_max = np.maximum(col["stat_run_max_Fplus"], col["stat_run_max_Fminus"])
    same_max = sum(ok[i] and run_max[i] == s["run_max"] for i, s in enumerate(stats))
    dmean = []
    for i, s in enumerate(stats):
        for fl in ("Fplus", "Fminus"):
            a, b = col[f"stat_run_mean_{fl}"][i], s[f"mean_run_{fl}"]
            if np.isfinite(a) and np.isfinite(b):
                dmean.append(abs(a - b))
    return n, same_counts, same_max, max(dmean) if dmean else float("nan")


def figure(path, rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 3.6), constrained_layout=True)
    labels, values = zip(*rows)
    ax.barh(range(len(values)), [1e3 * v for v in values], color="tab:blue")
    ax.set_yticks(range(len(values)))
    ax.set_yticklabels(labels, fontsize=8)
    ax.set_xscale("log")
    ax.set_xlabel("CPU per 1-s point [ms] (log scale)")
    for k, v in enumerate(values):
        ax.text(1e3 * v, k, f" {1e3 * v:.2f} ms", va="center", fontsize=8)
    ax.invert_yaxis()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fmu", default=os.path.join("target", "fmu", "GearRattle.fmu"))
    ap.add_argument("--out", default=os.path.join("target", "bench-study"))
    ap.add_argument("--report", default=os.path.join("docs", "STUDY_BENCH.md"))
    a = ap.parse_args(argv)
    model = read_model(a.fmu)
    if "stat_impacts_Fplus" not in model.outputs:
        sys.exit(f"{a.fmu} has no stat_* outputs: rebuild it (make fmu)")
    shutil.rmtree(a.out, ignore_errors=True)
    os.makedirs(a.out)
    load0 = open("/proc/loadavg").read().split()[:3]
    tmp = tempfile.mkdtemp(prefix="bench-study-")
    fmu_dir = os.path.join(tmp, "fmu")
    zipfile.ZipFile(a.fmu).extractall(fmu_dir)
    L = []

    def say(line):
        print(line, flush=True)
        L.append(line)

    metrics = [v.name for v in model.metrics]
    grid = grid_values(*GRID)
    base = ["--fmu", a.fmu, "--duration", str(DURATION), "--stats-from", str(T_FROM)]
    # 1. the sampled engine and the runner on the paper's grid
    stats, cpu_sampled, _ = run_sampled(fmu_dir, grid, 2)
    out1 = os.path.join(a.out, "map")
    wall_map, cpu_map = study(["map", *base, "--x", GRID[0], "--y", GRID[1], "--workers", "2"],
                              out1)
    table = pq.read_table(os.path.join(out1, "points.parquet"))
    per_point_runner = cpu_map / len(grid)
    n, same_counts, same_max, dmean = compare(table, stats)
    cpu_pt = np.array(table.column("cpu_s").to_pylist())
    # 2. the same points from C
    params = [n_ for n_ in table.schema.names if n_ in model.parameters]
    cpu_c, c_out = from_c(a.fmu, fmu_dir, model, table, params, metrics, tmp)
    c_same = sum(all(r[m] == float(table.column(m)[i].as_py()) for m in metrics)
                 for i, r in enumerate(c_out))
    # 3. the 10 000-point tolerance Monte Carlo of S1
    mc = ["mc", *base, *sum((["--dist", t] for t in TOLERANCES), []),
          *sum((["--set", f"{k}={v}"] for k, v in S1.items()), []), "--n", "10000",
          "--seed", "1", "--workers", "2", "--exceed", "stat_regime>0"]
    wall_mc, cpu_mc = study(mc, os.path.join(a.out, "mc"))
    # 4. the finer map: the sampled engine on 2 processes, the runner on 2 workers
    fine = grid_values(*FINE)
    _, cpu_fine_sampled, wall_fine_sampled = run_sampled(fmu_dir, fine, 2)
    wall_fine, _ = study(["map", *base, "--x", FINE[0], "--y", FINE[1], "--workers", "2"],
                         os.path.join(a.out, "fine"))
    # 5. throughput, 2 workers against 1
    pairs = [(throughput(a.fmu, 1, 2000, os.path.join(tmp, f"pair{k}")),
              throughput(a.fmu, 2, 2000, os.path.join(tmp, f"pair{k}"))) for k in range(PAIRS)]
    ratios = [two[0] / one[0] for one, two in pairs]
    (tp1, busy1, _), (tp2, busy2, idle2) = pairs[int(np.argsort(ratios)[len(ratios) // 2])]
    load1 = open("/proc/loadavg").read().split()[:3]
    shutil.rmtree(tmp, ignore_errors=True)

    def verdict(ok):
        return "met" if ok else "NOT met"

    r1 = np.mean(cpu_sampled) / per_point_runner
    r2 = (cpu_c and np.sum(cpu_pt) / cpu_c)
    say("# Study runner benchmark")
    say("")
    say("Generated by `make bench-study` (benches/study/study_bench.py); do not edit by hand. "
        f"Machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; load "
        f"average {' '.join(load0)} at the start, {' '.join(load1)} at the end (the machine "
        f"is shared: wall times move with the load). FMU GUID {model.guid}.")
    say("")
    say("| measure | figure | target | verdict |")
    say("|---|---|---|---|")
    say(f"| CPU per 1-s point, paper's grid (208 points): the sampled engine (fmpy every 50 us, "
        f"statistics from samples) | {1e3 * np.mean(cpu_sampled):.1f} ms | | |")
    say(f"| the runner's CPU per point in the worker (reset to outputs read, mean) | "
        f"{1e3 * np.mean(cpu_pt):.2f} ms: {np.mean(cpu_sampled) / np.mean(cpu_pt):.0f}x less | "
        f">= 20x less | {verdict(np.mean(cpu_sampled) / np.mean(cpu_pt) >= 20)} |")
    say(f"| the runner, all its processes' CPU with start-up and figures, over the 208 points "
        f"(`gearrattle-study map`, 2 workers) | {1e3 * per_point_runner:.2f} ms: "
        f"{r1:.1f}x less (start-up and figures are most of it at 208 points) | | |")
    say(f"| same impact counts (both flanks) as the sampled engine | {same_counts} of {n} points | "
        f"every point | {verdict(same_counts == n)} |")
    say(f"| same longest run as the sampled engine | {same_max} of {n} points; mean run per flank "
        f"differs by at most {dmean:.3g} | every point | {verdict(same_max == n)} |")
    say(f"| the same 208 points stepped from C alone (one instance, the same calls) | "
        f"{1e3 * cpu_c / n:.2f} ms; outputs bit-identical to the runner's at {c_same} of {n} "
        f"points | | |")
    say(f"| runner's per-point CPU / C's | {r2:.2f} | <= 1.5 | {verdict(r2 <= 1.5)} |")
    say(f"| all-in CPU per point / C's (Dask, Python and start-up spread over 208 points) | "
        f"{per_point_runner / (cpu_c / n):.2f} | | |")
    say(f"| all-in CPU per point of the 10 000-point Monte Carlo below (every process, start-up "
        f"and figures included) | {1e3 * cpu_mc / 1e4:.2f} ms: "
        f"{np.mean(cpu_sampled) / (cpu_mc / 1e4):.0f}x less than the sampled engine | | |")
    say(f"| 10 000-point tolerance Monte Carlo of S1 (G, I_L, C, K_star), 2 workers, wall with "
        f"start-up | {wall_mc:.1f} s ({cpu_mc:.1f} s CPU: at least {cpu_mc / 2:.1f} s on 2 "
        f"cores with nothing else running) | <= 20 s | {verdict(wall_mc <= 20)} |")
    say(f"| map 4x finer (832 points), the sampled engine on 2 processes, wall | "
        f"{wall_fine_sampled:.1f} s ({1e3 * np.mean(cpu_fine_sampled):.1f} ms CPU per point) | | |")
    say(f"| the runner on 2 workers, wall with start-up | {wall_fine:.1f} s: "
        f"{wall_fine_sampled / wall_fine:.1f}x faster | >= 10x | "
        f"{verdict(wall_fine_sampled / wall_fine >= 10)} |")
    say(f"| throughput with the cluster up, 1 worker / 2 workers (2000-point mc; the median of "
        f"{PAIRS} pairs run one after the other, whose ratios are "
        f"{', '.join(f'{r:.2f}' for r in ratios)}) | "
        f"{tp1:.0f} / {tp2:.0f} points/s: {tp2 / tp1:.2f}x (workers inside the points "
        f"{100 * busy1:.0f} % / {100 * busy2:.0f} % of the wall time; the idle 2-worker "
        f"cluster takes {100 * idle2:.1f} % of a core) | >= 1.8x | "
        f"{verdict(tp2 / tp1 >= 1.8)} |")
    say("")
    png = os.path.join(os.path.dirname(a.report), "study_bench.png")
    os.makedirs(os.path.dirname(png) or ".", exist_ok=True)
    figure(png, [("sampled engine (fmpy, 50 us samples)", float(np.mean(cpu_sampled))),
                 ("runner, all processes, start-up included", per_point_runner),
                 ("runner, per point in the worker", float(np.mean(cpu_pt))),
                 ("the FMU stepped from C", cpu_c / n)])
    say(f"![CPU per point]({os.path.basename(png)})")
    say("")
    say("Commands: `make bench-study` (benches/study/study_bench.py); the studies it ran are "
        f"in {a.out}/ (map, mc, fine). Each figure is from this one run.")
    os.makedirs(os.path.dirname(a.report) or ".", exist_ok=True)
    with open(a.report, "w") as fh:
        fh.write("\n".join(L) + "\n")
    print(f"wrote {a.report} and {png}")


if __name__ == "__main__":
    main()
