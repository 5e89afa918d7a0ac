"""GearRattle rattle map: the paper's sweep (Dion et al. 2009, section 8: 30-60 Hz in 2 Hz steps
x 100-700 rad/s^2 RMS) through the FMU, as heat maps, plus the no-impact threshold vs frequency.

    .venv/bin/python scripts/rattle_map.py [--fmu PATH] [--out DIR] [--workers 2] ...

Every grid point is one fmpy simulate_fmu run of the FMU in sine mode (excitation = 1, f_exc,
A_rms; all other parameters at the FMU's start values = the paper's), from the bench start
(xi = G/2, xi' = 0). Statistics over the same steady window as scripts/demo.py (0.2 s to the
end of a 1 s run), so the S1/S2/S3 cells can be read against `make demo`.

Threshold, per frequency, by a geometric scan of A_rms from 0.5 rad/s^2 upwards, refined by
bisection (shorter runs: only the impact counters are read). A level is classed
  none       no impact at all in the run,
  transient  impacts in the start-up transient only (none in the last --threshold-window s),
  sustained  impacts still in the last --threshold-window s (on one or both flanks).
Two levels per frequency:
  A_first      the lowest level with any impact (the start-up transient reaches a flank),
  A_sustained  the onset of sustained rattle: every scanned level from there up to 1.5x it
               sustains. Below it, a few isolated levels may sustain too (coexisting states
               near the onset); they are listed in threshold.csv and marked on the plot.

Outputs (in --out, default target/rattle_map): rattle_map.csv, threshold.csv, summary.txt,
map_impacts_per_period.png, map_mean_run.png, map_impact_speed.png, map_power.png,
map_overview.png, threshold.png, collapse.png (the paper's section 9 claims: runs vs
main-shaft displacement, impact strength vs acceleration level).

Parameters other than the excitation can be changed with --set NAME=VALUE (e.g. --set G=80e-6
for the backlash the paper measured); the default is the paper's parameters.

If the FMU refuses a step (fmi2DoStep error; builds before commit a9af466 did so near grazing
contacts: "edge crossings without progress in time"), the run is retried with a slightly
different output interval and the retry is recorded in the CSVs; a point that still fails is
reported, not guessed.
"""

import argparse
import csv
import math
import multiprocessing as mp
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

from demo import SCENES, dist_str, read_params  # noqa: E402  (reuse, no duplicate)
from gearrattle import rattle_stats as rs  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

GRID_OUTPUTS = ["impacts_Fplus", "impacts_Fminus", "impact_speed", "E_contact", "E_lubricant",
                "a_pitch_L", "omega_L", "contact"]
COUNT_OUTPUTS = ["impacts_Fplus", "impacts_Fminus"]
RETRY_FACTORS = (1.0, 0.8, 0.6, 0.45)  # output interval multipliers tried in turn

# --------------------------------------------------------------------------- progress bar


class Progress:
    """A small progress bar on stderr: redrawn in place on a terminal, a line per 10 %
    otherwise (make logs, CI)."""

    def __init__(self, total, label, stream=sys.stderr, width=30):
        self.total, self.label, self.stream, self.width = max(total, 1), label, stream, width
        self.done, self.t0, self.last_decile = 0, time.perf_counter(), -1
        self.tty = hasattr(stream, "isatty") and stream.isatty()
        self._draw("")

    def update(self, n=1, note=""):
        self.done += n
        self._draw(note)

    def _draw(self, note):
        frac = self.done / self.total
        el = time.perf_counter() - self.t0
        eta = el / frac * (1 - frac) if frac > 0 else float("nan")
        fill = int(round(self.width * frac))
        line = (f"{self.label} [{'#' * fill}{'.' * (self.width - fill)}] {self.done}/{self.total} "
                f"{100 * frac:3.0f}%  {el:5.0f} s elapsed"
                + (f", ~{eta:.0f} s left" if self.done and self.done < self.total else "")
                + (f"  {note}" if note else ""))
        if self.tty:
            self.stream.write("\r" + line[:150].ljust(150))
        else:
            decile = int(10 * frac)
            if decile == self.last_decile and self.done < self.total:
                return
            self.last_decile = decile
            self.stream.write(line + "\n")
        self.stream.flush()

    def close(self):
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()


# --------------------------------------------------------------------------- simulation (workers)

_W = {}  # per worker process: the unzipped FMU and its model description


