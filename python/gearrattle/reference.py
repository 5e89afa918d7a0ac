"""Independent high-accuracy reference of the gear-rattle model (docs/MODEL.md).

Written from docs/MODEL.md alone (not from the Rust FMU), to check the FMU against.

State y = [xi, xi_dot, E_contact, E_lubricant]:

* xi = r_L theta_L - r_M theta_M, the transmission error on the pitch line (docs/MODEL.md §1),
  integrated directly (relative coordinate, §3 numerical note);
* E_contact = int s C_LM xi_dot^2 dt and E_lubricant = int C (omega_L - omega_S)^2 dt,
  quadrature states (§3, energy balance).

Equation of motion (§3) written for xi, with the main shaft imposed (§5):

    omega_L  = (xi_dot + r_M omega_M) / r_L
    I_L omega_L' = B - r_L F - C (omega_L - omega_S)
    xi''     = r_L omega_L' - r_M a_M(t)

Contact law (§2), five regions of xi (eps = 0: no band, three regions):

    region 0  contact F+   xi < -eps          s = 1
    region 1  band F+      -eps <= xi <= 0    s = (1 - sin(pi/eps (eps/2 + xi))) / 2
    region 2  gap          0 <= xi <= G       s = 0
    region 3  band F-      G <= xi <= G+eps   s = (1 - sin(pi/eps (eps/2 - (xi - G)))) / 2
    region 4  contact F-   xi > G + eps       s = 1

    F = s K* delta |delta/G|^(alpha-1) + s C_LM xi_dot,   delta = xi (F+), xi - G (F-)

Integration is piecewise: the region's formula is locked during each piece, and a piece
ends exactly on a band edge (xi = -eps, 0, G, G+eps; only the two edges bounding the
current region are watched). The steps are driven by hand with scipy's OdeSolver classes
(DOP853, or Radau as an independent second method) so that an edge crossed and recrossed
inside one step (a grazing touch: xi_dot changes sign within the step) is not skipped:
the extremum is located on the dense output and checked against the edges. That numerical
side (the solvers, the outputs, the edge search) is `gearrattle.piecewise`, shared with the
gearbox's reference.

Impacts are contact onsets (docs/MODEL.md §1): the gap left downwards through 0 (flank F+) or
upwards through G (flank F-); recorded with time, flank and |xi_dot|.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from gearrattle.piecewise import SOLVERS, Outputs, edge_in_step, output_grid, output_times, step

# The paper's parameters (docs/MODEL.md §4) and the FMU's defaults (modelDescription/GearRattle.toml).
DEFAULTS = dict(
    I_L=0.32e-3,
    r_L=0.037,
    r_M=0.02825,
    K_star=3e6,
    alpha=4.0 / 3.0,
    epsilon=1e-6,
    G=25e-6,
    C_LM=67.0,
    C=0.025,
    B=0.0,
    omega_S=0.0,
    A_rms=300.0,
    f_exc=30.0,
    omega_mean=0.0,
    gap_start=0.5,
    xi_dot_start=0.0,
    I_M=0.008,  # torque mode only: the main shaft's inertia
)

# Bench scenes (docs/MODEL.md §5).
SCENES = {
    "S1": dict(f_exc=30.0, A_rms=300.0),
    "S2": dict(f_exc=60.0, A_rms=300.0),
    "S3": dict(f_exc=30.0, A_rms=500.0),
}

# Flank codes, the same as the FMU's `contact` output: 1 = F+ (xi <= 0), 2 = F- (xi >= G).
FPLUS = 1
FMINUS = 2

_TWO_PI = 2.0 * math.pi


def params(scene: str | None = None, **overrides) -> dict:
    """Full parameter dict: defaults, then the scene's excitation, then overrides."""
    p = dict(DEFAULTS)
    if scene is not None:
        p.update(SCENES[scene])
    unknown = set(overrides) - set(DEFAULTS)
    if unknown:
        raise KeyError(f"unknown parameter(s): {sorted(unknown)}")
    p.update(overrides)
    return p


# ----------------------------------------------------------------------------------------
# Model functions (vectorised over numpy arrays; used by the tests as well)
# ----------------------------------------------------------------------------------------


