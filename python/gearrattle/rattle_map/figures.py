"""The rattle map's figures: heat maps of the grid with the bench scenes marked, the threshold
against frequency, and the paper's section 9 claims (runs against the main shaft's
displacement, impact strength against the acceleration level)."""

import math
import os

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import BoundaryNorm, LogNorm  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402
from matplotlib.ticker import FuncFormatter  # noqa: E402

from ..scenes import SCENES  # noqa: E402
from .grid import collapse_data, param_note, power_fit, spearman  # noqa: E402


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