def _init_worker(fmu_dir):
    from fmpy import read_model_description

    _W["dir"] = fmu_dir
    _W["md"] = read_model_description(fmu_dir)


def simulate(f, A, duration, interval, outputs, overrides=None):
    """One sine-mode run; retried with other output intervals if the FMU refuses a step.
    overrides: other start values (parameters), {name: value}.

    Returns (result or None, output interval used, retries, last FMU error message or '')."""
    from fmpy import simulate_fmu

    err = ""
    for k, fac in enumerate(RETRY_FACTORS):
        msgs = []

        def logger(_env, _inst, status, category, message):
            if status >= 3:  # error, fatal
                msgs.append(message.decode(errors="replace") if isinstance(message, bytes)
                            else str(message))

        h = interval * fac
        try:
            res = simulate_fmu(
                _W["dir"], model_description=_W["md"], fmi_type="CoSimulation",
                start_time=0.0, stop_time=duration, output_interval=h,
                start_values={**(overrides or {}), "excitation": 1, "f_exc": float(f),
                              "A_rms": float(A)},
                output=outputs, logger=logger,
            )
            return res, h, k, err
        except Exception as e:  # noqa: BLE001 (an FMU error: retry, then report)
            err = (msgs[-1] if msgs else f"{type(e).__name__}: {e}").replace("\n", " ")
    return None, interval, len(RETRY_FACTORS), err


def grid_point(task):
    """Statistics of one (f, A_rms) grid point: a flat dict for the CSV."""
    _, f, A, a = task
    t0 = time.perf_counter()
    out = {"f_Hz": f, "A_rms": A}
    try:
        res, h, retries, err = simulate(f, A, a["duration"], a["interval"], GRID_OUTPUTS,
                                       a["set"])
        out.update(output_interval=h, retries=retries, fmu_error=err)
        if res is None:
            out["status"] = "failed"
        else:
            t = res["time"]
            st = rs.rattle_summary(
                t, res["impacts_Fplus"], res["impacts_Fminus"], f, a["t_from"],
                impact_speed=res["impact_speed"],
                energies=(("contact", res["E_contact"]), ("lubricant", res["E_lubricant"])),
                accel=res["a_pitch_L"])
            st["power_dissipated"] = st["power_contact"] + st["power_lubricant"]
            st["run_lengths"] = dist_str(st["run_lengths"])
            dec = rs.free_flight_decay(t, res["omega_L"], res["contact"], a["t_from"])
            st["free_flight_decay"] = float(np.median(dec)) if len(dec) else float("nan")
            fl = rs.free_flights(t, res["contact"], a["t_from"])
            st["free_flights"] = len(fl)
            c = res["contact"]
            for name, keep in (("free_flight_mean_duration", lambda a_, b_: True),
                               ("crossing_flight_mean_duration", lambda a_, b_: a_ != b_),
                               ("bounce_flight_mean_duration", lambda a_, b_: a_ == b_)):
                d = [t[e] - t[s] for s, e in fl if keep(c[s - 1], c[e])]
                st[name] = float(np.mean(d)) if d else float("nan")
            out.update(st)
            out["status"] = "ok" if st["ambiguous"] == 0 else "ambiguous"
    except Exception as e:  # noqa: BLE001 (never let a worker die: report the point)
        out.update(status="failed", fmu_error=f"{type(e).__name__}: {e}")
    out["wall_s"] = time.perf_counter() - t0
    return out


def classify(f, A, a):
    """'none' / 'transient' / 'sustained' (see the module docstring), or None if the FMU
    failed; with the impacts in the window on F+ and F-, the retries and the FMU error."""
    D, win = a["thr_duration"], a["thr_window"]
    res, _, retries, err = simulate(f, A, D, a["thr_interval"], COUNT_OUTPUTS, a["set"])
    if res is None:
        return None, 0, 0, retries, err
    t, p, m = res["time"], res["impacts_Fplus"], res["impacts_Fminus"]
    i = int(np.searchsorted(t, D - win - 1e-12))
    lp, lm = int(p[-1] - p[i]), int(m[-1] - m[i])
    if p[-1] + m[-1] == 0:
        c = "none"
    elif lp + lm == 0:
        c = "transient"
    else:
        c = "sustained"
    return c, lp, lm, retries, err


