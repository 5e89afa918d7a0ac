"""The run of `make bench-gearbox` (`run`): each measurement printed as one line, the lines
written into docs/GEARBOX.md between its two bench-gearbox markers, the cost against n_gears
drawn into docs/gearbox_cost.png, the work against precision into
docs/gearbox_work_precision.png (its points in target/bench_gearbox/work_precision.csv)."""

from __future__ import annotations

import os
import re
import shutil
import sys
import time

from gearrattle import gearbox_fmu as GF
from gearrattle.study.cli import main as study

from gearbox import runs as B
from gearbox import work_precision as WP

DOC = GF.ROOT / "docs" / "GEARBOX.md"
PLOT = GF.ROOT / "docs" / "gearbox_cost.png"
WP_PLOT = GF.ROOT / "docs" / "gearbox_work_precision.png"
OUT = GF.ROOT / "target" / "bench_gearbox"
BEGIN, END = "<!-- bench-gearbox:begin -->", "<!-- bench-gearbox:end -->"


def rattle_map(x, y, out):
    """gearrattle-study map of the box (2 s per point, 2 workers): (points, wall time, exit code)."""
    nx, ny = (int(a.rsplit(":", 1)[1]) for a in (x, y))
    shutil.rmtree(out, ignore_errors=True)  # else the study resumes the points it finds there
    t0 = time.perf_counter()
    code = study(["map", "--fmu", str(GF.GEARBOX_FMU), "--x", x, "--y", y, "--duration", "2",
                  "--stats-from", "0.5", "--workers", "2", "--quiet", "--out", out])
    return nx * ny, time.perf_counter() - t0, code


def run(map_x: str, map_y: str, write: bool = True, with_map: bool = True) -> int:
    """Measures, prints, and (`write`) writes docs/GEARBOX.md's lines and the plot; the exit code."""
    lines = []

    def say(text):
        print(text, flush=True)
        lines.append(text)

    load = open("/proc/loadavg").read().split()[:3]
    say(f"Machine: {os.cpu_count()} cores, load average {' '.join(load)} at the start.")
    wall_box, rec = B.coupled_box()
    wall_gears = B.gears_one_by_one(rec)
    say(f"- Coupled default box (excitation 1, {B.T_END:g} s, communication steps of {B.H:g} s, "
        f"stepped by fmpy's FMU2Slave): {wall_box:.2f} s; its five gears stepped one by one as "
        f"GearRattle instances on the input-side motion recorded from it (theta, omega, alpha at "
        f"every step): {wall_gears:.2f} s together ({wall_gears / wall_box:.2f} x). Both times "
        f"include the Python loop's FMI calls.")
    ref = WP.Reference()
    curves = WP.sweep(ref)
    WP.write_csv(OUT / "work_precision.csv", curves)
    wp_rows = WP.ratios(curves, ref)
    for text in WP.summary(curves, ref, wp_rows):
        say(text)
    points, wall_map, code = rattle_map(map_x, map_y, str(OUT / "map")) if with_map else (0, 0.0, None)
    if code is None:
        pass
    elif code == 0:
        say(f"- Rattle map of the box with gearrattle-study ({points} points {map_x} x {map_y}, "
            f"2 s each, 2 workers): {wall_map:.0f} s, {wall_map / points:.2f} s per point.")
    else:
        say(f"- Rattle map with gearrattle-study: FAILED (exit code {code}) on {map_x} x {map_y}.")
    rows = B.cost_per_gear_count()
    say("- Wall time per simulated second against n_gears (2 s at 1 ms communication steps): "
        + ", ".join(f"{n}: {c:.2f} s" for n, c in rows) + " (docs/gearbox_cost.png).")
    if not write:
        return 0
    B.cost_figure(PLOT, rows)
    WP.figure(WP_PLOT, curves, ref, wp_rows)
    text = DOC.read_text()
    block = f"{BEGIN}\nMeasured with `make bench-gearbox` ({time.strftime('%Y-%m-%d')}):\n\n" + "\n".join(lines) + f"\n{END}"
    if BEGIN not in text:
        print(f"{DOC} has no {BEGIN} marker: nothing written", file=sys.stderr)
        return 1
    DOC.write_text(re.sub(re.escape(BEGIN) + ".*?" + re.escape(END), lambda _: block, text, flags=re.S))
    print(f"written into {DOC}, {PLOT} and {WP_PLOT}")
    return 0
