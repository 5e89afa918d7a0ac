"""Checks of the gearbox reference (gearrattle.gearbox_reference) against facts of
docs/GEARBOX.md that do not come from the reference itself: the energy balance (§3), the
damper's free oscillation (§2, linear and two-stage), Vogel's law (§5), the engine's closed
form (§4) and the impact definition (docs/MODEL.md §1) on a constructed case.

These tests do not need the FMU."""

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from gearrattle import gearbox_reference as B

# every dissipation off (docs/GEARBOX.md §3's strict test)
LOSSLESS = dict(c_cl=0.0, H_1=0.0, H_2=0.0, c_I=0.0)
LOSSLESS.update({f"gear[{i}].{k}": 0.0 for i in range(1, 6) for k in ("C_LM", "C", "B")})

# flywheel held at theta_F = 0, one gear flying in a 1 m gap (never touches)
HELD = dict(rpm=0.0, a_1=0.0, a_2=0.0, n_gears=1)
FLYING = {"gear[1].G": 1.0}


def test_vogel_factors():
    p = B.params()
    assert B.viscosity_factor(p, 40.0) == 1.0
    assert B.viscosity_factor(p, 100.0) == pytest.approx(p["nu_100"] / p["nu_40"], rel=1e-14)
    assert round(float(B.viscosity_factor(p, -10.0))) == 29
    assert round(float(B.viscosity_factor(p, 80.0)), 2) == 0.27
    # both drags follow the oil: the reference's gear drag is C_i nu(T)/nu_40
    cold = B.params(T_oil=-10.0)
    assert B.gear(cold, 3)["C"] == pytest.approx(2e-3 * B.viscosity_factor(cold), rel=1e-15)


def test_engine_speed_against_closed_form():
    """omega_F, theta_F integrated with the state against docs/GEARBOX.md §4's closed form."""
    p = B.params(phase_1=0.7, phase_2=-1.1, **HELD | {"rpm": 800.0, "a_1": 600.0, "a_2": 120.0}, **FLYING)
    t = np.linspace(0.0, 0.3, 301)
    r = B.simulate(p, 0.3, t_eval=t)
    om = 2 * math.pi * 800 / 60
    terms = [(2.0, 600.0, 0.7), (4.0, 120.0, -1.1)]

    def omega_F(s):
        return om + sum(a / (n * om) * np.sin(n * om * s + ph) for n, a, ph in terms)

    theta_F = om * t - sum(a / (n * om) ** 2 * (np.cos(n * om * t + ph) - math.cos(ph)) for n, a, ph in terms)
    assert np.max(np.abs(r.omega_F - omega_F(t))) < 1e-11 * om
    assert np.max(np.abs(r.theta_F - theta_F)) < 1e-11 * om * 0.3
    # docs/GEARBOX.md §6's start: the input side at omega_F(0), the gear at rigid meshing speed
    assert r.omega_I[0] == pytest.approx(omega_F(0.0), rel=1e-15) and r.xi_dot[0, 0] == 0.0
    # alpha_F (the recorded motion's) is the closed form's derivative
    h = 1e-6
    assert np.max(np.abs(B.engine_acceleration(t, p) - (omega_F(t + h) - omega_F(t - h)) / (2 * h))) < 1e-3


def test_engine_ramp_against_quadrature():
    """With a ramp, omega_F(t) - omega_F(0) against a quadrature of alpha_F, written here
    from docs/GEARBOX.md §4."""
    p = B.params(rpm_rate=-300.0, phase_1=0.3, **HELD | {"rpm": 800.0, "a_1": 600.0, "a_2": 120.0}, **FLYING)
    t = np.linspace(0.0, 0.5, 6)
    r = B.simulate(p, 0.5, t_eval=t)
    om, ramp = 2 * math.pi * 800 / 60, -2 * math.pi * 300 / 60

    def alpha_F(s):
        angle = om * s + 0.5 * ramp * s * s
        return ramp + 600.0 * math.cos(2.0 * angle + 0.3) + 120.0 * math.cos(4.0 * angle)

    assert r.omega_F[0] == pytest.approx(om + 600.0 / (2.0 * om) * math.sin(0.3), rel=1e-15)
    assert np.allclose(B.engine_acceleration(t, p), [alpha_F(s) for s in t], rtol=0.0, atol=1e-9)
    for tk, wk in zip(t, r.omega_F):
        ref = r.omega_F[0] + quad(alpha_F, 0.0, tk, limit=500, epsabs=1e-13)[0]
        assert wk == pytest.approx(ref, rel=1e-11)


