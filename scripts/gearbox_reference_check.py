"""Check the gearbox reference (gearrattle.gearbox_reference) against docs/GEARBOX.md §8.

Slow (minutes on a 2-core machine), not part of the test suite:

    PYTHONPATH=python .venv/bin/python scripts/gearbox_reference_check.py [--parts ...]

Parts: B1 and B2 (impacts per second per gear over 0.5-2 s, the damper's main-stage share
and largest twist), chaos (how long a perturbation of xi_1(0) stays below 1e-4 G: the
window over which trajectories can be compared pointwise), radau (DOP853 at rtol 1e-12
against DOP853 at 1e-13 and Radau at 1e-11 over the start), rundown (R1, a run-down 800 ->
500 rpm in 2 s), spread (the rates of B1 and R1 under perturbations of
xi_1(0), not run by default).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from gearrattle import gearbox_reference as B

DT = 1e-4  # output spacing of the runs [s]


def grid(t_end: float) -> np.ndarray:
    return np.arange(int(round(t_end / DT)) + 1) * DT


def run(scene: str, t_end: float, method: str = "DOP853", rtol: float = 1e-12, **over):
    p = B.params(scene, **over)
    t0 = time.process_time()
    r = B.simulate(p, t_end, t_eval=grid(t_end), method=method, rtol=rtol)
    return r, time.process_time() - t0


def rates_report(scene: str, t_end: float = 2.0):
    r, cpu = run(scene, t_end)
    e = r.energy()
    rates = r.impact_rates(0.5, t_end)
    flanks = [
        (int(np.count_nonzero((d["t"] >= 0.5) & (d["flank"] == B.FPLUS))), int(np.count_nonzero((d["t"] >= 0.5) & (d["flank"] == B.FMINUS))))
        for d in r.impacts
    ]
    sel = r.t >= 0.5
    print(f"{scene}: {t_end} s in {cpu:.0f} s CPU ({r.nsteps} steps, {r.npieces} pieces, {r.nfev} RHS calls)")
    print(f"  impacts/s per gear over 0.5-{t_end} s: " + " / ".join(f"{x:.0f}" for x in rates))
    print("  impacts over the whole run per gear: " + " / ".join(str(d["t"].size) for d in r.impacts))
    print("  impacts F+ / F- per gear over the window: " + "  ".join(f"{a}/{b}" for a, b in flanks))
    print(f"  damper main stage {100 * r.main_stage_share(0.5, t_end):.1f} % of 0.5-{t_end} s; twist "
          f"{math.degrees(r.phi[sel].min()):+.2f} .. {math.degrees(r.phi[sel].max()):+.2f} deg "
          f"(whole run {math.degrees(r.phi.min()):+.2f} .. {math.degrees(r.phi.max()):+.2f})")
    a_I = np.gradient(r.omega_I, r.t)
    print(f"  input side acceleration {np.sqrt(np.mean(a_I[sel] ** 2)):.0f} rad/s^2 RMS over the window")
    print(f"  energy balance: max |balance| {np.abs(e['balance']).max():.2e} J, E(0) = {e['E'][0]:.3f} J")
    return r


def divergence(a, b, G) -> np.ndarray:
    """max over gears of |xi_a - xi_b| / G_i at each output time."""
    return np.max(np.abs(a.xi - b.xi) / G[:, None], axis=0)


def first_above(t, d, level):
    k = np.flatnonzero(d >= level)
    return t[k[0]] if k.size else None


def chaos_report(scene: str, t_end: float, base=None, deltas=(1e-10,)):
    base = base if base is not None and base.t[-1] >= t_end else run(scene, t_end)[0]
    if base.t[-1] > t_end:
        base = _truncate(base, t_end)
    n = base.xi.shape[0]
    G = np.array([base.params[f"gear[{i + 1}].G"] for i in range(n)])
    for delta in deltas:
        gs = base.params["gear[1].gap_start"] + delta
        r, cpu = run(scene, t_end, **{"gear[1].gap_start": gs})
        d = divergence(base, r, G)
        t4 = first_above(r.t, d, 1e-4)
        marks = ", ".join(f"{lv:g}·G at {_when(first_above(r.t, d, lv))}" for lv in (1e-8, 1e-6, 1e-4, 1e-2))
        t_cmp = r.t[-1] if t4 is None else t4
        same = np.array_equal(base.impact_counts(t_cmp), r.impact_counts(t_cmp))
        print(f"{scene}: xi_1(0) + {delta:g}·G: max_i |dxi_i|/G_i reaches {marks} (run {t_end} s, {cpu:.0f} s CPU);"
              f" impact counts per gear equal up to {t_cmp:.4f} s: {same}", flush=True)


def _when(t):
    return "never" if t is None else f"{t:.4f} s"


def _truncate(r, t_end):
    k = np.searchsorted(r.t, t_end, side="right")
    r.t, r.xi = r.t[:k], r.xi[:, :k]
    return r


def radau_report(scene: str, t_end: float):
    """The reference's own error: DOP853 at rtol 1e-12 against DOP853 at 1e-13 and against
    Radau at 1e-11, max_i |dxi_i|/G_i at a few times."""
    a, ca = run(scene, t_end)
    n = a.xi.shape[0]
    G = np.array([a.params[f"gear[{i + 1}].G"] for i in range(n)])
    marks = [t for t in (0.02, 0.05, 0.1, 0.2, 0.3, 0.4) if t <= t_end]
    for method, rtol in (("DOP853", 1e-13), ("Radau", 1e-11)):
        b, cb = run(scene, t_end, method=method, rtol=rtol)
        d = np.maximum.accumulate(divergence(a, b, G))
        at = ", ".join(f"{d[int(round(t / DT))]:.1e} by {t} s" for t in marks)
        ia = [x["t"].size for x in a.impacts]
        ib = [x["t"].size for x in b.impacts]
        print(f"{scene}: DOP853 1e-12 ({ca:.0f} s CPU) vs {method} {rtol:g} ({cb:.0f} s CPU): max |dxi|/G {at};"
              f" impacts per gear {ia} vs {ib}", flush=True)


def spread_report(scene: str, t_end: float = 2.0, deltas=(0.0, 1e-10, 1e-8, 1e-6)):
    """Impacts per second per gear over stats_from..t_end for runs whose xi_1(0) differs by
    delta·G: the spread a rate from another solver can be judged against."""
    rates = []
    for delta in deltas:
        r, cpu = run(scene, t_end, **{"gear[1].gap_start": 0.5 + delta})
        rates.append(r.impact_rates(0.5, t_end))
        print(f"{scene}: xi_1(0) + {delta:g}·G: impacts/s " + " / ".join(f"{x:.1f}" for x in rates[-1])
              + f", main stage {100 * r.main_stage_share(0.5, t_end):.1f} % ({cpu:.0f} s CPU)", flush=True)
    rates = np.array(rates)
    mid = rates.mean(axis=0)
    print(f"{scene}: spread (max - min) / mean per gear: " + " / ".join(f"{x:.1%}" for x in (rates.max(0) - rates.min(0)) / mid))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--parts", nargs="+", default=["B1", "B2", "rundown", "chaos", "radau"])
    args = ap.parse_args()
    base = {}
    for part in args.parts:
        if part in ("B1", "B2"):
            base[part] = rates_report(part)
        elif part == "chaos":
            chaos_report("B1", 1.0, base.get("B1"), deltas=(1e-12, 1e-10, 1e-8, 1e-6))
            chaos_report("B2", 2.0, base.get("B2"), deltas=(1e-10, 1e-6))
            chaos_report("R1", 1.0, base.get("R1"), deltas=(1e-10, 1e-8, 1e-6))
        elif part == "radau":
            radau_report("B1", 0.4)
        elif part == "spread":
            spread_report("B1")
            spread_report("R1")
        elif part == "rundown":
            base["R1"] = rates_report("R1")
        else:
            raise SystemExit(f"unknown part {part}")
        print(flush=True)


if __name__ == "__main__":
    main()
