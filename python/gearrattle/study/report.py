"""What a study writes besides its points: summary.txt (also printed) and the figures of its
kind: heat maps for a map, parameter-metric scatter plots for a DOE, and for a Monte Carlo the
distributions, exceedance probabilities and sensitivity indices (gearrattle.study.montecarlo)."""

import os

import numpy as np

from . import figures, montecarlo
from .table import column, ok_rows
from ..sound.study import COLUMNS, COST

# The metrics drawn in the overview figures (all of them are in points.csv): where a user of a
# rattle map looks first. An FMU without them gets its first metrics drawn.
FIGURE_METRICS = ["stat_impact_rate_Fplus", "stat_impact_rate_Fminus", "stat_run_mean_Fplus",
                  "stat_run_max_Fplus", "stat_v_mean_Fplus", "stat_rattle_power", "stat_a_rms",
                  "stat_regime", "stat_loudest_gear"]


def figure_metrics(table, metrics, record):
    """The metrics the figures draw: FIGURE_METRICS (else the first ones) and the recorded
    outputs, each only where it varies over the study's points."""
    drawn = [m for m in FIGURE_METRICS if m in metrics]
    drawn = (drawn or [m for m in metrics if m not in record][:len(FIGURE_METRICS)]) + list(record)
    return [m for m in drawn if figures.varies(table, m)]


def _gear(name):
    """The gear a metric belongs to (gear[3].stat_regime: 3), None for the box's or model's."""
    return int(name[5:name.index("]")]) if name.startswith("gear[") else None


def gears_of(st, model):
    """The gears a gearbox study models (1..n_gears, fixed or the FMU's default); none for a
    model without gears."""
    if "gear[1].stat_rattle_power" not in model.outputs:
        return []
    n = st.fixed.get("n_gears", (model.parameters["n_gears"].start, ""))[0]
    if any(a.name == "n_gears" for a in st.axes):
        n = model.parameters["n_gears"].max
    return list(range(1, int(n) + 1))


def write(st, model, table, wall):
    """Summary lines and the list of files written."""
    n = table.num_rows
    ok = ok_rows(table)
    cpu = column(table, "cpu_s")
    files = [os.path.join(st.out, "points.parquet"), os.path.join(st.out, "points.csv")]
    status = table.column("status").to_pylist()
    lines = [f"{st.kind} study of {st.fmu} (GUID {model.guid}): {n} points, {int(ok.sum())} ok, "
             f"{status.count('refused')} refused by the FMU, {status.count('failed')} failed "
             f"(run again on resume); {st.duration:g} s each"
             + (f", statistics from {st.stats_from[0]:g} s" if st.stats_from else "")]
    lines.append(f"  fixed: " + (", ".join(f"{k} = {v:g}" for k, (v, _) in st.fixed.items())
                                 or "-"))
    if np.isfinite(cpu).any():
        lines.append(f"  CPU per point: median {1e3 * np.nanmedian(cpu):.2f} ms, total "
                     f"{np.nansum(cpu):.1f} s; wall {wall:.1f} s for the points run now")
    for code, msg in sorted({(s, m) for s, m in zip(status, table.column("message").to_pylist())
                             if s != "ok"})[:10]:
        lines.append(f"  {code}: {msg}")
    if st.sound and np.isfinite(column(table, COST)).any():
        lines.append(f"  sound: CPU per point median {np.nanmedian(column(table, COST)):.2f} s "
                     f"(fine stepping, filtering and metrics) of {np.nanmedian(cpu):.2f} s")
    extra = list(st.record) + (list(COLUMNS) if st.sound else [])
    metrics = [v.name for v in model.metrics] + extra
    if not metrics:
        lines.append("  this FMU has no stat_* outputs: the rows hold the parameters and status")
    gears = gears_of(st, model)
    shown = [m for m in metrics if _gear(m) in [None] + gears]
    if metrics and ok.any():
        w = max(24, *map(len, shown))
        lines.append(f"  {'metric':{w}s} {'min':>11s} {'median':>11s} {'max':>11s}")
        for m in shown:
            x = column(table, m)[ok]
            x = x[np.isfinite(x)]
            lines.append(f"  {m:{w}s} " + (f"{x.min():11.4g} {np.median(x):11.4g} {x.max():11.4g}"
                                           if len(x) else "undefined at every point"))
    drawn = figure_metrics(table, metrics, extra)
    if st.kind != "map":  # a map draws the gears in map_gears.png
        drawn += [m for m in (f"gear[{i}].stat_rattle_power" for i in gears)
                  if figures.varies(table, m)]
    if st.kind == "map" and metrics:
        files += figures.map_figures(st, model, table, drawn, gears)
    elif st.kind == "doe" and drawn:
        files += figures.doe_figures(st, model, table, drawn)
    elif st.kind == "mc" and metrics:
        more, extra = montecarlo.analyse(st, model, table, metrics, drawn)
        lines += more
        files += extra
    path = os.path.join(st.out, "summary.txt")
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    files.append(path)
    return lines, files
