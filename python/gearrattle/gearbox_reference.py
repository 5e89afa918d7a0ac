"""Independent high-accuracy reference of the gearbox model (docs/GEARBOX.md).

Written from docs/GEARBOX.md §1-§6 and docs/MODEL.md §1-§3 alone (not from the Rust code), to check
the GearboxRattle FMU against. Parameters are keyed by the FMU's contract names
(`DEFAULTS`, gears as "gear[i].X" with i = 1..n_gears).

Coordinates are relative (docs/GEARBOX.md §3): the state is

    y = [phi, phi_dot, w_F, q_F, xi_1..xi_N, xi_dot_1..xi_dot_N, quadratures]

* phi = theta_F - theta_I, the damper's twist, and phi_dot = omega_F - omega_I its rate:
  the input side's speed omega_I = omega_F - phi_dot is never a state, whose tolerance
  (relative to ~100 rad/s) would blur xi_dot by r_M times its error;
* the flywheel (§4) as omega_F = Omega_0 + Omega' t + w_F and
  theta_F = Omega_0 t + Omega' t^2/2 + q_F: w_F' = sum_k a_k cos(psi_k) and q_F' = w_F are
  integrated with the rest (quadrature, ramp or not: no Fresnel integrals), so that the
  state holds only the bounded fluctuation and theta_F is never a difference of large
  numbers;
* xi_i = r_L,i theta_L,i - r_M,i rho_i theta_I and xi_dot_i its rate (§1);
* quadratures (§3's energy terms): W_F = int T_cl omega_F dt (work of the flywheel),
  D_damper = int (H tanh(phi'/omega_h) + c_cl phi') phi' dt, D_input = int c_I omega_I^2 dt,
  and per gear D_contact_i = int s C_LM xi_dot^2 dt, D_lubricant_i = int C (omega_L -
  omega_S)^2 dt, W_ext_i = int (B omega_L - C (omega_L - omega_S) omega_S) dt.

Then, with T_cl, F_i, c_I(T) and C_i(T) of §2, §5 and docs/MODEL.md §2:

    omega_L,i = (xi_dot_i + r_M,i rho_i omega_I) / r_L,i
    omega_I'  = (T_cl + sum_i rho_i r_M,i F_i - c_I omega_I) / I_I
    xi_i''    = r_L,i (B_i - r_L,i F_i - C_i (omega_L,i - omega_S,i)) / I_L,i
                - r_M,i rho_i omega_I'
    phi_dot'  = alpha_F - omega_I'

and the energy of §3, E = 1/2 I_I omega_I^2 + sum 1/2 I_L,i omega_L,i^2 + V_cl(phi) +
sum V_i(xi_i), obeys E(t) - E(0) = W_F - D_damper - D_input - sum (D_contact_i +
D_lubricant_i) + sum W_ext_i.

Integration is piecewise, as in `gearrattle.reference` for one gear: each gear's region of
the contact law (five, edges -eps, 0, G, G+eps) and the damper's stage (three, edges
-phi_1, +phi_1) are locked during a piece, and a piece ends exactly on the first edge that
any of them crosses. The steps are driven by hand with scipy's DOP853 (or Radau, the
independent second method); after each step every gear's xi and the twist phi are checked
at the step's end and, where their rate changed sign inside the step, at the turning point
found on the dense output, so that an edge crossed and recrossed within one step (a grazing
touch) is not skipped. The crossing is located by a root search on the dense output, and
the state there is reached by a step of the method from the step's start (the dense
output's error, carried on at every restart, would limit the accuracy).

Impacts are contact onsets (docs/MODEL.md §1): a gear leaving the gap downwards through 0 (flank
F+) or upwards through G (flank F-).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import quad

from gearrattle.piecewise import SOLVERS, Outputs, edge_in_step, output_grid, output_times, step
from gearrattle.reference import FMINUS, FPLUS, _contact, _regions, contact_force

# docs/GEARBOX.md §6, per gear: (ratio r_L/r_M, r_M, r_L, I_L, G, C_LM, C at 40 °C)
_TABLE = [
    (3.50, 0.012, 0.042, 0.75e-3, 80e-6, 90.0, 2e-3),
    (2.00, 0.018, 0.036, 0.40e-3, 80e-6, 80.0, 2e-3),
    (1.35, 0.023, 0.031, 0.22e-3, 70e-6, 70.0, 2e-3),
    (1.00, 0.027, 0.027, 0.13e-3, 70e-6, 60.0, 2e-3),
    (0.80, 0.030, 0.024, 0.08e-3, 60e-6, 52.0, 2e-3),
]

GEAR_KEYS = ("I_L", "r_L", "r_M", "rho", "G", "K_star", "alpha", "epsilon", "C_LM", "C", "B", "sigma", "gap_start")
MAX_GEARS = 8


def _gear_defaults(i: int, row) -> dict:
    _, r_M, r_L, I_L, G, C_LM, C = row
    g = dict(I_L=I_L, r_L=r_L, r_M=r_M, rho=1.0, G=G, K_star=3e6, alpha=4.0 / 3.0, epsilon=1e-6)
    g.update(C_LM=C_LM, C=C, B=0.0, sigma=0.0, gap_start=0.5)
    return {f"gear[{i}].{k}": v for k, v in g.items()}


# The five-speed box of docs/GEARBOX.md §6 (and the engine of §4, the oil of §5).
DEFAULTS = dict(
    n_gears=5,
    I_I=0.008,
    c_I=5e-3,
    k_1=0.5 * 180.0 / math.pi,  # 0.5 N m/deg
    k_2=15.0 * 180.0 / math.pi,  # 15 N m/deg
    phi_1=3.0 * math.pi / 180.0,
    H_1=0.2,
    H_2=3.0,
    c_cl=0.02,
    omega_h=0.01,
    T_oil=40.0,
    nu_40=55.0,
    nu_100=9.5,
    excitation=1,
    rpm=800.0,
    rpm_rate=0.0,
    order_1=2.0,
    a_1=600.0,
    phase_1=0.0,
    order_2=4.0,
    a_2=120.0,
    phase_2=0.0,
    stats_from=0.5,
    phi_start=0.0,
    omega_out=0.0,  # an input of the FMU: the output shaft's speed, held constant here
)
for _i, _row in enumerate(_TABLE, start=1):
    DEFAULTS.update(_gear_defaults(_i, _row))

# Scenes: B1, B2 of docs/GEARBOX.md §8 and R1, a run-down from 800 to 500 rpm over 2 s.
SCENES = {
    "B1": dict(),
    "B2": dict(T_oil=-10.0),
    "R1": dict(rpm_rate=-150.0),
}

# Damper stage codes: -1 main stage (phi < -phi_1), 0 pre-damper, +1 main stage (phi > phi_1).
IDLE = 0

_TWO_PI = 2.0 * math.pi


def params(scene: str | None = None, **overrides) -> dict:
    """Full parameter dict: DEFAULTS, then the scene's (SCENES), then overrides (contract
    names, "gear[i].X" for gears; gears beyond the defaults' five need all their keys)."""
    p = dict(DEFAULTS)
    if scene is not None:
        p.update(SCENES[scene])
    allowed = set(DEFAULTS) | {f"gear[{i}].{k}" for i in range(1, MAX_GEARS + 1) for k in GEAR_KEYS}
    unknown = set(overrides) - allowed
    if unknown:
        raise KeyError(f"unknown parameter(s): {sorted(unknown)}")
    p.update(overrides)
    return p