def threshold(task):
    """No-impact threshold at one frequency: geometric scan, then bisection of both edges."""
    _, f, _, a = task
    t0 = time.perf_counter()
    scan = []  # (A, class, last-window impacts F+, F-)
    stats = {"sims": 0, "retried": 0, "failed": 0, "errors": []}

    def cls(A):
        # a level whose run fails even after the retries is nudged by 0.1 %, not guessed
        for nudge in (1.0, 1.001, 0.999, 1.002):
            c, lp, lm, retries, err = classify(f, A * nudge, a)
            stats["sims"] += retries + (c is not None)
            stats["retried"] += retries > 0
            if err:
                stats["errors"].append(f"{A * nudge:.4g}: {err}")
            if c is not None:
                return c, lp, lm
        stats["failed"] += 1
        return None, 0, 0

    A, streak = a["thr_lo"], None
    while A <= a["thr_hi"]:
        c, lp, lm = cls(A)
        scan.append((A, c, lp, lm))
        if c == "sustained":
            streak = A if streak is None else streak
            if A >= a["thr_confirm"] * streak:
                break
        elif c is not None:
            streak = None
        A *= a["thr_ratio"]
    levels = [s[0] for s in scan]
    classes = [s[1] for s in scan]
    out = {"f_Hz": f, "scan": scan}

    def bisect(lo, hi, is_hi):
        while hi / lo > 1 + a["thr_tol"]:
            mid = math.sqrt(lo * hi)
            c, _, _ = cls(mid)
            if c is None:
                break
            if is_hi(c):
                hi = mid
            else:
                lo = mid
        return lo, hi

    # A_first: lowest level with any impact
    first = next((i for i, c in enumerate(classes) if c not in ("none", None)), None)
    if first is None or first == 0:
        out["A_first"], out["A_first_lo"] = float("nan"), float("nan")
    else:
        lo, hi = bisect(levels[first - 1], levels[first], lambda c: c != "none")
        out["A_first_lo"], out["A_first"] = lo, hi
    # A_sustained: start of the final sustained streak
    if streak is None or levels[-1] < a["thr_confirm"] * streak:
        out["A_sustained"], out["A_sustained_lo"] = float("nan"), float("nan")
        below = []
    else:
        j = levels.index(streak)
        lo, hi = bisect(levels[j - 1], streak, lambda c: c == "sustained") if j else (
            float("nan"), streak)
        out["A_sustained_lo"], out["A_sustained"] = lo, hi
        below = [s for s in scan[:j] if s[1] == "sustained"]
    out["isolated_sustained"] = [s[0] for s in below]
    out["one_sided"] = [(s[0], "F+" if s[3] == 0 else "F-") for s in scan
                        if s[1] == "sustained" and (s[2] == 0 or s[3] == 0)]
    out.update(sims=stats["sims"], retried=stats["retried"], failed=stats["failed"],
               fmu_errors=stats["errors"], wall_s=time.perf_counter() - t0)
    return out


def run_task(task):
    try:
        return task[0], (grid_point(task) if task[0] == "grid" else threshold(task))
    except Exception as e:  # noqa: BLE001
        return task[0], {"f_Hz": task[1], "A_rms": task[2], "status": "failed",
                         "fmu_error": f"{type(e).__name__}: {e}"}


# --------------------------------------------------------------------------- figures

def grid_array(rows, fs, As, key, scale=1.0):
    Z = np.full((len(As), len(fs)), np.nan)
    for r in rows:
        if r.get("status") in ("ok", "ambiguous") and key in r:
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
    ok = [r for r in rows if r.get("status") in ("ok", "ambiguous")]
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
    "runs", "mean_run", "mean_run_Fplus", "mean_run_Fminus", "run_min", "run_max", "run_lengths",
    "mean_impact_speed", "mean_impact_speed_Fplus", "mean_impact_speed_Fminus",
    "max_impact_speed", "runs_decreasing", "min_gap_same_flank", "power_dissipated", "power_contact",
    "power_lubricant", "rms_accel", "free_flight_decay", "free_flights",
    "free_flight_mean_duration", "crossing_flight_mean_duration", "bounce_flight_mean_duration",
    "ambiguous", "output_interval", "retries", "wall_s", "fmu_error",
]


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
            "isolated_sustained", "one_sided", "scan", "sims", "retried", "failed", "wall_s",
            "fmu_errors"]
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
            row["fmu_errors"] = " | ".join(t.get("fmu_errors", []))
            w.writerow([fmt_cell(row.get(c, "")) for c in cols])
    return path


