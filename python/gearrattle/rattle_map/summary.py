"""The rattle map's summary (summary.txt, also printed): the grid, the bench scenes against the
model's reference and the paper, the trajectory statistics, and the thresholds."""

import numpy as np

from ..scenes import SCENES
from .grid import TRAJECTORY, collapse_data, param_note, power_fit, spearman


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
    L.append("Bench scenes (cells of this map; cf. `make demo` and docs/MODEL.md section 5):")
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
