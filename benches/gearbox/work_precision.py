"""The coupled default box against scipy at equal error (docs/GEARBOX.md §11, the method in
docs/DECISIONS.md D59). Both sides are swept over their tolerance on B1's predictable window
and measured on one output grid:

* error: the largest |xi_i - xi_ref,i| / G_i over the five gears and the grid's points, the
  reference being DOP853 at rtol 1e-12 with every edge located (gearbox_reference); its own
  error is estimated by the same run at 1e-13;
* the FMU: stepped from one grid point to the next (the communication points a user asks
  for), the five xi read at each, in one call of its sampling entry (gearrattle.calls.sample:
  an fmi2DoStep and an fmi2GetReal a point inside the FMU, without Python's cost a call), its
  tolerance set by fmi2SetupExperiment;
* scipy: each of solve_ivp's methods driven by the reference's piecewise integration (edges
  located, a restart at each), the grid as its output times;
* cost: CPU time (time.process_time) per simulated second, the FMU's from fmi2Instantiate to
  its last output (the FMU unzipped and its library loaded once, as a user's session does),
  scipy's of the whole call; the median of 3 runs under 2 s.

The cost at an error level is interpolated on each log-log curve between the two tolerances
that bracket it (precision.report.curves.cost_at, the work-precision bench's rule)."""

from __future__ import annotations

import csv
import math
import statistics
import time
from dataclasses import dataclass

import numpy as np

from gearrattle import gearbox_fmu as GF
from gearrattle import gearbox_reference as R
from gearrattle.calls import sample
from gearrattle.piecewise import output_grid

from gearbox.runs import Stepper
from precision.report.curves import cost_at

WINDOW = 0.35  # s: B1's pointwise-predictable window (docs/GEARBOX.md §8)
GRID = 1e-3  # s: the output grid of both sides, where the error is measured
REF_RTOL, CHECK_RTOL = 1e-12, 1e-13
FMU = "FMU"
METHODS = ["RK45", "DOP853", "LSODA", "Radau", "BDF"]
FMU_TOLS = [10.0**-k for k in range(4, 13)]
SCIPY_TOLS = [10.0**-k for k in range(4, 12)]
LEVELS = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6]  # G: the errors at which the costs are compared
RUN_LIMIT = 30.0  # s: a scipy run longer than this ends its method's sweep
SWEEP_BUDGET = 60.0  # s: CPU of one method's sweep, past which it ends
REPEAT_BELOW = 2.0  # s: runs shorter than this are repeated (3 in all, the median kept)


@dataclass
class Point:
    tol: float
    err: float  # G
    cost: float  # CPU s per simulated second
    repeats: int


@dataclass
class Curve:
    name: str
    points: list
    stop: str  # why the sweep ended before its last tolerance ("" if it did not)

    def at(self, level: float):
        """(CPU s per simulated second, kind) at the error `level`: cost_at's kinds."""
        return cost_at([(p.tol, p.err, p.cost, math.nan) for p in self.points], level)


class Reference:
    """B1 on the grid by the reference, and the reference's own error."""

    def __init__(self):
        self.t = output_grid(WINDOW, GRID)
        self.run = R.scene("B1", WINDOW, GRID, "DOP853", REF_RTOL)
        self.G = np.array([R.gear(self.run.params, i + 1)["G"] for i in range(self.run.xi.shape[0])])
        self.floor = self.error(R.scene("B1", WINDOW, GRID, "DOP853", CHECK_RTOL).xi)

    def error(self, xi: np.ndarray) -> float:
        """The largest |xi_i - xi_ref,i| / G_i, xi as (gears, grid points)."""
        return float(np.max(np.abs(xi - self.run.xi) / self.G[:, None]))


def _timed(run):
    """(CPU time of run(), its result, runs): the median of 3 under REPEAT_BELOW."""
    t0 = time.process_time()
    out = run()
    times = [time.process_time() - t0]
    while times[0] < REPEAT_BELOW and len(times) < 3:
        t0 = time.process_time()
        run()
        times.append(time.process_time() - t0)
    return statistics.median(times), out, len(times)


