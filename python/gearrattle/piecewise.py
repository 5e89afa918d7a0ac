"""The numerical side of the references' piecewise integration (docs/MODEL.md §3, docs/GEARBOX.md
§6), shared by `reference` (one gear pair) and `gearbox_reference` (the box): scipy's
solvers driven step by step, the output times and the state there from each step's dense
output, and the search for the first edge a coordinate crosses within a step, turning
points included (a graze in and out of a region within one step). The regions, right-hand
sides and what a crossing means stay in each reference, written from its specification."""

from __future__ import annotations

import numpy as np
from scipy.integrate import BDF, DOP853, LSODA, RK45, Radau
from scipy.optimize import brentq

# DOP853 makes the references, Radau checks them; all five of solve_ivp's methods step the
# gearbox's for its benchmark against scipy (benches/gearbox).
SOLVERS = {"RK45": RK45, "DOP853": DOP853, "LSODA": LSODA, "Radau": Radau, "BDF": BDF}
# The root searches' tolerances: an edge's time to a few rounding errors.
BRENT_RTOL = 4.0 * np.finfo(float).eps
XTOL = 1e-16


def output_times(t_eval, t_start: float, t_end: float) -> np.ndarray:
    """t_eval as an array (default: t_start and t_end), refused unless increasing within
    [t_start, t_end]."""
    t_eval = np.array([t_start, t_end]) if t_eval is None else np.asarray(t_eval, dtype=float)
    if t_eval.size and (t_eval[0] < t_start or t_eval[-1] > t_end * (1 + 1e-12) or np.any(np.diff(t_eval) < 0)):
        raise ValueError("t_eval must be increasing within [t_start, t_end]")
    return t_eval


def output_grid(t_end: float, dt: float) -> np.ndarray:
    """The output times i dt from 0 to t_end, the last one not beyond t_end."""
    t_eval = np.arange(int(round(t_end / dt)) + 1) * dt
    t_eval[-1] = min(t_eval[-1], t_end)
    return t_eval


class Outputs:
    """The state at the output times `t` (a column each), filled in order as the integration
    passes them."""

    def __init__(self, t: np.ndarray, size: int):
        self.t = t
        self.values = np.full((size, t.size), np.nan)
        self.k = 0  # the next output

    def due(self, t_lim: float) -> bool:
        """Whether an output time not filled yet is at or before t_lim."""
        return self.k < self.t.size and self.t[self.k] <= t_lim

    def fill(self, t_lim: float, state):
        """The outputs up to t_lim, from state(t)."""
        while self.due(t_lim):
            self.values[:, self.k] = state(self.t[self.k])
            self.k += 1


def step(solver):
    """One step of the solver; its failure raised."""
    msg = solver.step()
    if solver.status == "failed":
        raise RuntimeError(f"{type(solver).__name__} failed at t={solver.t}: {msg}")


def edge_in_step(solver, dense, ix, iv, lo, hi, t_old, y_old, y_new):
    """The first crossing of lo or hi by y[ix] within the solver's last step (from t_old,
    y_old to solver.t, y_new), as ((t_c, side), dense, x_turn) with side -1 (lo) or +1 (hi),
    or (None, dense, x_turn). A turning point of y[ix] inside the step (its rate y[iv]
    changes sign) is located and checked as well; x_turn is y[ix] there when it stays within
    [lo, hi] (else None). `dense` is the step's dense output, computed here only when needed
    and handed back."""
    t_from, t_new, x_turn = t_old, solver.t, None
    v_old, v_new = y_old[iv], y_new[iv]
    if (v_old > 0.0 and v_new < 0.0) or (v_old < 0.0 and v_new > 0.0):
        dense = dense or solver.dense_output()
        t_turn = brentq(lambda s: dense(s)[iv], t_old, t_new, xtol=XTOL, rtol=BRENT_RTOL)
        x = dense(t_turn)[ix]
        if x < lo:
            return (root(dense, ix, lo, t_old, t_turn), -1), dense, None
        if x > hi:
            return (root(dense, ix, hi, t_old, t_turn), 1), dense, None
        t_from, x_turn = t_turn, x
    x_new = y_new[ix]
    if x_new < lo:
        edge, side = lo, -1
    elif x_new > hi:
        edge, side = hi, 1
    else:
        return None, dense, x_turn
    dense = dense or solver.dense_output()
    return (root(dense, ix, edge, t_from, t_new), side), dense, x_turn


def root(dense, ix, edge, a, b):
    """The time in [a, b] where y[ix] reaches `edge` on the dense output."""
    if dense(a)[ix] - edge == 0.0:
        return a
    return brentq(lambda s: dense(s)[ix] - edge, a, b, xtol=XTOL, rtol=BRENT_RTOL)