def main_shaft(t, p: dict):
    """Sine excitation (docs/MODEL.md §5): theta_M, omega_M, alpha_M at time(s) t."""
    t = np.asarray(t, dtype=float)
    w = _TWO_PI * p["f_exc"]
    amp = math.sqrt(2.0) * p["A_rms"]
    theta = p["omega_mean"] * t - amp / w**2 * np.sin(w * t)
    omega = p["omega_mean"] - amp / w * np.cos(w * t)
    acc = amp * np.sin(w * t)
    return theta, omega, acc


def smoothing(xi, p: dict):
    """Smoothing factor s(xi) of docs/MODEL.md §2 (vectorised)."""
    xi = np.asarray(xi, dtype=float)
    eps, G = p["epsilon"], p["G"]
    s = np.zeros_like(xi)
    s[xi <= -eps] = 1.0
    s[xi >= G + eps] = 1.0
    if eps > 0.0:
        b1 = (xi > -eps) & (xi < 0.0)
        s[b1] = 0.5 * (1.0 - np.sin(math.pi / eps * (eps / 2.0 + xi[b1])))
        b2 = (xi > G) & (xi < G + eps)
        s[b2] = 0.5 * (1.0 - np.sin(math.pi / eps * (eps / 2.0 - (xi[b2] - G))))
    return s


def contact_force(xi, xi_dot, p: dict):
    """Contact force F = F_k + F_c along xi (docs/MODEL.md §2, vectorised)."""
    xi = np.asarray(xi, dtype=float)
    xi_dot = np.asarray(xi_dot, dtype=float)
    G = p["G"]
    s = smoothing(xi, p)
    delta = np.where(xi <= 0.0, xi, np.where(xi >= G, xi - G, 0.0))
    fk = p["K_star"] * delta * np.abs(delta / G) ** (p["alpha"] - 1.0)
    return s * fk + s * p["C_LM"] * xi_dot


def contact_region(xi, p: dict):
    """The FMU's contact flag expected from xi: 0 gap, 1 F+ (xi < 0), 2 F- (xi > G)."""
    xi = np.asarray(xi, dtype=float)
    return np.where(xi < 0.0, FPLUS, np.where(xi > p["G"], FMINUS, 0))


def loose_gear(t, xi, xi_dot, p: dict):
    """omega_L, alpha_L (= omega_L'), F from the state, with the sine main shaft."""
    _, om_m, _ = main_shaft(t, p)
    om_l = (np.asarray(xi_dot) + p["r_M"] * om_m) / p["r_L"]
    f = contact_force(xi, xi_dot, p)
    al_l = (p["B"] - p["r_L"] * f - p["C"] * (om_l - p["omega_S"])) / p["I_L"]
    return om_l, al_l, f


# ----------------------------------------------------------------------------------------
# Piecewise integration
# ----------------------------------------------------------------------------------------


def _regions(p: dict):
    """Ordered regions (code, lower edge, upper edge); codes as in the module docstring."""
    eps, G = p["epsilon"], p["G"]
    inf = math.inf
    if eps > 0.0:
        return [(0, -inf, -eps), (1, -eps, 0.0), (2, 0.0, G), (3, G, G + eps), (4, G + eps, inf)]
    return [(0, -inf, 0.0), (2, 0.0, G), (4, G, inf)]


def _contact(p: dict, code: int):
    """Contact law of region `code` (docs/MODEL.md §2) as a function (xi, xi_dot) -> (s, F)."""
    K, am1, eps, G = p["K_star"], p["alpha"] - 1.0, p["epsilon"], p["G"]
    C_LM = p["C_LM"]
    inv_G = 1.0 / G
    pi_eps = math.pi / eps if eps > 0.0 else 0.0
    half_eps = 0.5 * eps
    sin, fabs, pow_ = math.sin, math.fabs, math.pow

    if code == 2:

        def contact(xi, v):
            return 0.0, 0.0

    elif code == 0:

        def contact(xi, v):
            return 1.0, K * xi * pow_(fabs(xi) * inv_G, am1) + C_LM * v

    elif code == 4:

        def contact(xi, v):
            d = xi - G
            return 1.0, K * d * pow_(fabs(d) * inv_G, am1) + C_LM * v

    elif code == 1:

        def contact(xi, v):
            s = 0.5 * (1.0 - sin(pi_eps * (half_eps + xi)))
            return s, s * (K * xi * pow_(fabs(xi) * inv_G, am1) + C_LM * v)

    elif code == 3:

        def contact(xi, v):
            d = xi - G
            s = 0.5 * (1.0 - sin(pi_eps * (half_eps - d)))
            return s, s * (K * d * pow_(fabs(d) * inv_G, am1) + C_LM * v)

    else:  # pragma: no cover
        raise ValueError(code)

    return contact