def summary_lines(rows, thr, fs, As, p, meta):
    L = []
    rows = sorted(rows, key=lambda r: (r["f_Hz"], r["A_rms"]))
    ok = [r for r in rows if r.get("status") in ("ok", "ambiguous")]
    bad = [r for r in rows if r.get("status") == "failed"]
    amb = [r for r in rows if r.get("status") == "ambiguous"]
    retried = [r for r in rows if r.get("retries", 0)]
    L.append(f"Grid: f = {fs[0]:g}..{fs[-1]:g} Hz ({len(fs)} values) x A_rms = {As[0]:g}.."
             f"{As[-1]:g} rad/s^2 RMS ({len(As)} values): {len(rows)} points, {len(ok)} ok, "
             f"{len(bad)} failed, {len(retried)} retried after an FMU step failure, "
             f"{len(amb)} with ambiguous impact order (output interval too coarse)")
    L.append(f"  {param_note(p, meta)}; runs of {meta['duration']:g} s, statistics {meta['t_from']:g}-"
             f"{meta['duration']:g} s, output interval {meta['interval']:g} s")
    for r in bad:
        L.append(f"  FAILED f={r['f_Hz']:g} A={r['A_rms']:g}: {r.get('fmu_error', '')}")
    if not ok:
        return L
    f, A, disp, run, v, arms = collapse_data(rows, p)

    def rng(x, scale=1.0, fmt="{:.2f}"):
        return f"{fmt.format(np.nanmin(x) * scale)}..{fmt.format(np.nanmax(x) * scale)}"

    ipp = np.array([r["impacts_per_period"] for r in ok])
    pw = np.array([r["power_dissipated"] for r in ok])
    pc = np.array([r["power_contact"] for r in ok])
    dec = np.array([r["free_flight_decay"] for r in ok])
    gap = np.array([r["min_gap_same_flank"] for r in ok])
    asym = np.array([abs(r["impacts_Fplus"] - r["impacts_Fminus"]) /
                     max(r["impacts_Fplus"] + r["impacts_Fminus"], 1) for r in ok])
    L.append("Over the grid (min..max):")
    L.append(f"  impacts per period (F+ + F-): {rng(ipp)}")
    L.append(f"  mean run on one flank:        {rng(run)}; every complete run on the grid has "
             f"length {int(np.nanmin([r['run_min'] for r in ok]))}.."
             f"{int(np.nanmax([r['run_max'] for r in ok]))}")
    short = [f"{r['f_Hz']:g}/{r['A_rms']:g}" for r in ok if r["mean_run"] < 2]
    L.append(f"  mean run < 2 at {len(short)} of {len(ok)} points (f Hz/A_rms): "
             + (" ".join(short) or "-"))
    L.append(f"  mean impact speed:            {rng(v, fmt='{:.1f}')} mm/s")
    L.append(f"  dissipated power:             {rng(pw, 1e3, '{:.0f}')} mW, of which contact "
             f"{rng(pc / pw, 100, '{:.1f}')} % ({rng(pc, 1e3, '{:.1f}')} mW)")
    L.append(f"  RMS pitch-line acceleration:  {rng(arms, fmt='{:.1f}')} m/s^2")
    L.append(f"  |F+ - F-| / (F+ + F-) impacts: at most {100 * np.max(asym):.1f} %; above 5 % in "
             f"{np.count_nonzero(asym > 0.05)} of {len(ok)} points (more on F+ in "
             f"{sum(1 for r, a_ in zip(ok, asym) if a_ > 0.05 and r['impacts_Fplus'] > r['impacts_Fminus'])}"
             f", on F- in "
             f"{sum(1 for r, a_ in zip(ok, asym) if a_ > 0.05 and r['impacts_Fplus'] < r['impacts_Fminus'])})")
    vp = np.array([r["mean_impact_speed_Fplus"] for r in ok])
    vm = np.array([r["mean_impact_speed_Fminus"] for r in ok])
    dv = (vp - vm) / (0.5 * (vp + vm))
    L.append(f"  mean impact speed F+ vs F-: differ by more than 5 % in "
             f"{np.count_nonzero(np.abs(dv) > 0.05)} of {len(ok)} points (faster on F+ in "
             f"{np.count_nonzero(dv > 0.05)}, on F- in {np.count_nonzero(dv < -0.05)}); at most "
             f"{100 * np.nanmax(np.abs(dv)):.0f} %")
    dur = np.array([r["free_flight_mean_duration"] for r in ok])
    rd = np.array([r["runs_decreasing"] for r in ok])
    L.append(f"  runs of >= 2 impacts whose impact speeds decrease along the run: "
             f"{rng(rd, 100, '{:.0f}')} % of the runs of a point; 100 % at "
             f"{np.count_nonzero(rd == 1)} of {np.count_nonzero(np.isfinite(rd))} points")
    L.append(f"  mean free-flight duration: {rng(dur, 1e3)} ms, i.e. the speed decays by "
             f"{100 * (1 - np.exp(-p['C'] / p['I_L'] * np.nanmin(dur))):.0f}.."
             f"{100 * (1 - np.exp(-p['C'] / p['I_L'] * np.nanmax(dur))):.0f} % over a mean flight")
    L.append(f"  shortest time between two impacts on one flank: {1e3 * np.nanmin(gap):.2f} ms "
             f"(output interval {1e3 * meta['interval']:.3f} ms)")
    L.append(f"  free-flight speed decay rate (median per point): {rng(dec, fmt='{:.2f}')} 1/s "
             f"(C* = C/I_L = {p['C'] / p['I_L']:.2f} 1/s)")
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
    # Along the level at fixed frequency: more impacts? stronger?
    L.append("Raising the level at fixed f (first -> last A_rms of the grid):")
    for fv in sorted({fs[0], fs[len(fs) // 2], fs[-1]}):
        col = sorted((r for r in ok if r["f_Hz"] == fv), key=lambda r: r["A_rms"])
        if len(col) >= 2:
            a0, a1 = col[0], col[-1]
            L.append(f"  {fv:g} Hz, {a0['A_rms']:g} -> {a1['A_rms']:g}: impacts/period "
                     f"{a0['impacts_per_period']:.2f} -> {a1['impacts_per_period']:.2f}, mean run "
                     f"{a0['mean_run']:.2f} -> {a1['mean_run']:.2f}, impact speed "
                     f"{1e3 * a0['mean_impact_speed']:.1f} -> {1e3 * a1['mean_impact_speed']:.1f}"
                     f" mm/s, RMS accel {a0['rms_accel']:.1f} -> {a1['rms_accel']:.1f} m/s^2")
    lv = [s["A_rms"] for s in SCENES if s["name"] in ("S1", "S3")]
    if len(lv) == 2 and all(x in As for x in lv):
        lo_, hi_ = lv
        cmp_ = []
        for fv in fs:
            r0 = next((r for r in ok if r["f_Hz"] == fv and r["A_rms"] == lo_), None)
            r1 = next((r for r in ok if r["f_Hz"] == fv and r["A_rms"] == hi_), None)
            if r0 and r1:
                cmp_.append((fv, r0, r1))
        fewer = [fv for fv, r0, r1 in cmp_ if r1["impacts_per_period"] < r0["impacts_per_period"]]
        same = [fv for fv, r0, r1 in cmp_ if r1["impacts_per_period"] == r0["impacts_per_period"]]
        faster = [fv for fv, r0, r1 in cmp_ if r1["mean_impact_speed"] > r0["mean_impact_speed"]]
        harder = [fv for fv, r0, r1 in cmp_ if r1["rms_accel"] > r0["rms_accel"]]
        L.append(f"S1 -> S3 level ({lo_:g} -> {hi_:g} rad/s^2) at each of {len(cmp_)} frequencies: "
                 f"more impacts per period at {len(cmp_) - len(fewer) - len(same)}, as many at "
                 f"{len(same)}, fewer at {len(fewer)} ({', '.join(f'{x:g}' for x in fewer) or '-'}"
                 f" Hz); higher mean impact speed at {len(faster)}, higher RMS acceleration at "
                 f"{len(harder)}")
    L.append("Bench scenes (cells of this map; cf. `make demo` and MODEL.md section 5):")
    for s in SCENES:
        r = next((r for r in ok if r["f_Hz"] == s["f"] and r["A_rms"] == s["A_rms"]), None)
        if r is None:
            continue
        span = meta["duration"] - meta["t_from"]
        L.append(f"  {s['name']} ({s['f']:g} Hz, {s['A_rms']:g}): impacts/s F+/F- "
                 f"{r['impacts_Fplus'] / span:.1f}/{r['impacts_Fminus'] / span:.1f}, runs "
                 f"{r['run_lengths']}, mean impact speed {1e3 * r['mean_impact_speed']:.1f} mm/s,"
                 f" RMS accel {r['rms_accel']:.1f} m/s^2, mean free flight "
                 f"{1e3 * r['free_flight_mean_duration']:.2f} ms (across the gap "
                 f"{1e3 * r['crossing_flight_mean_duration']:.2f}, bounces on one flank "
                 f"{1e3 * r['bounce_flight_mean_duration']:.2f}), impact speeds decreasing "
                 f"along {100 * r['runs_decreasing']:.0f} % of the runs")
        if not meta["set"]:  # the references hold for the paper's parameters only
            L.append(f"      model reference: {s['model_ref']}")
        L.append(f"      paper (measured): {s['paper']}")
    if thr:
        L.append("No-impact threshold (A_rms in rad/s^2 RMS; [lo, hi] brackets of the bisection):")
        L.append(f"  {'f Hz':>5}  {'A_first':>16}  {'A_sustained':>16}  isolated sustaining "
                 f"levels below the onset; one-sided sustained levels")
        for t in sorted(thr, key=lambda t: t["f_Hz"]):
            iso = ", ".join(f"{x:.3g}" for x in t["isolated_sustained"]) or "-"
            one = ", ".join(f"{x:.3g} ({fl} only)" for x, fl in t["one_sided"]) or "-"
            L.append(f"  {t['f_Hz']:5g}  {t['A_first']:6.3g} [{t['A_first_lo']:.3g},"
                     f"{t['A_first']:.3g}]  {t['A_sustained']:6.3g} [{t['A_sustained_lo']:.3g},"
                     f"{t['A_sustained']:.3g}]  {iso}; {one}")
        fails = sum(t.get("failed", 0) for t in thr)
        retr = sum(t.get("retried", 0) for t in thr)
        sims = sum(t.get("sims", 0) for t in thr)
        L.append(f"  {sims} threshold runs; {retr} levels needed a retry after an FMU step "
                 f"failure (see threshold.csv, fmu_errors); {fails} levels failed at every "
                 f"output interval and 0.1 % nudge (left out of the search)")
        f_thr = np.array([t["f_Hz"] for t in thr])
        a2 = np.array([t["A_sustained"] for t in thr])
        for key, name in (("A_first", "first impact"), ("A_sustained", "sustained rattle")):
            fit = power_fit(f_thr, np.array([t[key] for t in thr]))
            if fit:
                L.append(f"  fit of the {name} (least squares of ln A on ln f): "
                         f"{fit[0]:.2f} (f/30 Hz)^{fit[1]:.2f}")
        if np.any(np.isfinite(a2)):
            L.append(f"  highest onset of sustained rattle: {np.nanmax(a2):.3g} rad/s^2, "
                     f"{As[0] / np.nanmax(a2):.1f}x below the lowest level of the grid "
                     f"({As[0]:g})")
    return L


# --------------------------------------------------------------------------- main

def frange(lo, hi, step):
    n = int(round((hi - lo) / step))
    return [round(lo + i * step, 10) for i in range(n + 1)]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fmu", default=os.path.join(ROOT, "target", "fmu", "GearRattle.fmu"))
    ap.add_argument("--out", default=os.path.join(ROOT, "target", "rattle_map"))
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--f", default="30:60:2", help="frequencies lo:hi:step [Hz]")
    ap.add_argument("--A", default="100:700:50", help="levels lo:hi:step [rad/s^2 RMS]")
    ap.add_argument("--duration", type=float, default=1.0, help="simulated time per point [s]")
    ap.add_argument("--t-from", type=float, default=0.2, help="statistics from here [s]")
    ap.add_argument("--interval", type=float, default=5e-5,
                    help="output interval of the grid runs [s] (impacts are read from the "
                         "counters: at most one impact per interval)")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="override a parameter's start value (repeatable), e.g. --set G=80e-6; "
                         "the default is the paper's parameters")
    ap.add_argument("--no-threshold", action="store_true", help="skip the threshold search")
    ap.add_argument("--threshold-duration", type=float, default=1.0)
    ap.add_argument("--threshold-window", type=float, default=0.4)
    ap.add_argument("--threshold-interval", type=float, default=1e-3)
    ap.add_argument("--threshold-tol", type=float, default=0.005,
                    help="relative width of the bisection's final bracket")
    args = ap.parse_args(argv)

    if not os.path.isfile(args.fmu):
        print(f"rattle_map: no FMU at {args.fmu}: build it first (make fmu)", file=sys.stderr)
        return 2
    if not 0 <= args.t_from < args.duration:
        ap.error("need 0 <= --t-from < --duration")
    if not 0 < args.threshold_window < args.threshold_duration:
        ap.error("need 0 < --threshold-window < --threshold-duration")
    overrides = {}
    for item in args.set:
        name, _, val = item.partition("=")
        try:
            overrides[name.strip()] = float(val)
        except ValueError:
            ap.error(f"--set {item}: expected NAME=number")
    fs = frange(*map(float, args.f.split(":")))
    As = frange(*map(float, args.A.split(":")))
    os.makedirs(args.out, exist_ok=True)
    meta = dict(duration=args.duration, t_from=args.t_from, interval=args.interval,
                thr_duration=args.threshold_duration, thr_window=args.threshold_window,
                thr_interval=args.threshold_interval, thr_tol=args.threshold_tol,
                thr_lo=0.5, thr_hi=As[0], thr_ratio=1.08, thr_confirm=1.5, set=overrides)

    from fmpy import extract

    t_all = time.perf_counter()
    fmu_dir = extract(args.fmu)
    try:
        md, p = read_params(fmu_dir)
        params = {v.name for v in md.modelVariables if v.causality == "parameter"}
        bad = sorted(set(overrides) - params) + sorted(
            {"excitation", "f_exc", "A_rms"} & set(overrides))
        if bad:
            ap.error(f"--set: not a settable parameter here: {', '.join(bad)} (parameters: "
                     f"{', '.join(sorted(params - {'excitation', 'f_exc', 'A_rms'}))})")
        p.update(overrides)
        tasks = [] if args.no_threshold else [("thr", f, None, meta) for f in fs]
        tasks += [("grid", f, A, meta) for f in fs for A in As]
        print(f"rattle map: {args.fmu}; {len(fs)} x {len(As)} grid points"
              + ("" if args.no_threshold else f" + threshold search at {len(fs)} frequencies")
              + f" on {args.workers} workers", file=sys.stderr)
        rows, thr = [], []
        bar = Progress(len(tasks), "rattle map")
        with mp.get_context("fork").Pool(args.workers, initializer=_init_worker,
                                         initargs=(fmu_dir,)) as pool:
            for kind, r in pool.imap_unordered(run_task, tasks):
                if kind == "grid":
                    rows.append(r)
                    note = f"{r['f_Hz']:g} Hz {r['A_rms']:g}: {r.get('status')}"
                else:
                    thr.append(r)
                    note = f"threshold {r['f_Hz']:g} Hz: {r.get('A_sustained', float('nan')):.3g}"
                bar.update(1, note)
        bar.close()
        wall_sim = time.perf_counter() - t_all
    finally:
        shutil.rmtree(fmu_dir, ignore_errors=True)

    thr_failed = [t for t in thr if "scan" not in t]
    thr = sorted((t for t in thr if "scan" in t), key=lambda t: t["f_Hz"])
    rows.sort(key=lambda r: (r["f_Hz"], r["A_rms"]))
    files = [write_grid_csv(rows, os.path.join(args.out, "rattle_map.csv"))]
    if thr:
        files.append(write_threshold_csv(thr, os.path.join(args.out, "threshold.csv")))
    files += map_figures(rows, fs, As, args.out, meta, p)
    if thr:
        files.append(threshold_figure(thr, args.out, meta, (As[0], As[-1]), p))
    files.append(collapse_figure(rows, p, args.out))
    lines = summary_lines(rows, thr, fs, As, p, meta)
    for t in thr_failed:
        lines.append(f"THRESHOLD SEARCH FAILED at {t['f_Hz']:g} Hz: {t.get('fmu_error', '')}")
    lines.append(f"wall time: {time.perf_counter() - t_all:.1f} s (simulations "
                 f"{wall_sim:.1f} s on {args.workers} workers)")
    path = os.path.join(args.out, "summary.txt")
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    files.append(path)
    print("\n".join(lines))
    print("files:")
    for f in files:
        print("  " + os.path.relpath(f))
    failed = [r for r in rows if r.get("status") == "failed"]
    return 1 if failed or thr_failed else 0


if __name__ == "__main__":
    sys.exit(main())