def gear(p: dict, i: int) -> dict:
    """Gear i's parameters (1-based) under docs/MODEL.md's names, its drag C at the oil's
    temperature (§5) and omega_S = sigma omega_out: the dict `gearrattle.reference` reads."""
    g = {k: p[f"gear[{i}].{k}"] for k in GEAR_KEYS}
    g["C"] = g["C"] * viscosity_factor(p)
    g["omega_S"] = g["sigma"] * p["omega_out"]
    return g


# ----------------------------------------------------------------------------------------
# Model functions (§2, §4, §5)
# ----------------------------------------------------------------------------------------


def viscosity_factor(p: dict, T=None):
    """nu(T) / nu_40 of Vogel's law (docs/GEARBOX.md §5, c = 95 °C); T defaults to p["T_oil"]."""
    T = p["T_oil"] if T is None else np.asarray(T, dtype=float)
    b = math.log(p["nu_40"] / p["nu_100"]) / (1.0 / 135.0 - 1.0 / 195.0)
    return np.exp(b * (1.0 / (T + 95.0) - 1.0 / 135.0))


def _orders(p: dict):
    """The engine orders with a non-zero amplitude: [(n_k, a_k, phase_k)]."""
    return [(p[f"order_{k}"], p[f"a_{k}"], p[f"phase_{k}"]) for k in (1, 2) if p[f"a_{k}"] != 0.0]


