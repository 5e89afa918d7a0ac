"""The rattle map's statistics: one row per grid point from the FMU's stat_* outputs, what
only the sampled trajectory shows (--trajectory-stats), the CSV files, and the measures that
the summary and the figures share."""

import csv
import math
import os
import shutil

import numpy as np

from ..study import sampled

# The FMU's outputs the map reads (an FMU without them is refused before anything runs).
NEEDED = ["stat_impacts_Fplus", "stat_impacts_Fminus", "stat_runs_Fplus", "stat_runs_Fminus",
          "stat_run_mean_Fplus", "stat_run_mean_Fminus", "stat_run_max_Fplus",
          "stat_run_max_Fminus", "stat_v_mean_Fplus", "stat_v_mean_Fminus", "stat_v_max_Fplus",
          "stat_v_max_Fminus", "stat_P_contact", "stat_P_lubricant", "stat_a_rms"]

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
