"""GearRattle rattle map: the paper's sweep (Dion et al. 2009, section 8: 30-60 Hz in 2 Hz steps
x 100-700 rad/s^2 RMS) through the FMU, as heat maps, plus the no-impact threshold vs frequency.

    .venv/bin/python scripts/rattle_map.py [--fmu PATH] [--out DIR] [--workers N] ...

The points run on the study runner (gearrattle.study, docs/STUDIES.md): Dask workers, one FMU
instance each, every point stepped in one fmi2DoStep, its statistics read from the FMU's stat_*
outputs (exact at the impacts, no sampling) over the window from --t-from (0.2 s, as `make
demo`) to the end of a 1 s run. Sine mode (excitation = 1), all other parameters at the FMU's
start values (the paper's) unless --set NAME=VALUE, from the bench start (xi = G/2, xi' = 0).

Threshold, per frequency: A_rms scanned geometrically from 0.5 rad/s^2 upwards (x1.08), then
both edges refined by bisection to --threshold-tol; the scan's levels of all frequencies run as
one study, each bisection round as another. A level is classed
  none       no impact at all in the run (the impact counters from t = 0),
  transient  impacts in the start-up transient only (none in the last --threshold-window s:
             stat_impacts_* with stats_from = duration - window),
  sustained  impacts still in the last --threshold-window s (on one or both flanks).
Two levels per frequency:
  A_first      the lowest level with any impact (the start-up transient reaches a flank),
  A_sustained  the onset of sustained rattle: every scanned level from there up to 1.5x it
               sustains. Below it, a few isolated levels may sustain too (coexisting states
               near the onset); they are listed in threshold.csv and marked on the plot.
A level the FMU refuses is reported with the FMU's message and ends that bisection.

--trajectory-stats adds what only the trajectory shows (free flights and their decay, impact
speeds along a run, the shortest gap between two impacts on one flank): every grid point is also
sampled every 50 us through fmpy (gearrattle.study.sampled), and its impact counts checked
against the stat_* outputs'.

Outputs (in --out, default target/rattle_map): rattle_map.csv, threshold.csv, summary.txt,
map_impacts_per_period.png, map_mean_run.png, map_impact_speed.png, map_power.png,
map_overview.png, threshold.png, collapse.png (the paper's section 9 claims: runs vs
main-shaft displacement, impact strength vs acceleration level); the runner's points in
grid/ and threshold/ (Parquet and CSV; a rerun reuses them).
"""

import argparse
import csv
import math
import os
import shutil
import sys
import time

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import BoundaryNorm, LogNorm  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402
from matplotlib.ticker import FuncFormatter  # noqa: E402

from demo import SCENES, read_params  # noqa: E402  (reuse, no duplicate)
from gearrattle.study import engine, sampled, spec  # noqa: E402
from gearrattle.study.cli import prepare  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
COUNTS = ["impacts_Fplus", "impacts_Fminus"]  # cumulative from t = 0
NEEDED = ["stat_impacts_Fplus", "stat_impacts_Fminus", "stat_runs_Fplus", "stat_runs_Fminus",
          "stat_run_mean_Fplus", "stat_run_mean_Fminus", "stat_run_max_Fplus",
          "stat_run_max_Fminus", "stat_v_mean_Fplus", "stat_v_mean_Fminus", "stat_v_max_Fplus",
          "stat_v_max_Fminus", "stat_P_contact", "stat_P_lubricant", "stat_a_rms"]

# --------------------------------------------------------------------------- grid statistics


def _weighted(a, wa, b, wb):
    return (a * wa + b * wb) / (wa + wb) if wa + wb else float("nan")


def grid_rows(table, duration, t_from):
    """One dict per grid point: the map's statistics from the FMU's stat_* outputs."""
    rows = []
    for r in table.to_pylist():
        out = {"f_Hz": r["f_exc"], "A_rms": r["A_rms"], "cpu_s": r["cpu_s"],
               "status": "ok" if r["status"] == "ok" else "failed", "fmu_error": r["message"]}
        if r["status"] == "ok":
            npl, nmi = r["stat_impacts_Fplus"], r["stat_impacts_Fminus"]
            rpl, rmi = r["stat_runs_Fplus"], r["stat_runs_Fminus"]
            periods = r["f_exc"] * (duration - t_from)
            out.update(
                periods=periods, impacts_Fplus=npl, impacts_Fminus=nmi,
                impacts_per_period=(npl + nmi) / periods,
                impacts_per_period_Fplus=npl / periods, impacts_per_period_Fminus=nmi / periods,
                runs=rpl + rmi, mean_run_Fplus=r["stat_run_mean_Fplus"],
                mean_run_Fminus=r["stat_run_mean_Fminus"],
                mean_run=_weighted(r["stat_run_mean_Fplus"], rpl, r["stat_run_mean_Fminus"], rmi),
                run_max=max(r["stat_run_max_Fplus"], r["stat_run_max_Fminus"]),
                mean_impact_speed=_weighted(r["stat_v_mean_Fplus"], npl, r["stat_v_mean_Fminus"],
                                            nmi),
                mean_impact_speed_Fplus=r["stat_v_mean_Fplus"],
                mean_impact_speed_Fminus=r["stat_v_mean_Fminus"],
                max_impact_speed=max(r["stat_v_max_Fplus"], r["stat_v_max_Fminus"]),
                power_contact=r["stat_P_contact"], power_lubricant=r["stat_P_lubricant"],
                power_dissipated=r["stat_P_contact"] + r["stat_P_lubricant"],
                rms_accel=r["stat_a_rms"])
        rows.append(out)
    return rows