def engine_start(p: dict):
    """Omega_0 [rad/s], Omega' [rad/s^2] and omega_F(0) of docs/GEARBOX.md §4."""
    om0 = _TWO_PI * p["rpm"] / 60.0
    ramp = _TWO_PI * p["rpm_rate"] / 60.0
    return om0, ramp, om0 + sum(a / (n * om0) * math.sin(ph) for n, a, ph in _orders(p))


def engine_acceleration(t, p: dict):
    """alpha_F(t) = Omega' + sum_k a_k cos(psi_k) (docs/GEARBOX.md §4, vectorised)."""
    t = np.asarray(t, dtype=float)
    om0, ramp, _ = engine_start(p)
    angle = om0 * t + 0.5 * ramp * t * t
    return ramp + sum(a * np.cos(n * angle + ph) for n, a, ph in _orders(p))


def damper_spring(phi, p: dict):
    """T_k(phi) and V_cl(phi) = int_0^phi T_k (docs/GEARBOX.md §2, vectorised)."""
    phi = np.asarray(phi, dtype=float)
    k1, k2, phi1 = p["k_1"], p["k_2"], p["phi_1"]
    beyond = np.maximum(np.abs(phi) - phi1, 0.0)
    inner = np.minimum(np.abs(phi), phi1)
    torque = np.sign(phi) * (k1 * inner + k2 * beyond)
    energy = 0.5 * k1 * inner**2 + k1 * phi1 * beyond + 0.5 * k2 * beyond**2
    return torque, energy


def damper_torque(phi, phi_dot, p: dict, stage=None):
    """T_cl of docs/GEARBOX.md §2 (vectorised); stage: the damper's stage where phi sits on an
    edge (default: from phi, the pre-damper at |phi| = phi_1)."""
    phi = np.asarray(phi, dtype=float)
    if stage is None:
        stage = stage_of(phi, p)
    H = np.where(np.asarray(stage) == IDLE, p["H_1"], p["H_2"])
    return damper_spring(phi, p)[0] + H * np.tanh(np.asarray(phi_dot) / p["omega_h"]) + p["c_cl"] * np.asarray(phi_dot)


def stage_of(phi, p: dict):
    """The damper's stage code from the twist: -1, 0 (|phi| <= phi_1), +1."""
    phi = np.asarray(phi, dtype=float)
    return np.where(phi > p["phi_1"], 1, np.where(phi < -p["phi_1"], -1, IDLE))


def contact_potential(xi, g: dict):
    """V(xi) = int F_k dxi of docs/MODEL.md §2 (zero in the gap): closed form beyond the bands,
    adaptive quadrature inside them (vectorised over xi)."""
    K, alpha, eps, G = g["K_star"], g["alpha"], g["epsilon"], g["G"]

    def fk(delta):  # F_k without smoothing
        return K * delta * abs(delta / G) ** (alpha - 1.0)

    def s_band(delta):  # s(delta) in the band, delta = penetration (<= 0 on F+, >= 0 on F-)
        return 0.5 * (1.0 - math.sin(math.pi / eps * (eps / 2.0 - abs(delta))))

    def free(d):  # int_0^d K* delta |delta/G|^(alpha-1) ddelta
        return K * abs(d) ** (alpha + 1.0) / ((alpha + 1.0) * G ** (alpha - 1.0))

    band = quad(lambda d: s_band(d) * fk(d), 0.0, eps, epsabs=0.0, epsrel=1e-10)[0] if eps > 0 else 0.0
    out = []
    for x in np.atleast_1d(np.asarray(xi, dtype=float)):
        d = x if x < 0.0 else (x - G if x > G else 0.0)
        if abs(d) <= eps and d != 0.0:
            out.append(quad(lambda u: s_band(u) * fk(u), 0.0, abs(d), epsabs=0.0, epsrel=1e-10)[0])
        elif d != 0.0:
            out.append(band + free(d) - free(eps))
        else:
            out.append(0.0)
    return np.array(out)


