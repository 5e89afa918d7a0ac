"""docs/work_precision.png: each solver's work-precision curve per scene."""

import math

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from precision.report.curves import curve_any  # noqa: E402
from precision.report.names import FMPY, FMU_C, GR, RUST_PEERS, SCIPY, TARGET, USER_RHS  # noqa: E402

STYLE = {
    GR: dict(color="k", marker="o", lw=2.2),
    "differential-equations DOPRI5": dict(color="tab:blue", marker="s"),
    "differential-equations DOP853": dict(color="tab:cyan", marker="D"),
    "diffsol Tsit45": dict(color="tab:purple", marker="^"),
    USER_RHS[0]: dict(color="tab:blue", marker="s", ls=":", mfc="none"),
    USER_RHS[1]: dict(color="tab:cyan", marker="D", ls=":", mfc="none"),
    USER_RHS[2]: dict(color="tab:purple", marker="^", ls=":", mfc="none"),
    "scipy RK45": dict(color="tab:orange", marker="v", ls="--"),
    "scipy DOP853": dict(color="tab:red", marker="<", ls="--"),
    "scipy Radau": dict(color="tab:brown", marker=">", ls="--"),
    "scipy LSODA": dict(color="tab:olive", marker="x", ls="--"),
    f"{FMU_C} @ 1 ms": dict(color="tab:green", marker="+", ls=":"),
    f"{FMU_C} @ 10 us": dict(color="tab:green", marker="*", ls="-."),
    f"{FMPY} @ 1 ms": dict(color="tab:gray", marker="P", ls="none"),
}


def plot(rows, scenes, path):
    names = [s["scene"] for s in scenes]
    ordered = ["S1-1s"] + [n for n in names if n != "S1-1s"]
    ncol = 4
    nrow = math.ceil(len(ordered) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(5.2 * ncol, 4.4 * nrow), squeeze=False)
    lines = {}
    for ax, name in zip(axes.flat, ordered):
        sc = next(s for s in scenes if s["scene"] == name)
        series = [(s, s, "") for s in [GR] + RUST_PEERS + SCIPY]
        series += [(f"{FMU_C} @ 1 ms", FMU_C, "1.000000e-3"), (f"{FMU_C} @ 10 us", FMU_C, "1.000000e-5"),
                   (f"{FMPY} @ 1 ms", FMPY, "1.000000e-3")]
        for label, solver, comm in series:
            pts = [p for p in curve_any(rows, solver, name, comm) if p[1] > 0 and p[2] > 0]
            if not pts:
                continue
            (ln,) = ax.loglog([p[2] for p in pts], [p[1] for p in pts], label=label, ms=5, **STYLE[label])
            lines[label] = ln
        if name.startswith("S1-") and "IL" not in name and "CLM" not in name:
            ax.axhline(TARGET, color="0.6", lw=0.8)
        ax.set_title(f"{name}: window {float(sc['window']) * 1e3:.0f} ms", fontsize=10)
        ax.set_xlabel("CPU time [s]")
        ax.set_ylabel("max |Δξ| [m]")
        ax.grid(True, which="major", alpha=0.3)
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    for ax in list(axes.flat)[len(ordered):]:
        ax.axis("off")
    fig.legend(lines.values(), lines.keys(), loc="lower center", ncol=6, fontsize=9, frameon=False)
    fig.suptitle("GearRattle work-precision: error in ξ over the predictable window vs CPU time "
                 "(median of interleaved repeats); tolerance sweep 1e-3 … 1e-10", fontsize=12)
    fig.tight_layout(rect=(0, 0.07, 1, 0.96))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
