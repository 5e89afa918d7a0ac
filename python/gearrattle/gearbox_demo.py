"""The gearbox demo (docs/GEARBOX.md): the default five-speed box in neutral at idle and on a
run-down from 1000 to 600 rpm, with the oil at 40 °C, −10 °C and 80 °C, run through fmpy.
Prints per gear its impacts per second per flank, runs, mean impact speed, rattle power and
share, and the damper's main-stage share and mean drag; draws per temperature the gears' xi
in their bands with their impacts and the damper's twist against its stages, and the gears'
impact rates against engine speed on the run-down. Called by gearrattle.demo.run()."""

from __future__ import annotations

import math
import os
import time

import numpy as np

from . import gearbox_fmu as GF

T_END, DT = 2.0, 1e-4
STATS_FROM = 0.5
TEMPERATURES = (40.0, -10.0, 80.0)
RUN_DOWN = dict(rpm=1000.0, rpm_rate=-200.0)  # 1000 -> 600 rpm over T_END
RATE_BIN = 0.1  # s: the run-down's rates over 20 rpm
SHOWN = (1.0, 1.25)  # s: the span the idle figure draws
FLANKS = ("Fplus", "Fminus")


def _start(md) -> dict:
    """The contract's start values the demo reads (docs/GEARBOX.md §6's defaults)."""
    starts = {v.name: v.start for v in md.modelVariables if v.causality == "parameter"}
    n = int(starts["n_gears"])
    return dict(n=n, G=[float(starts[f"gear[{i}].G"]) for i in range(1, n + 1)], phi_1=float(starts["phi_1"]))


def _run(fmu, md, **start):
    t0 = time.perf_counter()
    res = GF.simulate(fmu, T_END, DT, gear_fields=GF.GEAR_OUTPUTS + GF.GEAR_STATS, model_description=md,
                      stats_from=STATS_FROM, **start)
    return res, time.perf_counter() - t0


def _last(res, field) -> np.ndarray:
    return GF.per_gear(res, field)[:, -1]


def print_idle(res, T, wall):
    sel = res["time"] >= STATS_FROM
    main = np.mean(res["damper_stage"][sel] == 2)
    drag = np.mean(res["T_drag"][sel])
    print(f"\n=== idle 800 rpm, oil {T:g} °C ({wall:.1f} s): damper in its main stage "
          f"{100 * main:.0f} % of the time, mean drag {drag:.2f} N m, rattle power "
          f"{res['stat_rattle_power'][-1]:.3g} W")
    print("  gear  impacts/s F+ / F-   runs F+ / F-   v_mean F+ / F- [mm/s]   power [W]  share")
    rate = [_last(res, f"stat_impact_rate_{f}") for f in FLANKS]
    runs = [_last(res, f"stat_runs_{f}") for f in FLANKS]
    v = [1e3 * _last(res, f"stat_v_mean_{f}") for f in FLANKS]
    power, share = _last(res, "stat_rattle_power"), _last(res, "stat_rattle_share")
    for i in range(power.size):
        print(f"  {i + 1:>4}  {rate[0][i]:8.1f} / {rate[1][i]:<8.1f} {runs[0][i]:6.0f} / {runs[1][i]:<6.0f} "
              f"{v[0][i]:9.1f} / {v[1][i]:<9.1f}   {power[i]:9.3g}  {100 * share[i]:4.0f} %")


def run_down_rates(res):
    """Engine speed [rpm] at the bins' middles and each gear's impact rate there (N, bins)."""
    t = res["time"]
    edges = np.arange(0.0, T_END + 1e-9, RATE_BIN)
    k = np.searchsorted(t, edges - 1e-9)
    counts = GF.impact_counts(res)[:, k]
    mid = 0.5 * (edges[1:] + edges[:-1])
    return RUN_DOWN["rpm"] + RUN_DOWN["rpm_rate"] * mid, np.diff(counts, axis=1) / RATE_BIN


def idle_figure(path, res, T, box):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = res["time"]
    w = (t >= SHOWN[0]) & (t <= SHOWN[1])
    xi, counts = GF.per_gear(res, "xi"), GF.impact_counts(res)
    fig, axes = plt.subplots(box["n"] + 1, 1, figsize=(9, 1.6 * (box["n"] + 1)), sharex=True)
    for i, ax in enumerate(axes[:-1]):
        G = box["G"][i]
        ax.plot(t[w], xi[i, w] / G, lw=0.7)
        hit = w & np.append(False, np.diff(counts[i]) > 0)
        ax.plot(t[hit], xi[i, hit] / G, "r.", ms=3)
        ax.axhline(0, color="k", lw=0.5)
        ax.axhline(1, color="k", lw=0.5)
        ax.set_ylabel(f"xi_{i + 1} / G")
    ax = axes[-1]
    ax.plot(t[w], np.degrees(res["phi"][w]), lw=0.7)
    for s in (-1, 1):
        ax.axhline(s * math.degrees(box["phi_1"]), color="k", ls="--", lw=0.5)
    ax.set_ylabel("twist phi [°]")
    ax.set_xlabel("t [s]")
    axes[0].set_title(f"Idle 800 rpm, oil {T:g} °C: each gear in its backlash (red: impacts),\n"
                      f"the damper's twist against its pre-damper's travel (dashed)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run_down_figure(path, curves, box):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(box["n"], 1, figsize=(8, 1.7 * box["n"]), sharex=True)
    for T, (rpm, rates) in curves.items():
        for i, ax in enumerate(axes):
            ax.plot(rpm, rates[i], label=f"{T:g} °C")
    for i, ax in enumerate(axes):
        ax.set_ylabel(f"gear {i + 1} [1/s]")
    axes[0].legend(fontsize=8, ncol=3)
    axes[0].set_title("Run-down 1000 -> 600 rpm: impacts per second per gear against engine speed")
    axes[-1].set_xlabel("engine speed [rpm]")
    axes[-1].invert_xaxis()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run(fmu=GF.GEARBOX_FMU, out="target/demo"):
    """The gearbox part of the demo; returns the figures' paths."""
    from fmpy import read_model_description

    md = read_model_description(str(fmu))
    box = _start(md)
    print(f"\nGearbox demo: {fmu}, {box['n']} gears (the contract's defaults, docs/GEARBOX.md §6), "
          f"{T_END:g} s per run, statistics from {STATS_FROM:g} s")
    figures, curves = [], {}
    for T in TEMPERATURES:
        res, wall = _run(fmu, md, T_oil=T)
        print_idle(res, T, wall)
        path = os.path.join(out, f"gearbox_idle_{T:g}C.png")
        idle_figure(path, res, T, box)
        figures.append(path)
        down, wall = _run(fmu, md, T_oil=T, **RUN_DOWN)
        curves[T] = run_down_rates(down)
        rpm, rates = curves[T]
        print(f"  run-down 1000 -> 600 rpm ({wall:.1f} s): impacts/s per gear at "
              + ", ".join(f"{rpm[k]:.0f} rpm {np.array2string(rates[:, k], precision=0)}" for k in (0, rpm.size // 2, -1)))
    path = os.path.join(out, "gearbox_run_down.png")
    run_down_figure(path, curves, box)
    figures.append(path)
    return figures