# ----------------------------------------------------------------------------------------
# State layout and right-hand side
# ----------------------------------------------------------------------------------------


class _Layout:
    """Indices of the state vector (module docstring)."""

    def __init__(self, n: int):
        self.n = n
        self.xi = 4
        self.xi_dot = 4 + n
        self.W_F = 4 + 2 * n
        self.D_damper = self.W_F + 1
        self.D_input = self.W_F + 2
        self.D_contact = self.W_F + 3
        self.D_lubricant = self.D_contact + n
        self.W_ext = self.D_lubricant + n
        self.size = self.W_ext + n


def _make_rhs(p: dict, gears: list, stage: int, codes: tuple):
    """Right-hand side with the damper's stage and every gear's contact region locked."""
    n = len(gears)
    om0, ramp, _ = engine_start(p)
    orders = _orders(p)
    I_I = p["I_I"]
    c_I = p["c_I"] * viscosity_factor(p)
    k1, k2, phi1, omh, c_cl = p["k_1"], p["k_2"], p["phi_1"], p["omega_h"], p["c_cl"]
    H = p["H_1"] if stage == IDLE else p["H_2"]
    contacts = [_contact(g, c) for g, c in zip(gears, codes)]
    rows = [
        (g["I_L"], g["r_L"], g["r_M"] * g["rho"], g["C_LM"], g["C"], g["B"], g["omega_S"], contacts[i])
        for i, g in enumerate(gears)
    ]
    tanh, cos = math.tanh, math.cos

    def rhs(t, y):
        phi, phi_dot, w_F = y[0], y[1], y[2]
        angle = om0 * t + 0.5 * ramp * t * t
        a_F = 0.0
        for n_k, a_k, ph_k in orders:
            a_F += a_k * cos(n_k * angle + ph_k)
        om_F = om0 + ramp * t + w_F
        om_I = om_F - phi_dot
        if stage == IDLE:
            T_k = k1 * phi
        elif stage > 0:
            T_k = k1 * phi1 + k2 * (phi - phi1)
        else:
            T_k = -k1 * phi1 + k2 * (phi + phi1)
        T_f = H * tanh(phi_dot / omh) + c_cl * phi_dot
        T_cl = T_k + T_f
        reaction = 0.0
        acc = [0.0] * n  # r_L omega_L' of each gear
        d_contact, d_lub, w_ext = [0.0] * n, [0.0] * n, [0.0] * n
        for i, (I_L, r_L, r_M_rho, C_LM, C, B, om_S, contact) in enumerate(rows):
            v = y[4 + n + i]
            s, F = contact(y[4 + i], v)
            om_L = (v + r_M_rho * om_I) / r_L
            slip = om_L - om_S
            reaction += r_M_rho * F
            acc[i] = r_L * (B - r_L * F - C * slip) / I_L
            d_contact[i] = s * C_LM * v * v
            d_lub[i] = C * slip * slip
            w_ext[i] = B * om_L - C * slip * om_S
        a_I = (T_cl + reaction - c_I * om_I) / I_I
        dy = [phi_dot, ramp + a_F - a_I, a_F, w_F]
        dy += y[4 + n : 4 + 2 * n].tolist()
        dy += [acc[i] - rows[i][2] * a_I for i in range(n)]
        dy += [T_cl * om_F, T_f * phi_dot, c_I * om_I * om_I]
        return np.array(dy + d_contact + d_lub + w_ext)

    return rhs


# ----------------------------------------------------------------------------------------
# Piecewise integration
# ----------------------------------------------------------------------------------------


