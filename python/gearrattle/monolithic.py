"""Monolithic reference of the coupled drivetrain: the Flywheel partner (partners/flywheel)
and the gear pair (docs/MODEL.md) as ONE ODE, integrated to a tight tolerance with steps
ending exactly on the band edges of the contact law. What the co-simulations are checked
against (tests/masters) and what scripts/coupling_study.py measures their error from.

State z = [xi, xi_dot, E_contact, E_lubricant, theta_M, omega_M, phi, omega_E]:

* the gear pair's part, [xi, xi_dot, E_contact, E_lubricant], is computed by the right-hand
  side of gearrattle/reference.py with the region's contact formula locked
  (`reference._make_rhs`), fed with the main shaft's current speed and a zero acceleration:
  its second component is then r_L omega_L', from which the contact force F follows
  (I_L omega_L' = B - r_L F - C (omega_L - omega_S)), so the contact law, the loose gear's
  equation and the energies are the reference's own, not a copy;
* the drivetrain (partners/flywheel/src/model.rs, `drivetrain`): phi = theta_E - theta_M,
  T_d = k_d phi + c_d (omega_E - omega_M), I_M omega_M' = T_d + r_M F,
  I_E omega_E' = T_mean + T_2 sin(2 theta_E) - (T_mean / omega_idle) omega_E - T_d; the
  Model Exchange master (model_exchange.py) puts the same function around GearRattle, with
  its partials (`drivetrain_partials`) in the master's Jacobian;
* xi'' = r_L omega_L' - r_M omega_M'.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import DOP853
from scipy.optimize import brentq

from . import reference as R

# The Flywheel FMU's defaults (partners/flywheel/src/model.rs; values: partners/flywheel/README.md).
FLYWHEEL = dict(
    I_E=0.15,
    I_M=0.008,
    k_d=150.0,
    c_d=0.3,
    T_mean=15.0,
    T_2=80.0,
    omega_idle=800.0 * math.pi / 30.0,
)

# GearRattle parameters set in the coupled runs (the rest: the paper's defaults). The paper's
# lubricant drag C = 0.025 N m s was identified on a bench turning about zero mean speed; at
# idle the loose gear turns at ~640 rpm against its output shaft at rest, where it would
# brake with 1.6 N m and hold the gear on one flank unless the main shaft's acceleration
# exceeded ~6500 rad/s^2. 1e-3 N m s gives a spin drag of 0.064 N m, of the order measured on
# loose gears, and a rattle threshold near 260 rad/s^2 (README of the partner).
GEAR = dict(C=1e-3)

_X, _V = 0, 1  # xi, xi_dot in z


@dataclass
class Result:
    t: np.ndarray
    z: np.ndarray  # (8, len(t))
    impact_t: np.ndarray
    impact_flank: np.ndarray
    impact_speed: np.ndarray
    nfev: int
    pieces: int

    @property
    def xi(self):
        return self.z[0]

    @property
    def theta_M(self):
        return self.z[4]

    @property
    def omega_M(self):
        return self.z[5]

    def impact_counts(self, t):
        """Cumulative (F+, F-) impact counts at the times t (onsets at <= t)."""
        t = np.asarray(t, dtype=float)
        return tuple(np.searchsorted(self.impact_t[self.impact_flank == fl], t, side="right") for fl in (R.FPLUS, R.FMINUS))


def gear_params(**overrides) -> dict:
    return R.params(**{**GEAR, **overrides})


def _flywheel(pf: dict) -> tuple:
    """(I_E, I_M, k_d, c_d, T_mean, T_2, d_E), d_E = T_mean / omega_idle the engine's
    speed-proportional loss."""
    return (*(pf[k] for k in ("I_E", "I_M", "k_d", "c_d", "T_mean", "T_2")), pf["T_mean"] / pf["omega_idle"])


def drivetrain(pf: dict):
    """The Flywheel's equations (partners/flywheel/src/model.rs) as a function
    accelerations(theta_M, phi, omega_M, omega_E, tau_M) -> (omega_M', omega_E'), tau_M being
    the torque the gear pair exerts on the main shaft (r_M F): the clutch damper's
    T_d = k_d phi + c_d (omega_E - omega_M), I_M omega_M' = T_d + tau_M,
    I_E omega_E' = T_mean + T_2 sin(2 theta_E) - (T_mean / omega_idle) omega_E - T_d."""
    I_E, I_M, k_d, c_d, T_mean, T_2, d_E = _flywheel(pf)
    sin = math.sin

    def accelerations(theta_M, phi, om_m, om_e, tau_M):
        t_d = k_d * phi + c_d * (om_e - om_m)
        return (t_d + tau_M) / I_M, (T_mean + T_2 * sin(2.0 * (theta_M + phi)) - d_E * om_e - t_d) / I_E

    return accelerations


def drivetrain_partials(pf: dict):
    """The partials of `drivetrain`'s accelerations as a function partials(theta_M, phi) ->
    a (2, 5) array: rows omega_M', omega_E'; columns theta_M, omega_M, phi, omega_E, tau_M
    (the order of the master's state vector, then the gear pair's torque, through which a
    caller adds tau_M's own partials by the chain rule). Only the engine's firing torque
    T_2 sin(2 (theta_M + phi)) is nonlinear; the rest is constant."""
    I_E, I_M, k_d, c_d, _, T_2, d_E = _flywheel(pf)
    const = np.array([
        [0.0, -c_d / I_M, k_d / I_M, c_d / I_M, 1.0 / I_M],
        [0.0, c_d / I_E, -k_d / I_E, -(d_E + c_d) / I_E, 0.0],
    ])
    cos = math.cos

    def partials(theta_M, phi):
        out = const.copy()
        firing = 2.0 * T_2 * cos(2.0 * (theta_M + phi)) / I_E
        out[1, 0] = firing
        out[1, 2] += firing
        return out

    return partials