def _make_rhs(p: dict, code: int, shaft=None):
    """Right-hand side with the contact formula of region `code` locked.

    shaft: None for the sine excitation of docs/MODEL.md §5, else a function t -> (omega_M, a_M)."""
    I_L, r_L, r_M = p["I_L"], p["r_L"], p["r_M"]
    C_LM, C, B, om_s = p["C_LM"], p["C"], p["B"], p["omega_S"]
    w = _TWO_PI * p["f_exc"]
    amp = math.sqrt(2.0) * p["A_rms"]
    amp_w = amp / w
    om_mean = p["omega_mean"]
    sin, cos = math.sin, math.cos
    contact = _contact(p, code)

    def rhs(t, y):
        xi = y[0]
        v = y[1]
        if shaft is None:
            wt = w * t
            a_m = amp * sin(wt)
            om_m = om_mean - amp_w * cos(wt)
        else:
            om_m, a_m = shaft(t)
        om_rel = (v + r_M * om_m) / r_L - om_s
        s, f = contact(xi, v)
        dom_l = (B - r_L * f - C * om_rel) / I_L
        return np.array((v, r_L * dom_l - r_M * a_m, s * C_LM * v * v, C * om_rel * om_rel))

    return rhs


@dataclass
class Result:
    """What `simulate` returns. Arrays at the output points t."""

    params: dict
    t: np.ndarray
    xi: np.ndarray
    xi_dot: np.ndarray
    E_contact: np.ndarray
    E_lubricant: np.ndarray
    impact_t: np.ndarray  # impact (contact onset) times
    impact_flank: np.ndarray  # FPLUS (1) or FMINUS (2)
    impact_speed: np.ndarray  # |xi_dot| at the onset
    impact_excursion: np.ndarray  # how far into the gap xi went before this onset [m]
    xi_min: float  # extremes of xi over the whole run (step ends and turning points)
    xi_max: float
    nfev: int
    nsteps: int
    npieces: int
    method: str
    rtol: float
    final_y: np.ndarray = field(repr=False, default=None)

    # convenience ------------------------------------------------------------------------
    def loose_gear(self):
        """omega_L, alpha_L, F at the output points."""
        return loose_gear(self.t, self.xi, self.xi_dot, self.params)

    def impact_counts(self, t):
        """Cumulative impact counts (F+, F-) at the times t (onsets at <= t counted)."""
        t = np.asarray(t, dtype=float)
        out = []
        for fl in (FPLUS, FMINUS):
            ti = self.impact_t[self.impact_flank == fl]
            out.append(np.searchsorted(ti, t, side="right"))
        return out[0], out[1]


def simulate(
    p: dict | None = None,
    t_end: float = 0.05,
    t_eval=None,
    method: str = "DOP853",
    rtol: float = 1e-12,
    e_scale: float = 1e-3,
    shaft=None,
    t_start: float = 0.0,
) -> Result:
    """Integrate the model from t_start (default 0) to t_end.

    p: full parameter dict (see `params`); t_eval: increasing output times in [t_start, t_end]
    (default: t_start and t_end only); method: 'DOP853' or 'Radau'; rtol: relative tolerance,
    the absolute tolerances being rtol * (G, G * 3600 rad/s, e_scale, e_scale).
    shaft: None for the sine excitation, else a function t -> (omega_M, a_M) (any imposed
    main-shaft motion); t_start: the initial time (xi = gap_start G, xi_dot = xi_dot_start).
    """
    p = params() if p is None else dict(p)
    G = p["G"]
    atol = rtol * np.array([G, G * 3600.0, e_scale, e_scale])
    rhs_cache = {}

    def rhs_for(code, _t):
        if code not in rhs_cache:
            rhs_cache[code] = _make_rhs(p, code, shaft)
        return rhs_cache[code]

    y0 = np.array([p["gap_start"] * G, p["xi_dot_start"], 0.0, 0.0])
    run = _piecewise(p, rhs_for, y0, atol, t_start, t_end, t_eval, method, rtol)
    out = run.pop("out")
    return Result(params=p, method=method, rtol=rtol, **_named(out), **run)