def add_trajectory_stats(rows, fmu, workers, duration, t_from, fixed):
    """What needs the trajectory itself (free flights, impact speeds along a run, the shortest
    gap between impacts on one flank), from every grid point sampled every 50 us through fmpy
    (gearrattle.study.sampled); and whether those samples count the impacts the stat_* outputs
    count."""
    from fmpy import extract

    ok = [r for r in rows if r["status"] == "ok"]
    fmu_dir = extract(fmu)
    try:
        stats, _ = sampled.run(fmu_dir, [{**fixed, "f_exc": r["f_Hz"], "A_rms": r["A_rms"]}
                                         for r in ok], workers or os.cpu_count() or 1,
                               duration, t_from, trajectory=True)
    finally:
        shutil.rmtree(fmu_dir, ignore_errors=True)
    for r, st in zip(ok, stats):
        r.update({k: st[k] for k in TRAJECTORY})
        r["sampled_counts_agree"] = int(st["impacts_Fplus"] == r["impacts_Fplus"]
                                        and st["impacts_Fminus"] == r["impacts_Fminus"])


def trajectory_lines(ok, p, meta):
    """The summary's lines from --trajectory-stats."""
    def rng(x, scale=1.0, fmt="{:.2f}"):
        return f"{fmt.format(np.nanmin(x) * scale)}..{fmt.format(np.nanmax(x) * scale)}"

    col = {k: np.array([r[k] for r in ok], dtype=float)
           for k in TRAJECTORY + ["sampled_counts_agree"]}
    rd, dur = col["runs_decreasing"], col["free_flight_mean_duration"]
    decay = p["C"] / p["I_L"]
    return [
        "From every grid point sampled every 50 us (--trajectory-stats):",
        f"  impact counts of the samples equal to the stat_* outputs' at "
        f"{int(col['sampled_counts_agree'].sum())} of {len(ok)} points",
        f"  runs of >= 2 impacts whose impact speeds decrease along the run: "
        f"{rng(rd, 100, '{:.0f}')} % of the runs of a point; 100 % at "
        f"{np.count_nonzero(rd == 1)} of {np.count_nonzero(np.isfinite(rd))} points",
        f"  mean free-flight duration: {rng(dur, 1e3)} ms, i.e. the speed decays by "
        f"{100 * (1 - np.exp(-decay * np.nanmin(dur))):.0f}.."
        f"{100 * (1 - np.exp(-decay * np.nanmax(dur))):.0f} % over a mean flight",
        f"  shortest time between two impacts on one flank: "
        f"{1e3 * np.nanmin(col['min_gap_same_flank']):.2f} ms",
        f"  free-flight speed decay rate (median per point): "
        f"{rng(col['free_flight_decay'], fmt='{:.2f}')} 1/s (C* = C/I_L = {decay:.2f} 1/s)",
    ] + [f"  {s['name']}: mean free flight {1e3 * r['free_flight_mean_duration']:.2f} ms (across "
         f"the gap {1e3 * r['crossing_flight_mean_duration']:.2f}, bounces on one flank "
         f"{1e3 * r['bounce_flight_mean_duration']:.2f}), impact speeds decreasing along "
         f"{100 * r['runs_decreasing']:.0f} % of the runs"
         for s in SCENES for r in ok if r["f_Hz"] == s["f"] and r["A_rms"] == s["A_rms"]]


# --------------------------------------------------------------------------- threshold


def classify(r):
    """'none' / 'transient' / 'sustained' of a threshold run (see the module docstring), with
    the impacts in the window on F+ and F-; None if the FMU refused the level."""
    if r["status"] != "ok":
        return None, 0, 0
    lp, lm = r["stat_impacts_Fplus"], r["stat_impacts_Fminus"]
    if r["impacts_Fplus"] + r["impacts_Fminus"] == 0:
        return "none", lp, lm
    return ("transient" if lp + lm == 0 else "sustained"), lp, lm


def _run_levels(study, model, data, session, points, out):
    """Classes of the levels {(f, A)} run as one study in out."""
    study.out = out
    table = engine.execute(study, model, data, points=[{"f_exc": f, "A_rms": A}
                                                         for f, A in points], session=session)
    res = {(r["f_exc"], r["A_rms"]): r for r in table.to_pylist()}
    return {k: (classify(res[k]), res[k]["message"]) for k in points}


def scan_one(f, levels, classes, meta):
    """The scan at one frequency as rattle_map always read it: up to the level where sustained
    rattle has held from its onset to thr_confirm times it. (scan, streak start or None)."""
    scan, streak = [], None
    for A in levels:
        (c, lp, lm), _ = classes[(f, A)]
        scan.append((A, c, lp, lm))
        if c == "sustained":
            streak = A if streak is None else streak
            if A >= meta["thr_confirm"] * streak:
                break
        elif c is not None:
            streak = None
    return scan, streak