def _fmu_xi(tol: float, n_gears: int):
    """(CPU time of the run, xi of the gears on the grid as (gears, points))."""
    s = Stepper(GF.GEARBOX_FMU, "box")
    names = [f"gear[{i}].xi" for i in range(1, n_gears + 1)]
    t0 = time.process_time()
    s.start({}, tol)
    s.fmu.exitInitializationMode()
    rec = sample(s.fmu, s.refs(names), 0.0, GRID, int(round(WINDOW / GRID)))
    s.fmu.terminate()
    cpu = time.process_time() - t0
    s.fmu.freeInstance()
    return cpu, rec.T


def fmu_curve(ref: Reference) -> Curve:
    points = []
    for tol in FMU_TOLS:
        runs = [_fmu_xi(tol, ref.G.size) for _ in range(3)]
        cpu = statistics.median(c for c, _ in runs)
        points.append(Point(tol, ref.error(runs[0][1]), cpu / WINDOW, len(runs)))
    return Curve(FMU, points, "")


def scipy_curve(method: str, ref: Reference, finest: float) -> Curve:
    """`method` from the loosest tolerance on, until its error is at most `finest` (no level
    needs a tighter run), a run exceeds RUN_LIMIT or the sweep SWEEP_BUDGET."""
    points, used = [], 0.0
    p = R.params("B1")
    for tol in SCIPY_TOLS:
        try:
            cpu, res, n = _timed(lambda: R.simulate(p, WINDOW, t_eval=ref.t, method=method, rtol=tol))
        except RuntimeError as e:
            return Curve(method, points, f"failed at rtol {tol:g} ({e})")
        points.append(Point(tol, ref.error(res.xi), cpu / WINDOW, n))
        used += cpu * n
        if points[-1].err <= finest:
            return Curve(method, points, "" if tol == SCIPY_TOLS[-1] else f"{_tol(finest)} G reached")
        if cpu > RUN_LIMIT:
            return Curve(method, points, f"a run over {RUN_LIMIT:g} s")
        if used > SWEEP_BUDGET:
            return Curve(method, points, f"{SWEEP_BUDGET:g} s of CPU used")
    return Curve(method, points, "")


def sweep(ref: Reference, levels=LEVELS):
    """The FMU's curve and each scipy method's, the finest level the reference resolves
    (ten times its own error) ending the scipy sweeps."""
    finest = min(lv for lv in levels if lv >= 10.0 * ref.floor)
    return [fmu_curve(ref)] + [scipy_curve(m, ref, finest) for m in METHODS]


def ratios(curves, ref: Reference, levels=LEVELS):
    """Per level the reference resolves (ten times its own error): (level, FMU cost, best
    scipy cost, its method, ratio scipy / FMU, qualifier), the costs None where the FMU never
    reaches the level. The qualifier is '' when both costs are interpolated; '>=' or '<='
    when a cost is a bound (reached at the loosest tolerance: at most that run's cost; never
    reached: at least the most accurate run's), '?' when the two bounds point apart."""
    fmu, scipy = curves[0], curves[1:]
    rows = []
    for lv in levels:
        if lv < 10.0 * ref.floor:
            continue
        c_f, k_f = fmu.at(lv)
        if k_f in (None, "above"):
            rows.append((lv, None, None, None, None, None))
            continue
        runs = [(c, k, s.name) for s in scipy for c, k in [s.at(lv)] if k is not None]
        reached = [r for r in runs if r[1] != "above"]
        c_s, k_s, name = min(reached or runs)
        # what each bound makes of the ratio c_s / c_f; a method that stopped short of the
        # level below the best one's cost might have been cheaper there
        sides = {{"bound": "<=", "above": ">="}.get(k_s, "")}
        sides.add(">=" if k_f == "bound" else "")
        sides.add("<=" if reached and any(c < c_s for c, k, _ in runs if k == "above") else "")
        sides.discard("")
        q = sides.pop() if len(sides) == 1 else ("?" if sides else "")
        rows.append((lv, c_f, c_s, name, c_s / c_f, q))
    return rows


def write_csv(path, curves):
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["solver", "tolerance", "err_max_xi_over_G", "cpu_per_simulated_s", "repeats"])
        for c in curves:
            for p in c.points:
                w.writerow([c.name, f"{p.tol:g}", f"{p.err:.4e}", f"{p.cost:.5g}", p.repeats])