@dataclass
class Result:
    """What `simulate` returns; arrays at the output times t (gear arrays: one row per gear,
    row i-1 for gear[i])."""

    params: dict
    t: np.ndarray
    phi: np.ndarray
    omega_I: np.ndarray
    omega_F: np.ndarray
    theta_F: np.ndarray
    xi: np.ndarray  # (N, len(t))
    xi_dot: np.ndarray  # (N, len(t))
    quadratures: dict  # W_F, D_damper, D_input (len(t)); D_contact, D_lubricant, W_ext (N, len(t))
    impacts: list  # per gear: dict(t, flank, speed) of numpy arrays
    stage_t: np.ndarray  # times the damper enters a stage (the first: t = 0)
    stage: np.ndarray  # the stage entered then: -1, 0, +1
    nfev: int
    nsteps: int
    npieces: int
    method: str
    rtol: float
    final_y: np.ndarray = field(repr=False, default=None)

    @property
    def theta_I(self):
        return self.theta_F - self.phi

    def omega_L(self):
        """Each gear's speed at the output points, (N, len(t))."""
        gs = [gear(self.params, i + 1) for i in range(self.xi.shape[0])]
        return np.array([(self.xi_dot[i] + g["r_M"] * g["rho"] * self.omega_I) / g["r_L"] for i, g in enumerate(gs)])

    def impact_rates(self, t0: float | None = None, t1: float | None = None) -> np.ndarray:
        """Impacts per second per gear (both flanks) over [t0, t1), by default from
        stats_from to the run's end."""
        t0 = self.params["stats_from"] if t0 is None else t0
        t1 = self.t[-1] if t1 is None else t1
        return np.array([np.count_nonzero((d["t"] >= t0) & (d["t"] < t1)) / (t1 - t0) for d in self.impacts])

    def impact_counts(self, t, flank: int | None = None) -> np.ndarray:
        """Cumulative impact counts per gear at the times t (onsets at <= t counted), on one
        flank (FPLUS, FMINUS) or both: (N, len(t))."""
        t = np.asarray(t, dtype=float)
        out = []
        for d in self.impacts:
            ti = d["t"] if flank is None else d["t"][d["flank"] == flank]
            out.append(np.searchsorted(ti, t, side="right"))
        return np.array(out)

    def main_stage_share(self, t0: float | None = None, t1: float | None = None) -> float:
        """Share of [t0, t1) (default: stats_from to the end) the damper spends beyond
        +-phi_1, exact from the stage's switching times."""
        t0 = self.params["stats_from"] if t0 is None else t0
        t1 = self.t[-1] if t1 is None else t1
        edges = np.append(self.stage_t, np.inf)
        main = 0.0
        for k, st in enumerate(self.stage):
            a, b = max(edges[k], t0), min(edges[k + 1], t1)
            if st != IDLE and b > a:
                main += b - a
        return main / (t1 - t0)

    def energy(self) -> dict:
        """docs/GEARBOX.md §3's terms at the output points: E (mechanical energy), its parts
        (kinetic, V_cl, V per gear), the quadratures, and balance = E - E(0) - W_F +
        D_damper + D_input + sum(D_contact + D_lubricant - W_ext), zero up to the error."""
        p = self.params
        n = self.xi.shape[0]
        gs = [gear(p, i + 1) for i in range(n)]
        om_L = self.omega_L()
        kinetic = 0.5 * p["I_I"] * self.omega_I**2 + sum(0.5 * g["I_L"] * om_L[i] ** 2 for i, g in enumerate(gs))
        V_cl = damper_spring(self.phi, p)[1]
        V = np.array([contact_potential(self.xi[i], g) for i, g in enumerate(gs)])
        E = kinetic + V_cl + V.sum(axis=0)
        q = self.quadratures
        lost = q["D_damper"] + q["D_input"] + (q["D_contact"] + q["D_lubricant"] - q["W_ext"]).sum(axis=0)
        return dict(E=E, kinetic=kinetic, V_cl=V_cl, V=V, balance=E - E[0] - q["W_F"] + lost, **q)