def thresholds(study, model, data, session, fs, meta, base):
    """A_first and A_sustained at each frequency (geometric scan, then rounds of bisection);
    the runner's points in base/scan, base/bisection1, ..."""
    levels, A = [], meta["thr_lo"]
    while A <= meta["thr_hi"]:
        levels.append(A)
        A *= meta["thr_ratio"]
    classes = _run_levels(study, model, data, session, [(f, A) for f in fs for A in levels],
                          os.path.join(base, "scan"))
    out, brackets = {}, {}
    for f in fs:
        scan, streak = scan_one(f, levels, classes, meta)
        lv = [s[0] for s in scan]
        cl = [s[1] for s in scan]
        t = out[f] = {"f_Hz": f, "scan": scan, "errors": [f"{A:.4g}: {classes[(f, A)][1]}"
                                                          for A in lv if classes[(f, A)][0][0]
                                                          is None]}
        first = next((i for i, c in enumerate(cl) if c not in ("none", None)), None)
        t["A_first"] = t["A_first_lo"] = float("nan")
        if first:
            brackets[(f, "first")] = [lv[first - 1], lv[first]]
        t["A_sustained"] = t["A_sustained_lo"] = float("nan")
        t["isolated_sustained"] = []
        if streak is not None and lv[-1] >= meta["thr_confirm"] * streak:
            j = lv.index(streak)
            t["A_sustained"] = streak
            if j:
                brackets[(f, "sustained")] = [lv[j - 1], streak]
            t["isolated_sustained"] = [s[0] for s in scan[:j] if s[1] == "sustained"]
        t["one_sided"] = [(s[0], "F+" if s[3] == 0 else "F-") for s in scan
                          if s[1] == "sustained" and (s[2] == 0 or s[3] == 0)]
        t["sims"] = len(lv)
    active, rnd = dict(brackets), 0
    while active:
        rnd += 1
        mids = {k: math.sqrt(lo * hi) for k, (lo, hi) in active.items()}
        todo = sorted({(f, A) for (f, _), A in mids.items()})
        res = _run_levels(study, model, data, session, todo,
                          os.path.join(base, f"bisection{rnd}"))
        for (f, edge), mid in mids.items():
            (c, _, _), msg = res[(f, mid)]
            out[f]["sims"] += 1
            if c is None:
                out[f]["errors"].append(f"{mid:.4g}: {msg}")
                del active[(f, edge)]
                continue
            lo_hi = active[(f, edge)]
            lo_hi[1 if (c != "none" if edge == "first" else c == "sustained") else 0] = mid
            if lo_hi[1] / lo_hi[0] <= 1 + meta["thr_tol"]:
                del active[(f, edge)]
    for (f, edge), (lo, hi) in brackets.items():
        out[f][f"A_{edge}_lo"], out[f][f"A_{edge}"] = lo, hi
    return [out[f] for f in fs]


def grid_array(rows, fs, As, key, scale=1.0):
    Z = np.full((len(As), len(fs)), np.nan)
    for r in rows:
        if r["status"] == "ok":
            i = As.index(r["A_rms"])
            j = fs.index(r["f_Hz"])
            Z[i, j] = r[key] * scale
    return Z


def edges(v):
    v = np.asarray(v, dtype=float)
    if len(v) == 1:  # a single row or column: a cell 10 % wide
        w = max(0.1 * abs(v[0]), 1.0)
        return np.array([v[0] - w / 2, v[0] + w / 2])
    d = np.diff(v)
    return np.concatenate(([v[0] - d[0] / 2], v[:-1] + d / 2, [v[-1] + d[-1] / 2]))


def heatmap(ax, fs, As, Z, title, clabel, fmt, cmap="viridis", norm=None, fontsize=6.5):
    cm = plt.get_cmap(cmap)
    m = ax.pcolormesh(edges(fs), edges(As), np.ma.masked_invalid(Z), cmap=cm, norm=norm,
                      shading="flat")
    cb = plt.colorbar(m, ax=ax, pad=0.01)
    cb.set_label(clabel)
    if isinstance(norm, LogNorm):
        cb.ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        # label the minor ticks at 2 and 5 times a power of ten only
        cb.ax.yaxis.set_minor_formatter(FuncFormatter(
            lambda v, _: f"{v:g}" if v > 0 and round(v / 10 ** math.floor(math.log10(v)))
            in (2, 5) else ""))
    nrm = m.norm
    for i, A in enumerate(As):
        for j, f in enumerate(fs):
            z = Z[i, j]
            if np.isnan(z):
                ax.text(f, A, "fail", ha="center", va="center", fontsize=fontsize, color="r")
                continue
            r, g, b, _ = cm(nrm(z))
            col = "k" if 0.299 * r + 0.587 * g + 0.114 * b > 0.5 else "w"
            ax.text(f, A, fmt.format(z), ha="center", va="center", fontsize=fontsize, color=col)
    for s in SCENES:  # the bench scenes of `make demo`
        if s["f"] in fs and s["A_rms"] in As:
            df, dA = np.diff(edges(fs)).mean(), np.diff(edges(As)).mean()
            ax.add_patch(Rectangle((s["f"] - df / 2, s["A_rms"] - dA / 2), df, dA, fill=False,
                                   ec="red", lw=1.8))
            ax.annotate(s["name"], (s["f"] + df / 2, s["A_rms"] + dA / 2), color="red",
                        fontsize=8, fontweight="bold", ha="left", va="bottom",
                        xytext=(1, 0), textcoords="offset points")
    ax.set_xticks(fs)
    ax.set_xticklabels([f"{f:g}" for f in fs], fontsize=7)
    ax.set_yticks(As)
    ax.set_yticklabels([f"{A:g}" for A in As], fontsize=7)
    ax.set_xlabel("excitation frequency f [Hz]")
    ax.set_ylabel(r"main-shaft acceleration $A_{rms}$ [rad/s²]")
    ax.set_title(title, fontsize=10)
    return m