def test_damper_linear_resonance():
    """Flywheel held, gear flying: phi = phi_0 cos(sqrt(k_1/I_I) t), 9.5 Hz (§6)."""
    phi0 = 0.01
    p = B.params(phi_start=phi0, **HELD, **FLYING, **LOSSLESS)
    w = math.sqrt(p["k_1"] / p["I_I"])
    assert w / (2 * math.pi) == pytest.approx(9.52, abs=0.01)
    t = np.linspace(0.0, 0.3, 301)
    r = B.simulate(p, 0.3, t_eval=t)
    assert np.max(np.abs(r.phi - phi0 * np.cos(w * t))) < 1e-9 * phi0
    assert r.stage.tolist() == [B.IDLE]
    assert np.max(np.abs(r.theta_I + r.phi)) == 0.0  # theta_F stays 0


def test_damper_two_stage_period():
    """Free oscillation from phi_0 = 2 phi_1: a quarter period is the pre-damper's arc from
    0 to phi_1 plus the main stage's arc from phi_1 to phi_0 (closed forms)."""
    p = B.params(**HELD, **FLYING, **LOSSLESS)
    k1, k2, phi1, I = p["k_1"], p["k_2"], p["phi_1"], p["I_I"]
    phi0 = 2 * phi1
    E = 0.5 * k1 * phi1**2 + k1 * phi1 * (phi0 - phi1) + 0.5 * k2 * (phi0 - phi1) ** 2
    w1, w2 = math.sqrt(k1 / I), math.sqrt(k2 / I)
    t1 = math.asin(phi1 * w1 / math.sqrt(2 * E / I)) / w1
    x_e = -k1 * phi1 / k2  # the main stage's equilibrium, from phi_1
    t2 = (math.pi / 2 - math.asin(-x_e / (phi0 - phi1 - x_e))) / w2
    period = 4 * (t1 + t2)
    r = B.simulate(B.params(phi_start=phi0, **HELD, **FLYING, **LOSSLESS), 2.2 * period)
    assert r.stage[:6].tolist() == [1, 0, -1, 0, 1, 0]
    assert r.stage_t[1] == pytest.approx(t2, rel=1e-10)
    assert r.stage_t[5] - r.stage_t[1] == pytest.approx(period, rel=1e-10)
    assert r.stage_t[2] - r.stage_t[1] == pytest.approx(2 * t1, rel=1e-10)


def test_damper_friction_per_stage():
    """Flywheel held, no viscous loss: the first swing from phi_0 = 0.1 rad to -phi_a loses
    to the hysteresis H_2 beyond phi_1 and H_1 within it (§2, tanh ~ sign away from the
    turning points): V_cl(phi_0) - V_cl(phi_a) = H_2 (phi_0 + phi_a - 2 phi_1) + 2 H_1 phi_1."""
    p = B.params(phi_start=0.1, c_cl=0.0, c_I=0.0, **HELD, **FLYING)
    H1, H2, phi1 = p["H_1"], p["H_2"], p["phi_1"]

    def V(phi):
        return float(B.damper_spring(phi, p)[1])

    phi_a = brentq(lambda x: V(0.1) - V(x) - H2 * (0.1 + x - 2 * phi1) - 2 * H1 * phi1, phi1, 0.1)
    t = np.linspace(0.0, 0.025, 12501)
    r = B.simulate(p, 0.025, t_eval=t)
    assert r.stage[:4].tolist() == [1, 0, -1, 0] and r.stage_t[2] < t[np.argmin(r.phi)] < r.stage_t[3]
    assert -r.phi.min() == pytest.approx(phi_a, abs=2e-8)
    assert 0.1 - phi_a > 1e5 * 2e-8  # the loss is resolved


def test_energy_balance_lossless():
    """docs/GEARBOX.md §3: with every dissipation off, E - E(0) = W_F, to 1e-9 of E, the engine
    running down. The twist starts beyond phi_1 (without friction the idle stage alone
    would hold it)."""
    p = B.params(phi_start=0.08, n_gears=2, rpm_rate=-300.0, **LOSSLESS)
    r = B.simulate(p, 0.2, t_eval=np.linspace(0.0, 0.2, 41))
    e = r.energy()
    assert all(d["t"].size > 10 for d in r.impacts)  # both gears rattle
    assert set(r.stage.tolist()) == {-1, 0, 1}  # both main stages visited
    assert np.max(np.abs(e["balance"])) < 1e-9 * e["E"][0]
    for k in ("D_damper", "D_input", "D_contact", "D_lubricant", "W_ext"):
        assert np.all(e[k] == 0.0)
    assert np.max(np.abs(e["W_F"])) > 1e-3 * e["E"][0]  # the flywheel does work