def figure(path, curves, ref: Reference, rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 4.5))
    for c in curves:
        e = [p.err for p in c.points]
        k = [p.cost for p in c.points]
        ax.loglog(e, k, "o-" if c.name == FMU else ".--", lw=2 if c.name == FMU else 1,
                  label="GearboxRattle FMU" if c.name == FMU else f"scipy {c.name}")
    for lv, *_ in rows:
        ax.axvline(lv, color="grey", lw=0.5, ls=":")
    ax.axvspan(ref.floor, 10.0 * ref.floor, color="grey", alpha=0.15, label="below 10× the reference's error")
    errs = [p.err for c in curves for p in c.points]
    ax.set_xlim(2.0 * max(errs), 0.5 * min(errs + [ref.floor]))  # accuracy grows rightwards
    ax.set_xlabel("max |ξ_i − ξ_ref,i| / G_i over B1's window (0-0.35 s), 1 ms grid")
    ax.set_ylabel("CPU time per simulated second [s]")
    ax.set_title("GearboxRattle, default box (B1): work against precision")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _tol(x: float) -> str:
    return f"{x:.0e}".replace("e-0", "e-")


def _cost(c, kind) -> str:
    if kind is None:
        return "-"
    return {"bound": "≤ ", "above": "≥ "}.get(kind, "") + (f"{c:.2f} s" if c >= 0.1 else f"{c * 1e3:.0f} ms")


def summary(curves, ref: Reference, rows) -> list:
    """The lines of docs/GEARBOX.md §11 (markdown) on this comparison."""
    n = ref.t.size
    fmu = curves[0]
    out = [
        f"- Work against precision on B1's predictable window (0 to {WINDOW:g} s; "
        "docs/gearbox_work_precision.png; the method: docs/DECISIONS.md D59). Error: the largest "
        f"|ξ_i − ξ_ref,i| / G_i of the {ref.G.size} gears on a {GRID * 1e3:g} ms grid ({n} points), against "
        f"DOP853 at rtol {REF_RTOL:g} with its edges located (at {CHECK_RTOL:g} it moves by {ref.floor:.1e} G, "
        "so levels below ten times that are left out). Both sides output on that grid: the FMU stepped "
        "from one grid point to the next, its tolerance set by fmi2SetupExperiment, the five ξ read at "
        "each, in one call of its sampling entry (an fmi2DoStep and an fmi2GetReal a point inside the "
        "FMU; docs/SOUND.md); scipy's methods driven by the reference's piecewise integration (edges "
        "located, a restart at each) with the grid as output times. Cost: CPU time per simulated second "
        "(the FMU from fmi2Instantiate to its last output, scipy the whole call; the median of 3 runs "
        "under 2 s), interpolated on each log-log curve between the tolerances that bracket the level.",
        "- Swept by decades: " + "; ".join(
            f"{'the FMU' if c.name == FMU else c.name} {_tol(c.points[0].tol)} to {_tol(c.points[-1].tol)}"
            + (f" (stopped: {c.stop})" if c.stop else "") for c in curves if c.points)
        + f". Left out: tolerances looser than {_tol(SCIPY_TOLS[0])} (errors of order G), scipy's "
        f"tighter than {_tol(SCIPY_TOLS[-1])}, the FMU's tighter than {_tol(FMU_TOLS[-1])}. The FMU at its "
        "default tolerance 1e-6: "
        + next(f"{p.err:.1e} G, {_cost(p.cost, 'interp')} per simulated second" for p in fmu.points if p.tol == 1e-6)
        + ".",
        "",
        "| error [G] | FMU | " + " | ".join(f"scipy {c.name}" for c in curves[1:]) + " | best scipy / FMU |",
        "|---" * (len(curves) + 2) + "|",
    ]
    for lv, c_f, _, name, ratio, q in rows:
        cells = [_cost(*c.at(lv)) for c in curves]
        verdict = "FMU never this accurate" if ratio is None else (
            f"{q.replace('>=', '≥ ').replace('<=', '≤ ')}{ratio:.0f}× ({name})")
        out.append(f"| {lv:.0e} | " + " | ".join(cells) + f" | {verdict} |")
    met = [lv for lv, *_, ratio, q in rows if ratio is not None and ratio >= 100 and q in ("", ">=")]
    out += ["", f"At equal error the FMU is at least 100× faster than scipy's best method at: "
            + (", ".join(f"{lv:.0e} G" for lv in met) or "none of the levels") + "."]
    return out