def _named(out):
    """The rows of `_piecewise`'s out shared by both modes, by name."""
    return dict(xi=out[0], xi_dot=out[1], E_contact=out[2], E_lubricant=out[3])


def _piecewise(p, rhs_for, y0, atol, t_start, t_end, t_eval, method, rtol, breaks=()):
    """The piecewise integration of the module docstring, for any state whose first two
    components are xi and xi_dot: rhs_for(code, t) gives the right-hand side of region `code`
    for a piece that starts at t. A piece also ends at each time of `breaks`, where the
    right-hand side may jump (a torque held over a communication step). Returns the fields of
    a result: t, out (the state at the times t_eval, one row per component), the impacts, the
    extremes of xi, counters and final_y."""
    solver_cls = SOLVERS[method]
    t_eval = output_times(t_eval, t_start, t_end)
    breaks = np.asarray(breaks, dtype=float)
    y = np.array(y0, dtype=float)
    outputs = Outputs(t_eval, y.size)

    regions = _regions(p)

    # initial region
    xi0 = y[0]
    idx = next(i for i, (_, lo, hi) in enumerate(regions) if lo <= xi0 <= hi)
    t = t_start
    outputs.fill(t_start, lambda _t: y)

    imp_t, imp_fl, imp_v, imp_x = [], [], [], []
    xi_min = xi_max = xi0
    nfev = nsteps = npieces = 0
    stalls = 0
    piece_min = piece_max = xi0  # extremes of xi in the current region (across breaks)

    while t < t_end:
        code, lo, hi = regions[idx]
        rhs = rhs_for(code, t)
        later = breaks[breaks > t * (1.0 + 1e-14) + 1e-300]
        t_stop = min(t_end, later[0]) if later.size else t_end
        solver = solver_cls(rhs, t, y, t_stop, rtol=rtol, atol=atol)
        npieces += 1
        crossing = None  # (t_event, y_event, +1 upper / -1 lower)
        while True:
            t_old, y_old = solver.t, solver.y
            step(solver)
            nsteps += 1
            t_new, y_new = solver.t, solver.y
            # an edge crossed within the step, or past a turning point inside it (grazing)
            found, dense, x_turn = edge_in_step(solver, None, 0, 1, lo, hi, t_old, y_old, y_new)
            if x_turn is not None:
                xi_min = min(xi_min, x_turn)
                xi_max = max(xi_max, x_turn)
                piece_min = min(piece_min, x_turn)
                piece_max = max(piece_max, x_turn)
            if found is not None:
                tc, side = found
                y_c = dense(tc)
                y_c[0] = lo if side < 0 else hi
                t_lim = tc
            else:
                x_new = y_new[0]
                t_lim = t_new
                xi_min = min(xi_min, x_new)
                xi_max = max(xi_max, x_new)
                piece_min = min(piece_min, x_new)
                piece_max = max(piece_max, x_new)
            # outputs inside (t_old, t_lim]
            if outputs.due(t_lim):
                dense = dense or solver.dense_output()
                outputs.fill(t_lim, dense)
            if found is not None:
                crossing = (tc, y_c, side)
                break
            if solver.status == "finished":
                break
        nfev += solver.nfev
        if crossing is None:
            t, y = solver.t, solver.y
            if t >= t_end:
                break
            continue  # a break: the same region goes on with the next right-hand side
        t_c, y, side = crossing
        stalls = stalls + 1 if t_c <= t else 0
        if stalls > 20:
            raise RuntimeError(f"no progress at t={t}: region {code}, xi={y[0]}, xi_dot={y[1]}")
        t = t_c
        new_idx = idx + side
        if code == 2:  # leaving the gap: a contact onset
            imp_t.append(t)
            imp_fl.append(FPLUS if side < 0 else FMINUS)
            imp_v.append(abs(y[1]))
            # depth of the excursion into the gap since the last flank: G after a crossing
            imp_x.append(piece_max - lo if side < 0 else hi - piece_min)
        idx = new_idx
        piece_min = piece_max = y[0]

    # outputs exactly at t_end that may remain (t_eval[-1] == t_end rounding)
    outputs.fill(math.inf, lambda _t: y)

    return dict(
        t=t_eval,
        out=outputs.values,
        impact_t=np.array(imp_t),
        impact_flank=np.array(imp_fl, dtype=int),
        impact_speed=np.array(imp_v),
        impact_excursion=np.array(imp_x),
        xi_min=xi_min,
        xi_max=xi_max,
        nfev=nfev,
        nsteps=nsteps,
        npieces=npieces,
        final_y=np.array(y),
    )