def simulate(
    p: dict | None = None,
    t_end: float = 2.0,
    t_eval=None,
    method: str = "DOP853",
    rtol: float = 1e-12,
    e_scale: float = 1e-3,
) -> Result:
    """Integrate the gearbox from t = 0 to t_end (start of docs/GEARBOX.md §6: theta_F(0) = 0,
    phi(0) = phi_start, omega_I(0) = omega_F(0) (phi_dot(0) = 0), each gear at rigid meshing
    speed with xi_i(0) = gap_start_i G_i).

    p: full parameter dict (see `params`); t_eval: increasing output times in [0, t_end]
    (default: 0 and t_end); method: 'DOP853', 'Radau' or another of piecewise.SOLVERS;
    rtol: relative tolerance, the absolute ones being rtol times phi_1, 1 rad/s (phi_dot),
    1 rad/s (w_F), 1 rad (q_F), G_i, 100 G_i /s (below the gears' speeds in the gap, so that
    rtol rules) and e_scale [J] for the quadratures."""
    p = params() if p is None else dict(p)
    if p["excitation"] != 1:
        raise ValueError("the reference has the built-in engine only (excitation = 1)")
    n = int(p["n_gears"])
    gears = [gear(p, i + 1) for i in range(n)]
    lay = _Layout(n)
    om0, ramp, om_F0 = engine_start(p)

    y = np.zeros(lay.size)
    y[0] = p["phi_start"]
    y[2] = om_F0 - om0
    for i, g in enumerate(gears):
        y[lay.xi + i] = g["gap_start"] * g["G"]
    atol = np.full(lay.size, rtol * e_scale)
    atol[:4] = rtol * np.array([p["phi_1"], 1.0, 1.0, 1.0])
    for i, g in enumerate(gears):
        atol[lay.xi + i] = rtol * g["G"]
        atol[lay.xi_dot + i] = rtol * g["G"] * 100.0

    # switches: (index of x in y, index of its rate x', ordered regions)
    phi1 = p["phi_1"]
    damper_regions = [(-1, -math.inf, -phi1), (IDLE, -phi1, phi1), (1, phi1, math.inf)]
    switches = [(0, 1, damper_regions)]
    switches += [(lay.xi + i, lay.xi_dot + i, _regions(g)) for i, g in enumerate(gears)]
    region = [next(k for k, (_, lo, hi) in enumerate(reg) if lo <= y[ix] <= hi) for ix, _, reg in switches]

    t_eval = output_times(t_eval, 0.0, t_end)
    outputs = Outputs(t_eval, lay.size)
    outputs.fill(0.0, lambda _t: y)

    impacts = [dict(t=[], flank=[], speed=[]) for _ in gears]
    stage_t, stage = [0.0], [damper_regions[region[0]][0]]
    nfev = nsteps = npieces = stalls = 0
    solver_cls = SOLVERS[method]
    t = 0.0
    while t < t_end:
        codes = tuple(switches[j][2][region[j]][0] for j in range(1, n + 1))
        rhs = _make_rhs(p, gears, damper_regions[region[0]][0], codes)
        solver = solver_cls(rhs, t, y, t_end, rtol=rtol, atol=atol)
        npieces += 1
        crossing = None  # (t, switch, side)
        while True:
            t_old, y_old = solver.t, solver.y.copy()
            step(solver)
            nsteps += 1
            t_new, y_new = solver.t, solver.y
            dense = None
            for j, (ix, iv, reg) in enumerate(switches):
                _, lo, hi = reg[region[j]]
                found, dense, _ = edge_in_step(solver, dense, ix, iv, lo, hi, t_old, y_old, y_new)
                if found is not None and (crossing is None or found[0] < crossing[0]):
                    crossing = (found[0], j, found[1])
            t_lim = t_new if crossing is None else crossing[0]
            if outputs.due(t_lim):
                dense = dense or solver.dense_output()
                outputs.fill(t_lim, dense)
            if crossing is not None or solver.status == "finished":
                break
        nfev += solver.nfev
        if crossing is None:
            t, y = solver.t, solver.y
            break
        t_c, j, side = crossing
        ix, _, reg = switches[j]
        _, lo, hi = reg[region[j]]
        y, fev = _reach(solver_cls, rhs, t_old, y_old, t_c, rtol, atol)
        nfev += fev
        y[ix] = lo if side < 0 else hi
        stalls = stalls + 1 if t_c <= t else 0
        if stalls > 20:
            raise RuntimeError(f"no progress at t={t}: switch {j}, x={y[ix]}")
        t = t_c
        if j == 0:
            stage_t.append(t)
            stage.append(reg[region[j] + side][0])
        elif reg[region[j]][0] == 2:  # a gear leaving the gap: a contact onset
            d = impacts[j - 1]
            d["t"].append(t)
            d["flank"].append(FPLUS if side < 0 else FMINUS)
            d["speed"].append(abs(y[lay.xi_dot + j - 1]))
        region[j] += side

    outputs.fill(math.inf, lambda _t: y)

    out, n_t = outputs.values, t_eval.size
    quads = dict(
        W_F=out[lay.W_F],
        D_damper=out[lay.D_damper],
        D_input=out[lay.D_input],
        D_contact=out[lay.D_contact : lay.D_contact + n].reshape(n, n_t),
        D_lubricant=out[lay.D_lubricant : lay.D_lubricant + n].reshape(n, n_t),
        W_ext=out[lay.W_ext : lay.W_ext + n].reshape(n, n_t),
    )
    return Result(
        params=p,
        t=t_eval,
        phi=out[0],
        omega_I=om0 + ramp * t_eval + out[2] - out[1],
        omega_F=om0 + ramp * t_eval + out[2],
        theta_F=om0 * t_eval + 0.5 * ramp * t_eval**2 + out[3],
        xi=out[lay.xi : lay.xi + n].reshape(n, n_t),
        xi_dot=out[lay.xi_dot : lay.xi_dot + n].reshape(n, n_t),
        quadratures=quads,
        impacts=[{k: np.array(v, dtype=int if k == "flank" else float) for k, v in d.items()} for d in impacts],
        stage_t=np.array(stage_t),
        stage=np.array(stage, dtype=int),
        nfev=nfev,
        nsteps=nsteps,
        npieces=npieces,
        method=method,
        rtol=rtol,
        final_y=np.array(y),
    )