def runs_norm():
    b = np.arange(0.5, 7.5, 1.0)
    return BoundaryNorm(b, plt.get_cmap("viridis").N, extend="max")


MAPS = [
    # key, file, title, colour label, cell format, scale, colour norm (None: linear)
    ("impacts_per_period", "map_impacts_per_period.png", "Impacts per excitation period (F+ and F-)",
     "impacts per period", "{:.1f}", 1.0, None),
    ("mean_run", "map_mean_run.png", "Mean consecutive impacts on one flank before crossing the gap",
     "impacts per run", "{:.1f}", 1.0, runs_norm),
    ("mean_impact_speed", "map_impact_speed.png", r"Mean impact speed $|\xi'|$ at contact onset",
     "mm/s", "{:.1f}", 1e3, None),
    ("power_dissipated", "map_power.png",
     "Dissipated power (contact damping + lubricant drag)", "mW (log scale)", "{:.0f}", 1e3,
     LogNorm),
]
POWER_CONTACT = ("power_contact", None, "of which dissipated in the contact damping (impacts)",
                 "mW (log scale)", "{:.1f}", 1e3, LogNorm)


def disp_contours(ax, fs, As, r_M):
    """Dashed lines of constant main-shaft displacement amplitude on the pitch line."""
    F, AA = np.meshgrid(np.linspace(fs[0] - 1, fs[-1] + 1, 200),
                        np.linspace(As[0] - 25, As[-1] + 25, 200))
    D = 1e6 * r_M * np.sqrt(2) * AA / (2 * np.pi * F) ** 2
    cs = ax.contour(F, AA, D, levels=[50, 100, 150, 200, 300, 400, 600], colors="w",
                    linewidths=0.9, linestyles="--", alpha=0.9)
    ax.clabel(cs, fmt="%g µm", fontsize=7, inline_spacing=2)


def map_figures(rows, fs, As, out, meta, p):
    paths = []
    sub = (f"GearRattle FMU, {param_note(p, meta)}; statistics "
           f"{meta['t_from']:g}-{meta['duration']:g} s; red boxes: the bench scenes of "
           f"`make demo`")
    for key, fname, title, clabel, fmt, scale, norm in MAPS:
        power = key == "power_dissipated"
        fig, axes = plt.subplots(2 if power else 1, 1, figsize=(12, 12.5 if power else 6.5),
                                 constrained_layout=True, squeeze=False)
        ax = axes[0, 0]
        Z = grid_array(rows, fs, As, key, scale)
        heatmap(ax, fs, As, Z, f"{title}\n{sub}", clabel, fmt, norm=norm() if norm else None)
        if power:
            k2, _, t2, c2, f2, s2, n2 = POWER_CONTACT
            heatmap(axes[1, 0], fs, As, grid_array(rows, fs, As, k2, s2), t2, c2, f2, norm=n2())
        if key == "mean_run":
            disp_contours(ax, fs, As, p["r_M"])
            ax.text(0.005, -0.085, "dashed: main-shaft displacement amplitude on its pitch "
                    r"circle, $r_M\sqrt{2}A_{rms}/(2\pi f)^2$", transform=ax.transAxes,
                    fontsize=7, color="0.3", va="top")
        path = os.path.join(out, fname)
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    fig, axes = plt.subplots(2, 2, figsize=(17, 10), constrained_layout=True)
    for ax, (key, _, title, clabel, fmt, scale, norm) in zip(axes.flat, MAPS):
        Z = grid_array(rows, fs, As, key, scale)
        heatmap(ax, fs, As, Z, title, clabel, fmt, norm=norm() if norm else None, fontsize=5)
    fig.suptitle(f"Rattle map: the paper's sweep through the FMU\n{sub}", fontsize=11)
    path = os.path.join(out, "map_overview.png")
    fig.savefig(path, dpi=100)
    plt.close(fig)
    paths.append(path)
    return paths


def param_note(p, meta):
    """'paper's parameters (G = 25 µm)', or the overridden parameters."""
    if not meta["set"]:
        return f"paper's parameters (G = {1e6 * p['G']:g} µm)"
    return "paper's parameters except " + ", ".join(f"{k} = {v:g}" for k, v in meta["set"].items())


def power_fit(fs, a):
    """Least squares of ln a on ln f: (a at 30 Hz, exponent), or None with fewer than 2 points."""
    ok = np.isfinite(a)
    if np.count_nonzero(ok) < 2:
        return None
    pw, c = np.polyfit(np.log(fs[ok]), np.log(a[ok]), 1)
    return np.exp(c) * 30 ** pw, pw