# ----------------------------------------------------------------------------------------
# Torque mode (the FMU's excitation = 2)
# ----------------------------------------------------------------------------------------
#
# docs/MODEL.md imposes the main shaft; its §3 gives the torque the contact exerts on it,
# tau_M = + r_M F. In torque mode the shaft is a rigid inertia I_M driven by the drivetrain's
# torque tau_in and by that reaction:
#
#     I_M omega_M' = tau_in + r_M F,   theta_M' = omega_M,   xi'' = r_L omega_L' - r_M omega_M'
#
# State [xi, xi_dot, E_contact, E_lubricant, theta_M, omega_M], the same piecewise driver.


def _make_rhs_torque(p: dict, code: int, tau):
    """Right-hand side of the torque mode with region `code` locked; tau: t -> tau_in."""
    I_L, I_M, r_L, r_M = p["I_L"], p["I_M"], p["r_L"], p["r_M"]
    C_LM, C, B, om_s = p["C_LM"], p["C"], p["B"], p["omega_S"]
    contact = _contact(p, code)

    def rhs(t, y):
        xi, v, om_m = y[0], y[1], y[5]
        s, f = contact(xi, v)
        om_rel = (v + r_M * om_m) / r_L - om_s
        dom_l = (B - r_L * f - C * om_rel) / I_L
        a_m = (tau(t) + r_M * f) / I_M
        return np.array((v, r_L * dom_l - r_M * a_m, s * C_LM * v * v, C * om_rel * om_rel, om_m, a_m))

    return rhs


@dataclass
class TorqueResult(Result):
    """What `simulate_torque` returns: a Result plus the main shaft's motion."""

    theta_M: np.ndarray = None
    omega_M: np.ndarray = None
    alpha_M: np.ndarray = None  # (tau_in + r_M F) / I_M at the output points

    def loose_gear(self):
        """omega_L, alpha_L, F at the output points."""
        p = self.params
        om_l = (self.xi_dot + p["r_M"] * self.omega_M) / p["r_L"]
        f = contact_force(self.xi, self.xi_dot, p)
        al_l = (p["B"] - p["r_L"] * f - p["C"] * (om_l - p["omega_S"])) / p["I_L"]
        return om_l, al_l, f


def held_torque(t_k, tau_k, rate_k=None):
    """The torque a master gives at communication points t_k: tau_k, and with input
    derivatives rate_k, ramped as tau_k + rate_k (t - t_k) until t_(k+1).
    Returns (segment(t0) -> the function tau(t) of the segment that starts at t0, breaks)."""
    t_k = np.asarray(t_k, dtype=float)
    tau_k = np.asarray(tau_k, dtype=float)
    rate_k = np.zeros_like(tau_k) if rate_k is None else np.asarray(rate_k, dtype=float)

    def segment(t0):
        k = max(int(np.searchsorted(t_k, t0 * (1.0 + 1e-14) + 1e-300, side="right")) - 1, 0)
        t_s, a, b = float(t_k[k]), float(tau_k[k]), float(rate_k[k])
        return lambda t: a + b * (t - t_s)

    return segment, t_k[1:]