def _reach(solver_cls, rhs, t0, y0, t1, rtol, atol):
    """(y(t1), RHS calls) by steps of the method itself from (t0, y0), normally one: its end
    value is more accurate than the dense output, whose error a restart would carry on."""
    if t1 <= t0:
        return np.array(y0), 0
    solver = solver_cls(rhs, t0, y0, t1, rtol=rtol, atol=atol, first_step=t1 - t0)
    while solver.status == "running":
        solver.step()
    if solver.status == "failed":
        raise RuntimeError(f"no step from {t0} to {t1}")
    return np.array(solver.y), solver.nfev


@functools.lru_cache(maxsize=None)
def scene(name: str, t_end: float, dt_out: float, method: str = "DOP853", rtol: float = 1e-12) -> Result:
    """A scene of SCENES with the defaults, outputs every dt_out (i * dt_out), cached for
    the tests of one session."""
    return simulate(params(name), t_end, t_eval=output_grid(t_end, dt_out), method=method, rtol=rtol)


# ----------------------------------------------------------------------------------------
# Recorded motion (for the FMU's imposed-motion excitation)
# ----------------------------------------------------------------------------------------


def recorded_motion(t, p: dict | None = None, **kw) -> dict:
    """The coupled box's input-side and flywheel motion at the sample times t (increasing,
    from 0): theta_I, omega_I, alpha_I and theta_F, omega_F, alpha_F, plus the run itself
    (`result`). alpha_I is omega_I' from the state at each sample (its contact regions and
    damper stage read from xi and phi). kw: simulate's options."""
    p = params() if p is None else dict(p)
    t = np.asarray(t, dtype=float)
    res = simulate(p, t_end=float(t[-1]), t_eval=t, **kw)
    n = res.xi.shape[0]
    gs = [gear(p, i + 1) for i in range(n)]
    # reaction of the gears: docs/MODEL.md §2's force, region from xi (continuous across edges)
    reaction = sum(g["rho"] * g["r_M"] * contact_force(res.xi[i], res.xi_dot[i], g) for i, g in enumerate(gs))
    phi_dot = res.omega_F - res.omega_I
    T_cl = damper_torque(res.phi, phi_dot, p)
    alpha_I = (T_cl + reaction - p["c_I"] * viscosity_factor(p) * res.omega_I) / p["I_I"]
    return dict(
        t=t,
        theta_I=res.theta_I,
        omega_I=res.omega_I,
        alpha_I=alpha_I,
        theta_F=res.theta_F,
        omega_F=res.omega_F,
        alpha_F=engine_acceleration(t, p),
        result=res,
    )