def threshold_figure(thr, out, meta, grid_range, p):
    thr = sorted(thr, key=lambda t: t["f_Hz"])
    fs = np.array([t["f_Hz"] for t in thr])
    a1 = np.array([t["A_first"] for t in thr])
    a2 = np.array([t["A_sustained"] for t in thr])
    fig, ax = plt.subplots(figsize=(10, 7.5), constrained_layout=True)
    ax.axhspan(grid_range[0], grid_range[1], color="tab:orange", alpha=0.15)
    ax.text(fs.mean(), math.sqrt(grid_range[0] * grid_range[1]),
            f"levels the paper tested and the map covers\n({grid_range[0]:g}-{grid_range[1]:g} "
            "rad/s² RMS): the model rattles everywhere here", ha="center", va="center",
            fontsize=9, color="tab:brown")
    ax.fill_between(fs, a1, a2, color="tab:blue", alpha=0.12, lw=0,
                    label="impacts in the start-up transient only")
    ax.semilogy(fs, a2, "s-", color="tab:red", label=r"$A_{sustained}$: sustained rattle from here")
    ax.semilogy(fs, a1, "o-", color="tab:blue", label=r"$A_{first}$: first impact (from the "
                r"bench start $\xi = G/2$, $\xi' = 0$)")
    iso = [(t["f_Hz"], A) for t in thr for A in t["isolated_sustained"]]
    if iso:
        ax.plot(*zip(*iso), "x", color="tab:red", ms=5, ls="none",
                label="isolated sustaining levels below the onset (scan)")
    ax.fill_between(fs, np.ones_like(a1), a1, color="0.85", lw=0, label="no impact at all")
    for a, name, color in ((a2, "sustained", "tab:red"), (a1, "first", "tab:blue")):
        fit = power_fit(fs, a)
        if fit:
            at30, pw = fit
            ax.semilogy(fs, at30 * (fs / 30) ** pw, ":", color=color, lw=1,
                        label=rf"fit $A_{{{name}}} \approx {at30:.2f}\,"
                              rf"(f/30\,\mathrm{{Hz}})^{{{pw:.2f}}}$")
    ax.set_ylim(1, 1500)
    ax.set_xlim(fs[0] - 1, fs[-1] + 1)
    ax.set_xticks(fs)
    ax.set_xlabel("excitation frequency f [Hz]")
    ax.set_ylabel(r"main-shaft acceleration $A_{rms}$ [rad/s²]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), fontsize=8, ncol=2)
    ax.set_title(f"No-impact threshold of the model ({param_note(p, meta)})\n"
                 f"scan x{meta['thr_ratio']:g} from {meta['thr_lo']:g} rad/s², bisection to "
                 f"{100 * meta['thr_tol']:g} %; runs of {meta['thr_duration']:g} s, 'sustained' = "
                 f"impacts in the last {meta['thr_window']:g} s", fontsize=10)
    path = os.path.join(out, "threshold.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def spearman(x, y):
    from scipy.stats import spearmanr

    ok = np.isfinite(x) & np.isfinite(y)
    return float(spearmanr(x[ok], y[ok]).statistic) if np.count_nonzero(ok) > 2 else float("nan")


def collapse_data(rows, p):
    ok = [r for r in rows if r["status"] == "ok"]
    f = np.array([r["f_Hz"] for r in ok], dtype=float)
    A = np.array([r["A_rms"] for r in ok], dtype=float)
    disp = 1e6 * p["r_M"] * np.sqrt(2) * A / (2 * np.pi * f) ** 2  # µm on the pitch circle
    run = np.array([r["mean_run"] for r in ok], dtype=float)
    v = 1e3 * np.array([r["mean_impact_speed"] for r in ok], dtype=float)
    arms = np.array([r["rms_accel"] for r in ok], dtype=float)
    return f, A, disp, run, v, arms


def collapse_figure(rows, p, out):
    f, A, disp, run, v, arms = collapse_data(rows, p)
    fig, axes = plt.subplots(2, 2, figsize=(12, 9), constrained_layout=True)
    panels = [
        (axes[0, 0], disp, run, "main-shaft displacement amplitude on its pitch circle [µm]",
         "mean run on one flank"),
        (axes[0, 1], A, run, r"$A_{rms}$ [rad/s²]", "mean run on one flank"),
        (axes[1, 0], disp, arms, "main-shaft displacement amplitude on its pitch circle [µm]",
         r"RMS loose-gear pitch-line acceleration [m/s²]"),
        (axes[1, 1], A, arms, r"$A_{rms}$ [rad/s²]",
         r"RMS loose-gear pitch-line acceleration [m/s²]"),
    ]
    for ax, x, y, xl, yl in panels:
        sc = ax.scatter(x, y, c=f, cmap="plasma", s=18)
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
        ax.grid(alpha=0.3)
        ax.set_title(f"Spearman rank correlation {spearman(x, y):+.2f}", fontsize=9)
    fig.colorbar(sc, ax=axes, label="f [Hz]", shrink=0.6)
    fig.suptitle("Paper §9: 'the number of impacts on one side strongly depends on the angular "
                 "displacement of the main shaft';\n'the energy level of impacts mainly depends "
                 "on the acceleration level': each grid point of the map, coloured by f",
                 fontsize=10)
    path = os.path.join(out, "collapse.png")
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


# --------------------------------------------------------------------------- outputs

CSV_COLS = [
    "f_Hz", "A_rms", "status", "periods", "impacts_Fplus", "impacts_Fminus",
    "impacts_per_period", "impacts_per_period_Fplus", "impacts_per_period_Fminus",
    "runs", "mean_run", "mean_run_Fplus", "mean_run_Fminus", "run_max",
    "mean_impact_speed", "mean_impact_speed_Fplus", "mean_impact_speed_Fminus",
    "max_impact_speed", "power_dissipated", "power_contact", "power_lubricant", "rms_accel",
    "cpu_s", "fmu_error",
] + [  # with --trajectory-stats
    "runs_decreasing", "min_gap_same_flank", "free_flight_decay", "free_flight_mean_duration",
    "crossing_flight_mean_duration", "bounce_flight_mean_duration", "sampled_counts_agree",
]
TRAJECTORY = CSV_COLS[CSV_COLS.index("runs_decreasing"):CSV_COLS.index("sampled_counts_agree")]


def fmt_cell(v):
    if isinstance(v, float):
        return "" if math.isnan(v) else f"{v:.6g}"
    return str(v)


def write_grid_csv(rows, path):
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(CSV_COLS)
        for r in sorted(rows, key=lambda r: (r["f_Hz"], r["A_rms"])):
            w.writerow([fmt_cell(r.get(c, "")) for c in CSV_COLS])
    return path


def write_threshold_csv(thr, path):
    cols = ["f_Hz", "A_first_lo", "A_first", "A_sustained_lo", "A_sustained",
            "isolated_sustained", "one_sided", "scan", "sims", "fmu_errors"]
    code = {"none": ".", "transient": "t", "sustained": "S", None: "E"}
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        for t in sorted(thr, key=lambda t: t["f_Hz"]):
            row = dict(t)
            row["isolated_sustained"] = " ".join(f"{A:.3g}" for A in t["isolated_sustained"])
            row["one_sided"] = " ".join(f"{A:.3g}({fl})" for A, fl in t["one_sided"])
            # the scan as level:class, class . none, t transient, S sustained, E FMU failure
            row["scan"] = " ".join(f"{A:.3g}:{code[c]}" for A, c, _, _ in t["scan"])
            row["fmu_errors"] = " | ".join(t["errors"])
            w.writerow([fmt_cell(row.get(c, "")) for c in cols])
    return path


def summary_lines(rows, thr, fs, As, p, meta):
    L = []
    ok = [r for r in rows if r["status"] == "ok"]
    bad = [r for r in rows if r["status"] != "ok"]
    L.append(f"Grid: f = {fs[0]:g}..{fs[-1]:g} Hz ({len(fs)} values) x A_rms = {As[0]:g}.."
             f"{As[-1]:g} rad/s^2 RMS ({len(As)} values): {len(rows)} points, {len(ok)} ok, "
             f"{len(bad)} refused by the FMU")
    L.append(f"  {param_note(p, meta)}; runs of {meta['duration']:g} s, statistics "
             f"{meta['t_from']:g}-{meta['duration']:g} s (the FMU's stat_* outputs)")
    for r in bad:
        L.append(f"  REFUSED f={r['f_Hz']:g} A={r['A_rms']:g}: {r['fmu_error']}")
    if not ok:
        return L
    f, A, disp, run, v, arms = collapse_data(rows, p)

    def rng(x, scale=1.0, fmt="{:.2f}"):
        return f"{fmt.format(np.nanmin(x) * scale)}..{fmt.format(np.nanmax(x) * scale)}"

    ipp = np.array([r["impacts_per_period"] for r in ok])
    pw = np.array([r["power_dissipated"] for r in ok])
    pc = np.array([r["power_contact"] for r in ok])
    asym = np.array([abs(r["impacts_Fplus"] - r["impacts_Fminus"]) /
                     max(r["impacts_Fplus"] + r["impacts_Fminus"], 1) for r in ok])
    L.append("Over the grid (min..max):")
    L.append(f"  impacts per period (F+ + F-): {rng(ipp)}")
    L.append(f"  mean run on one flank:        {rng(run)}; longest run "
             f"{int(max(r['run_max'] for r in ok))}")
    short = [f"{r['f_Hz']:g}/{r['A_rms']:g}" for r in ok if r["mean_run"] < 2]
    L.append(f"  mean run < 2 at {len(short)} of {len(ok)} points (f Hz/A_rms): "
             + (" ".join(short) or "-"))
    L.append(f"  mean impact speed:            {rng(v, fmt='{:.1f}')} mm/s")
    L.append(f"  dissipated power:             {rng(pw, 1e3, '{:.0f}')} mW, of which contact "
             f"{rng(pc / pw, 100, '{:.1f}')} % ({rng(pc, 1e3, '{:.1f}')} mW)")
    L.append(f"  RMS pitch-line acceleration:  {rng(arms, fmt='{:.1f}')} m/s^2")
    L.append(f"  |F+ - F-| / (F+ + F-) impacts: at most {100 * np.max(asym):.1f} %; above 5 % in "
             f"{np.count_nonzero(asym > 0.05)} of {len(ok)} points")
    # where runs are long / short
    L.append("Mean run on one flank by frequency (min..max over A_rms), grid cells with mean "
             "run >= 3.5 / < 3.5:")
    for fv in fs:
        rr = np.array([r["mean_run"] for r in ok if r["f_Hz"] == fv])
        long_ = [r["A_rms"] for r in ok if r["f_Hz"] == fv and r["mean_run"] >= 3.5]
        L.append(f"  {fv:4g} Hz: {rng(rr)}   >= 3.5 at A_rms = "
                 + (", ".join(f"{x:g}" for x in long_) if long_ else "-"))
    L.append("Mean run on one flank against the main-shaft displacement amplitude on its pitch "
             "circle, r_M sqrt(2) A_rms / (2 pi f)^2 (bins; mean, min..max over the cells):")
    bins = [0, 50, 100, 150, 200, 250, 300, 400, 500, 1000]
    for b0, b1 in zip(bins[:-1], bins[1:]):
        sel = (disp >= b0) & (disp < b1)
        if np.any(sel):
            lo_f, hi_f = np.argmin(np.where(sel, f, np.inf)), np.argmax(np.where(sel, f, -np.inf))
            L.append(f"  {b0:4d}-{b1:<4d} um: {np.nanmean(run[sel]):.2f} ({rng(run[sel])}, "
                     f"{np.count_nonzero(sel):2d} cells); RMS accel {arms[lo_f]:.1f} m/s^2 at "
                     f"{f[lo_f]:g} Hz, {arms[hi_f]:.1f} at {f[hi_f]:g} Hz")
    parts = []
    for Av in As:
        x = arms[A == Av]
        if len(x):
            parts.append(f"{Av:g}: {rng(x, fmt='{:.1f}')}")
    L.append("RMS pitch-line acceleration [m/s^2] over f at fixed A_rms (min..max): "
             + "; ".join(parts))
    L.append("Paper section 9 (Spearman rank correlation over the grid):")
    L.append(f"  mean run vs main-shaft displacement amplitude {spearman(disp, run):+.2f}, "
             f"vs A_rms {spearman(A, run):+.2f}")
    L.append(f"  RMS acceleration vs A_rms {spearman(A, arms):+.2f}, vs displacement "
             f"{spearman(disp, arms):+.2f}; mean impact speed vs A_rms {spearman(A, v):+.2f}, "
             f"vs displacement {spearman(disp, v):+.2f}")
    L.append("Bench scenes (cells of this map; cf. `make demo` and MODEL.md section 5):")
    span = meta["duration"] - meta["t_from"]
    for s in SCENES:
        r = next((r for r in ok if r["f_Hz"] == s["f"] and r["A_rms"] == s["A_rms"]), None)
        if r is None:
            continue
        L.append(f"  {s['name']} ({s['f']:g} Hz, {s['A_rms']:g}): impacts/s F+/F- "
                 f"{r['impacts_Fplus'] / span:.1f}/{r['impacts_Fminus'] / span:.1f}, mean run "
                 f"{r['mean_run']:.2f} (longest {r['run_max']}), mean impact speed "
                 f"{1e3 * r['mean_impact_speed']:.1f} mm/s, RMS accel {r['rms_accel']:.1f} m/s^2")
        if not meta["set"]:  # the references hold for the paper's parameters only
            L.append(f"      model reference: {s['model_ref']}")
        L.append(f"      paper (measured): {s['paper']}")
    if "free_flight_decay" in ok[0]:
        L += trajectory_lines(ok, p, meta)
    if thr:
        L.append("No-impact threshold (A_rms in rad/s^2 RMS; [lo, hi] brackets of the bisection):")
        L.append(f"  {'f Hz':>5}  {'A_first':>16}  {'A_sustained':>16}  isolated sustaining "
                 f"levels below the onset; one-sided sustained levels")
        for t in thr:
            iso = ", ".join(f"{x:.3g}" for x in t["isolated_sustained"]) or "-"
            one = ", ".join(f"{x:.3g} ({fl} only)" for x, fl in t["one_sided"]) or "-"
            L.append(f"  {t['f_Hz']:5g}  {t['A_first']:6.3g} [{t['A_first_lo']:.3g},"
                     f"{t['A_first']:.3g}]  {t['A_sustained']:6.3g} [{t['A_sustained_lo']:.3g},"
                     f"{t['A_sustained']:.3g}]  {iso}; {one}")
        errs = sum(len(t["errors"]) for t in thr)
        L.append(f"  {sum(t['sims'] for t in thr)} threshold runs; {errs} levels refused by the "
                 f"FMU (threshold.csv, fmu_errors)")
        f_thr = np.array([t["f_Hz"] for t in thr])
        for key, name in (("A_first", "first impact"), ("A_sustained", "sustained rattle")):
            fit = power_fit(f_thr, np.array([t[key] for t in thr]))
            if fit:
                L.append(f"  fit of the {name} (least squares of ln A on ln f): "
                         f"{fit[0]:.2f} (f/30 Hz)^{fit[1]:.2f}")
    return L


# --------------------------------------------------------------------------- main

def frange(lo, hi, step):
    n = int(round((hi - lo) / step))
    return [round(lo + i * step, 10) for i in range(n + 1)]


def axis(name, text, flag):
    """An axis of the map from lo:hi:step."""
    try:
        lo, hi, step = map(float, text.split(":"))
    except ValueError:
        raise spec.StudyError(f"{flag} {text}: give lo:hi:step") from None
    if not (step > 0 and hi >= lo):
        raise spec.StudyError(f"{flag} {text}: give lo <= hi and step > 0")
    vals = frange(lo, hi, step)
    return spec.Axis(name, vals[0], vals[-1], len(vals), f"{flag} {text}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fmu", default=os.path.join(ROOT, "target", "fmu", "GearRattle.fmu"))
    ap.add_argument("--out", default=os.path.join(ROOT, "target", "rattle_map"))
    ap.add_argument("--workers", type=int, default=None,
                    help="Dask worker processes (default: one per core; 0: serial)")
    ap.add_argument("--scheduler", default=None, help="an existing Dask cluster's address")
    ap.add_argument("--f", default="30:60:2", help="frequencies lo:hi:step [Hz]")
    ap.add_argument("--A", default="100:700:50", help="levels lo:hi:step [rad/s^2 RMS]")
    ap.add_argument("--duration", type=float, default=1.0, help="simulated time per point [s]")
    ap.add_argument("--t-from", type=float, default=0.2, help="statistics from here [s]")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="override a parameter's start value (repeatable), e.g. --set G=80e-6; "
                         "the default is the paper's parameters")
    ap.add_argument("--no-threshold", action="store_true", help="skip the threshold search")
    ap.add_argument("--trajectory-stats", action="store_true",
                    help="also sample every grid point every 50 us through fmpy (the sampled "
                         "engine: about 30 s more on 2 cores) for the statistics that need "
                         "the trajectory: free flights, impact speeds along a run, the shortest "
                         "gap between two impacts on one flank")
    ap.add_argument("--threshold-duration", type=float, default=1.0)
    ap.add_argument("--threshold-window", type=float, default=0.4)
    ap.add_argument("--threshold-tol", type=float, default=0.005,
                    help="relative width of the bisection's final bracket")
    args = ap.parse_args(argv)
    if not 0 < args.threshold_window < args.threshold_duration:
        ap.error("need 0 < --threshold-window < --threshold-duration")
    t_all = time.perf_counter()
    grid = spec.Study(kind="map", fmu=args.fmu, out=os.path.join(args.out, "grid"),
                      duration=args.duration, stats_from=(args.t_from, f"--t-from {args.t_from:g}"),
                      workers=args.workers, scheduler=args.scheduler)
    try:
        grid.axes = [axis("f_exc", args.f, "--f"), axis("A_rms", args.A, "--A")]
        for text in args.set:
            name, value = spec.parse_set(text, f"--set {text}")
            grid.fixed[name] = (value, f"--set {text}")
        model, data = prepare(grid)
        missing = [m for m in NEEDED if m not in {v.name for v in model.metrics}]
        if missing:
            raise spec.StudyError(f"{args.fmu} lacks the outputs {', '.join(missing)}: rebuild "
                                  f"it (make fmu)")
    except spec.StudyError as e:
        print(f"rattle_map: {e}", file=sys.stderr)
        return 2
    fs, As = grid.axes[0].values(), grid.axes[1].values()
    overrides = {k: v for k, (v, w) in grid.fixed.items() if w != "default"}
    meta = dict(duration=args.duration, t_from=args.t_from, thr_duration=args.threshold_duration,
                thr_window=args.threshold_window, thr_tol=args.threshold_tol, thr_lo=0.5,
                thr_hi=As[0], thr_ratio=1.08, thr_confirm=1.5, set=overrides)
    _, p = read_params(args.fmu)
    p.update(overrides)
    thr = []
    with engine.Session(grid, model, data) as session:
        table = engine.execute(grid, model, data, session=session)
        if not args.no_threshold:
            win = args.threshold_duration - args.threshold_window
            tst = spec.Study(kind="map", fmu=args.fmu, out="", fixed=grid.fixed,
                             duration=args.threshold_duration,
                             stats_from=(win, "threshold window"), record=COUNTS)
            thr = thresholds(tst, model, data, session, fs, meta,
                             os.path.join(args.out, "threshold"))
    wall = time.perf_counter() - t_all
    rows = grid_rows(table, args.duration, args.t_from)
    if args.trajectory_stats:
        add_trajectory_stats(rows, args.fmu, args.workers, args.duration, args.t_from,
                             {k: v for k, (v, _) in grid.fixed.items()})
    os.makedirs(args.out, exist_ok=True)
    files = [write_grid_csv(rows, os.path.join(args.out, "rattle_map.csv"))]
    if thr:
        files.append(write_threshold_csv(thr, os.path.join(args.out, "threshold.csv")))
    files += map_figures(rows, fs, As, args.out, meta, p)
    if thr:
        files.append(threshold_figure(thr, args.out, meta, (As[0], As[-1]), p))
    files.append(collapse_figure(rows, p, args.out))
    lines = summary_lines(rows, thr, fs, As, p, meta)
    cpu = [r["cpu_s"] for r in rows if r["cpu_s"] == r["cpu_s"]]
    lines.append(f"wall time: {time.perf_counter() - t_all:.1f} s (simulations {wall:.1f} s; "
                 f"CPU per grid point median {1e3 * float(np.median(cpu)):.2f} ms)")
    path = os.path.join(args.out, "summary.txt")
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    files.append(path)
    print("\n".join(lines))
    print("files:")
    for f in files:
        print("  " + os.path.relpath(f))
    return 1 if any(r["status"] != "ok" for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