def test_energy_balance_with_losses():
    """Every loss term on, with a torque B and a turning output shaft."""
    p = B.params(omega_out=20.0, **{"gear[2].B": 0.05, "gear[2].sigma": 0.7, "gear[4].sigma": -0.4})
    r = B.simulate(p, 0.1, t_eval=np.linspace(0.0, 0.1, 21))
    e = r.energy()
    assert np.max(np.abs(e["balance"])) < 1e-9 * e["E"][0]
    for k in ("D_damper", "D_input"):
        assert e[k][-1] > 0.0
    assert np.all(e["D_contact"][:, -1] > 0.0) and np.all(e["D_lubricant"][:, -1] > 0.0)
    assert e["W_ext"][1, -1] != 0.0 and e["W_ext"][3, -1] != 0.0 and e["W_ext"][0, -1] == 0.0


@pytest.mark.parametrize("sign", [-1.0, 1.0])
def test_impact_is_the_gap_left(sign):
    """A torque B pushes gear 1 across its gap from rest (flywheel held, no drag): the
    flight is the parabola xi = G/2 + r_L B t^2 / (2 I_L), the impact its arrival at 0 (B < 0,
    flank F+) or G (B > 0, F-), though the contact stays inside the band (never reaches -eps
    or G + eps)."""
    b = sign * 2e-5
    g = B.gear(B.params(), 1)
    p = B.params(n_gears=1, rpm=0.0, a_1=0.0, a_2=0.0, **{"gear[1].B": b, "gear[1].C": 0.0})
    acc = g["r_L"] * abs(b) / g["I_L"]
    t_star = math.sqrt(g["G"] / acc)
    r = B.simulate(p, 1.5 * t_star, t_eval=np.linspace(0.0, 1.5 * t_star, 3001))
    imp = r.impacts[0]
    assert imp["t"][0] == pytest.approx(t_star, rel=1e-9)
    assert imp["speed"][0] == pytest.approx(acc * t_star, rel=1e-9)
    assert set(imp["flank"].tolist()) == {B.FPLUS if b < 0 else B.FMINUS}
    eps, G = g["epsilon"], g["G"]
    assert r.xi[0].min() > -eps and r.xi[0].max() < G + eps
    assert (r.xi[0].min() < -0.1 * eps) if b < 0 else (r.xi[0].max() > G + 0.1 * eps)


def test_leaving_a_flank_is_no_impact():
    """Gear 1 starts pressed into F+ and a torque drives it to F-: leaving F+ (xi rising
    through 0) is not an impact, the arrival at G is the one impact."""
    p = B.params(n_gears=1, rpm=0.0, a_1=0.0, a_2=0.0, **{"gear[1].B": 2e-4, "gear[1].C": 0.0, "gear[1].gap_start": -0.005})
    r = B.simulate(p, 0.15, t_eval=np.linspace(0, 0.15, 1501))
    imp = r.impacts[0]
    assert imp["flank"].tolist() == [B.FMINUS]
    t_hit = r.t[np.argmax(r.xi[0] > B.gear(p, 1)["G"])]
    assert imp["t"][0] == pytest.approx(t_hit, abs=r.t[1])


def test_recorded_motion_is_consistent():
    """theta_I, omega_I, alpha_I of a recorded run are each other's derivatives."""
    t = np.linspace(0.0, 0.02, 801)
    m = B.recorded_motion(t)
    h = t[1]
    inner = slice(1, -1)
    d_theta = (m["theta_I"][2:] - m["theta_I"][:-2]) / (2 * h)
    d_omega = (m["omega_I"][2:] - m["omega_I"][:-2]) / (2 * h)
    assert np.max(np.abs(d_theta - m["omega_I"][inner])) < 1e-3 * np.max(np.abs(m["omega_I"]))
    scale = np.max(np.abs(m["alpha_I"]))
    assert np.median(np.abs(d_omega - m["alpha_I"][inner])) < 1e-3 * scale
    assert m["omega_F"][0] == m["omega_I"][0] and m["theta_I"][0] == 0.0