def simulate_torque(
    p: dict | None = None,
    t_end: float = 0.05,
    tau=None,
    held=None,
    theta_M0: float = 0.0,
    omega_M0: float = 0.0,
    t_eval=None,
    method: str = "DOP853",
    rtol: float = 1e-12,
    e_scale: float = 1e-3,
) -> TorqueResult:
    """Integrate the torque mode from t = 0: xi(0) = gap_start G, xi_dot(0) = xi_dot_start,
    theta_M(0) = theta_M0, omega_M(0) = omega_M0, the shaft's inertia p["I_M"].

    tau: a smooth torque t -> tau_in; or held: the output of `held_torque` (what a master
    sets at each communication point), whose segments end pieces of the integration.
    The absolute tolerances are those of `simulate`, and for theta_M, omega_M the ones of
    xi, xi_dot divided by r_M."""
    p = params() if p is None else dict(p)
    G, r_M = p["G"], p["r_M"]
    atol = rtol * np.array([G, G * 3600.0, e_scale, e_scale, G / r_M, G * 3600.0 / r_M])
    if held is not None:
        segment, breaks = held
    elif tau is not None:
        segment, breaks = (lambda _t0: tau), ()
    else:
        segment, breaks = (lambda _t0: (lambda _t: 0.0)), ()

    def rhs_for(code, t0):
        return _make_rhs_torque(p, code, segment(t0))

    y0 = np.array([p["gap_start"] * G, p["xi_dot_start"], 0.0, 0.0, theta_M0, omega_M0])
    run = _piecewise(p, rhs_for, y0, atol, 0.0, t_end, t_eval, method, rtol, breaks)
    out = run.pop("out")
    # the shaft's acceleration at the output points, from the torque of the segment that
    # holds each point (the one that ends there, at a break) and the contact force
    seg_t = np.concatenate(([0.0], np.asarray(breaks, dtype=float)))
    tau_out = np.array(
        [segment(seg_t[max(int(np.searchsorted(seg_t, t, side="left")) - 1, 0)])(t) for t in run["t"]]
    )
    alpha = (tau_out + r_M * contact_force(out[0], out[1], p)) / p["I_M"]
    return TorqueResult(
        params=p, method=method, rtol=rtol, theta_M=out[4], omega_M=out[5], alpha_M=alpha, **_named(out), **run
    )


# ----------------------------------------------------------------------------------------
# Cached scene runs (shared by the tests of one pytest session)
# ----------------------------------------------------------------------------------------


@functools.lru_cache(maxsize=None)
def scene(name: str, t_end: float, dt_out: float | None = None, method: str = "DOP853", rtol: float = 1e-12) -> Result:
    """Run a bench scene (S1, S2, S3) with the defaults, outputs every dt_out (i * dt_out)."""
    t_eval = None if dt_out is None else output_grid(t_end, dt_out)
    return simulate(params(name), t_end, t_eval=t_eval, method=method, rtol=rtol)


# ----------------------------------------------------------------------------------------
# Impact statistics
# ----------------------------------------------------------------------------------------


def runs(flanks) -> list[tuple[int, int]]:
    """Consecutive-impact runs: [(flank, length), ...] in order of time.

    A run is a maximal sequence of consecutive impacts on the same flank (before one on
    the other flank)."""
    out: list[tuple[int, int]] = []
    for f in np.asarray(flanks, dtype=int).tolist():
        if out and out[-1][0] == f:
            out[-1] = (f, out[-1][1] + 1)
        else:
            out.append((f, 1))
    return out


def runs_per_flank(flanks) -> dict[int, list[int]]:
    """Run lengths per flank: {FPLUS: [...], FMINUS: [...]}, each in order of time."""
    d = {FPLUS: [], FMINUS: []}
    for f, n in runs(flanks):
        d[f].append(n)
    return d


def rates(impact_t, impact_flank, t0: float, t1: float) -> dict[int, float]:
    """Impacts per second per flank over the window [t0, t1)."""
    impact_t = np.asarray(impact_t, dtype=float)
    impact_flank = np.asarray(impact_flank, dtype=int)
    sel = (impact_t >= t0) & (impact_t < t1)
    return {fl: float(np.count_nonzero(sel & (impact_flank == fl))) / (t1 - t0) for fl in (FPLUS, FMINUS)}


def flanks_from_counters(n_plus, n_minus):
    """Flank sequence from sampled cumulative counters (FMU outputs impacts_Fplus/_Fminus).

    Returns (flanks, ambiguous): the flank of each impact in order, and the number of
    sampling intervals in which both counters rose (order unknown there: F+ listed first)."""
    dp = np.diff(np.asarray(n_plus, dtype=np.int64), prepend=0)
    dm = np.diff(np.asarray(n_minus, dtype=np.int64), prepend=0)
    if np.any(dp < 0) or np.any(dm < 0):
        raise ValueError("impact counters decreased")
    flanks = []
    ambiguous = 0
    for a, b in zip(dp.tolist(), dm.tolist()):
        if a and b:
            ambiguous += 1
        flanks.extend([FPLUS] * a)
        flanks.extend([FMINUS] * b)
    return np.array(flanks, dtype=int), ambiguous
