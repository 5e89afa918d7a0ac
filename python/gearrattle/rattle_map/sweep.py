"""GearRattle rattle map: the paper's sweep (Dion et al. 2009, section 8: 30-60 Hz in 2 Hz steps
x 100-700 rad/s^2 RMS) through the FMU, as heat maps, plus the no-impact threshold vs frequency.
scripts/rattle_map.py is its command line (`make rattle-map`).

The points run on the study runner (gearrattle.study, docs/STUDIES.md): Dask workers, one FMU
instance each, every point stepped in one fmi2DoStep, its statistics read from the FMU's stat_*
outputs (exact at the impacts, no sampling) over the window from t_from (0.2 s, as `make
demo`) to the end of a 1 s run. Sine mode (excitation = 1), all other parameters at the FMU's
start values (the paper's) unless overridden (--set NAME=VALUE), from the bench start
(xi = G/2, xi' = 0).

Threshold, per frequency (gearrattle.study.threshold): A_rms scanned geometrically from
0.5 rad/s^2 upwards (x1.08), then both edges refined by bisection to --threshold-tol; a level
is 'sustained' when it still rattles in the last --threshold-window s of its run. Isolated
sustaining levels below the onset are listed in threshold.csv and marked on the plot.

--trajectory-stats adds what only the trajectory shows (free flights and their decay, impact
speeds along a run, the shortest gap between two impacts on one flank): every grid point is also
sampled every 50 us through fmpy (gearrattle.study.sampled), and its impact counts checked
against the stat_* outputs'.

Outputs (in out, default target/rattle_map): rattle_map.csv, threshold.csv, summary.txt,
map_impacts_per_period.png, map_mean_run.png, map_impact_speed.png, map_power.png,
map_overview.png, threshold.png, collapse.png (the paper's section 9 claims: runs vs
main-shaft displacement, impact strength vs acceleration level); the runner's points in
grid/ and threshold/ (Parquet and CSV; a rerun reuses them).
"""

import os
import sys
import time
from dataclasses import dataclass, field

import numpy as np

from ..scenes import read_params
from ..study import engine, spec
from ..study.cli import prepare
from ..study.errors import StudyError
from ..study.threshold import COUNTS, thresholds
from .figures import collapse_figure, map_figures, threshold_figure
from .grid import NEEDED, add_trajectory_stats, grid_rows, write_grid_csv, write_threshold_csv
from .summary import summary_lines

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))


@dataclass
class Options:
    """A rattle map as scripts/rattle_map.py's flags give it (its --help says what each does)."""
    fmu: str = os.path.join(ROOT, "target", "fmu", "GearRattle.fmu")
    out: str = os.path.join(ROOT, "target", "rattle_map")
    workers: int | None = None
    scheduler: str | None = None
    f: str = "30:60:2"
    A: str = "100:700:50"
    duration: float = 1.0
    t_from: float = 0.2
    set: list = field(default_factory=list)
    no_threshold: bool = False
    trajectory_stats: bool = False
    threshold_duration: float = 1.0
    threshold_window: float = 0.4
    threshold_tol: float = 0.005


def frange(lo, hi, step):
    n = int(round((hi - lo) / step))
    return [round(lo + i * step, 10) for i in range(n + 1)]


def axis(name, text, flag):
    """An axis of the map from lo:hi:step."""
    try:
        lo, hi, step = map(float, text.split(":"))
    except ValueError:
        raise StudyError(f"{flag} {text}: give lo:hi:step") from None
    if not (step > 0 and hi >= lo):
        raise StudyError(f"{flag} {text}: give lo <= hi and step > 0")
    vals = frange(lo, hi, step)
    return spec.Axis(name, vals[0], vals[-1], len(vals), f"{flag} {text}")


def run(o: Options) -> int:
    """Run the map (and the threshold search unless o.no_threshold), write its files into o.out
    and print the summary; the exit code (1: a point failed, 2: a refused study)."""
    t_all = time.perf_counter()
    grid = spec.Study(kind="map", fmu=o.fmu, out=os.path.join(o.out, "grid"),
                      duration=o.duration, stats_from=(o.t_from, f"--t-from {o.t_from:g}"),
                      workers=o.workers, scheduler=o.scheduler)
    try:
        grid.axes = [axis("f_exc", o.f, "--f"), axis("A_rms", o.A, "--A")]
        for text in o.set:
            name, value = spec.parse_set(text, f"--set {text}")
            grid.fixed[name] = (value, f"--set {text}")
        model, data = prepare(grid)
        missing = [m for m in NEEDED if m not in {v.name for v in model.metrics}]
        if missing:
            raise StudyError(f"{o.fmu} lacks the outputs {', '.join(missing)}: rebuild "
                             f"it (make fmu)")
    except StudyError as e:
        print(f"rattle_map: {e}", file=sys.stderr)
        return 2
    fs, As = grid.axes[0].values(), grid.axes[1].values()
    overrides = {k: v for k, (v, w) in grid.fixed.items() if w != "default"}
    meta = dict(duration=o.duration, t_from=o.t_from, thr_duration=o.threshold_duration,
                thr_window=o.threshold_window, thr_tol=o.threshold_tol, thr_lo=0.5,
                thr_hi=As[0], thr_ratio=1.08, thr_confirm=1.5, set=overrides)
    _, p = read_params(o.fmu)
    p.update(overrides)
    thr = []
    with engine.Session(grid, model, data) as session:
        table = engine.execute(grid, model, data, session=session)
        if not o.no_threshold:
            win = o.threshold_duration - o.threshold_window
            tst = spec.Study(kind="map", fmu=o.fmu, out="", fixed=grid.fixed,
                             duration=o.threshold_duration,
                             stats_from=(win, "threshold window"), record=COUNTS)
            thr = thresholds(tst, model, data, session, fs, meta,
                             os.path.join(o.out, "threshold"))
    wall = time.perf_counter() - t_all
    rows = grid_rows(table, o.duration, o.t_from)
    if o.trajectory_stats:
        add_trajectory_stats(rows, o.fmu, o.workers, o.duration, o.t_from,
                             {k: v for k, (v, _) in grid.fixed.items()})
    os.makedirs(o.out, exist_ok=True)
    files = [write_grid_csv(rows, os.path.join(o.out, "rattle_map.csv"))]
    if thr:
        files.append(write_threshold_csv(thr, os.path.join(o.out, "threshold.csv")))
    files += map_figures(rows, fs, As, o.out, meta, p)
    if thr:
        files.append(threshold_figure(thr, o.out, meta, (As[0], As[-1]), p))
    files.append(collapse_figure(rows, p, o.out))
    lines = summary_lines(rows, thr, fs, As, p, meta)
    cpu = [r["cpu_s"] for r in rows if r["cpu_s"] == r["cpu_s"]]
    lines.append(f"wall time: {time.perf_counter() - t_all:.1f} s (simulations {wall:.1f} s; "
                 f"CPU per grid point median {1e3 * float(np.median(cpu)):.2f} ms)")
    path = os.path.join(o.out, "summary.txt")
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    files.append(path)
    print("\n".join(lines))
    print("files:")
    for f in files:
        print("  " + os.path.relpath(f))
    return 1 if any(r["status"] != "ok" for r in rows) else 0