def _coupled_rhs(pg: dict, pf: dict, code: int):
    r_L, r_M, I_L, B, C, om_s = pg["r_L"], pg["r_M"], pg["I_L"], pg["B"], pg["C"], pg["omega_S"]
    accelerations = drivetrain(pf)
    shaft_speed = [0.0]
    gear = R._make_rhs(pg, code, shaft=lambda t: (shaft_speed[0], 0.0))

    def rhs(t, z):
        om_m, phi, om_e = z[5], z[6], z[7]
        shaft_speed[0] = om_m
        g = gear(t, z[:4])  # [xi_dot, r_L omega_L' (a_M = 0), dE_contact, dE_lubricant]
        om_rel = (z[1] + r_M * om_m) / r_L - om_s
        force = (B - C * om_rel - I_L * g[1] / r_L) / r_L
        a_m, a_e = accelerations(z[4], phi, om_m, om_e, r_M * force)
        return np.array((z[1], g[1] - r_M * a_m, g[2], g[3], om_m, a_m, om_e - om_m, a_e))

    return rhs


def _leaves(dense, t0, t1, z0, z1, lo, hi):
    """First exit of xi from [lo, hi] within (t0, t1]: (time, +1 upper / -1 lower) or None.
    A sign change of xi_dot inside the step is an extremum of xi, checked first, so that a
    graze out and back in within one step is not missed."""
    points = [(t1, z1[_X])]
    if z0[_V] * z1[_V] < 0.0:
        t_turn = brentq(lambda s: dense(s)[_V], t0, t1, xtol=1e-16, rtol=4 * np.finfo(float).eps)
        points.insert(0, (t_turn, dense(t_turn)[_X]))
    t_in = t0
    for tp, x in points:
        if x < lo or x > hi:
            edge = lo if x < lo else hi
            if dense(t_in)[_X] == edge:
                return t_in, (-1 if x < lo else 1)
            tc = brentq(lambda s: dense(s)[_X] - edge, t_in, tp, xtol=1e-16, rtol=4 * np.finfo(float).eps)
            return tc, (-1 if x < lo else 1)
        t_in = tp
    return None


def simulate(t_end: float, t_eval=None, pg: dict | None = None, pf: dict | None = None, rtol: float = 1e-10) -> Result:
    """The coupled drivetrain from rest in the backlash (xi = gap_start G, xi_dot = 0) with
    both shafts at idle speed, theta = 0, no twist (the FMUs' initial state), to t_end."""
    pg = gear_params() if pg is None else pg
    pf = dict(FLYWHEEL) if pf is None else pf
    G = pg["G"]
    t_eval = np.array([0.0, t_end]) if t_eval is None else np.asarray(t_eval, dtype=float)
    out = np.full((8, t_eval.size), np.nan)
    k = 0
    scale = np.array([G, G * 3600.0, 1e-3, 1e-3, 1.0, 100.0, 1e-2, 100.0])
    z = np.array([pg["gap_start"] * G, pg["xi_dot_start"], 0.0, 0.0, 0.0, pf["omega_idle"], 0.0, pf["omega_idle"]])
    regions = R._regions(pg)
    idx = next(i for i, (_, lo, hi) in enumerate(regions) if lo <= z[_X] <= hi)
    rhs_of = {}
    imp_t, imp_fl, imp_v = [], [], []
    t, nfev, pieces = 0.0, 0, 0
    while k < t_eval.size and t_eval[k] <= t:
        out[:, k] = z
        k += 1
    while t < t_end:
        code, lo, hi = regions[idx]
        rhs = rhs_of.setdefault(code, _coupled_rhs(pg, pf, code))
        solver = DOP853(rhs, t, z, t_end, rtol=rtol, atol=rtol * scale)
        pieces += 1
        exit_ = None
        while solver.status == "running":
            t0, z0 = solver.t, solver.y
            msg = solver.step()
            if solver.status == "failed":
                raise RuntimeError(f"DOP853 failed at t = {solver.t}: {msg}")
            dense = None
            if not (lo <= solver.y[_X] <= hi) or z0[_V] * solver.y[_V] < 0.0:
                dense = solver.dense_output()
                exit_ = _leaves(dense, t0, solver.t, z0, solver.y, lo, hi)
            t_lim = exit_[0] if exit_ else solver.t
            if k < t_eval.size and t_eval[k] <= t_lim:
                dense = dense or solver.dense_output()
                while k < t_eval.size and t_eval[k] <= t_lim:
                    out[:, k] = dense(t_eval[k])
                    k += 1
            if exit_:
                t, side = exit_
                z = dense(t)
                z[_X] = lo if side < 0 else hi
                break
        nfev += solver.nfev
        if not exit_:
            t, z = solver.t, solver.y
            break
        if code == 2:  # leaving the gap: a contact onset (docs/MODEL.md §1)
            imp_t.append(t)
            imp_fl.append(R.FPLUS if side < 0 else R.FMINUS)
            imp_v.append(abs(z[_V]))
        idx += side
    while k < t_eval.size:
        out[:, k] = z
        k += 1
    return Result(t_eval, out, np.array(imp_t), np.array(imp_fl, dtype=int), np.array(imp_v), nfev, pieces)
