"""Checks of the Python reference (reference.py) against the independent facts of
docs/MODEL.md: the contact law (§2), the energy balance (§3) and the table of §5.

These tests do not need the FMU."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from gearrattle import reference as R

P = R.params()
G = P["G"]
EPS = P["epsilon"]


# ---------------------------------------------------------------------------------------
# Contact law (docs/MODEL.md §2)
# ---------------------------------------------------------------------------------------


def test_smoothing_factor_values_and_continuity():
    # the five regions
    assert R.smoothing([-2 * EPS, -EPS, -EPS / 2, 0.0, G / 2, G, G + EPS / 2, G + EPS, G + 2 * EPS], P).tolist() == (
        pytest.approx([1.0, 1.0, 0.5, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0], abs=1e-12)
    )
    # continuity of s at the four band edges, and ds/dxi = 0 there
    h = 1e-6 * EPS
    for edge in (-EPS, 0.0, G, G + EPS):
        s = R.smoothing([edge - h, edge, edge + h], P)
        assert abs(s[0] - s[1]) < 1e-10 and abs(s[2] - s[1]) < 1e-10
        # a quadratic touch: (s(edge +- h) - s(edge)) / h -> 0 like h / eps
        assert abs(s[0] - s[1]) / h < 1e-4 / EPS and abs(s[2] - s[1]) / h < 1e-4 / EPS
    # monotonic inside the bands, within [0, 1]
    xb = np.linspace(-EPS, 0.0, 1001)
    sb = R.smoothing(xb, P)
    assert np.all(np.diff(sb) <= 0) and sb.min() >= 0 and sb.max() <= 1
    xb = np.linspace(G, G + EPS, 1001)
    sb = R.smoothing(xb, P)
    assert np.all(np.diff(sb) >= 0) and sb.min() >= 0 and sb.max() <= 1
    # eps = 0: no band, a plain step
    p0 = R.params(epsilon=0.0)
    assert R.smoothing([-1e-12, 0.0 + 1e-12, G - 1e-12, G + 1e-12], p0).tolist() == [1.0, 0.0, 0.0, 1.0]


def test_contact_force_continuity_and_values():
    # F is continuous at the band edges (with and without speed), zero in the gap
    h = 1e-9 * EPS
    for v in (0.0, 0.05, -0.05):
        for edge in (-EPS, 0.0, G, G + EPS):
            f = R.contact_force([edge - h, edge, edge + h], [v, v, v], P)
            scale = 1.0 + abs(f[1])
            assert abs(f[0] - f[1]) < 1e-6 * scale and abs(f[2] - f[1]) < 1e-6 * scale
        assert np.all(R.contact_force(np.linspace(0, G, 11), np.full(11, v), P) == 0.0)
    # full contact: F_k = K* delta |delta/G|^(alpha-1) = K_LM delta |delta|^(alpha-1)
    k_lm = P["K_star"] / G ** (P["alpha"] - 1)
    assert k_lm == pytest.approx(1.03e8, rel=5e-3)  # docs/MODEL.md §4 (1.026e8, rounded)
    for delta in (-3e-6, -10e-6):
        f = R.contact_force([delta], [0.0], P)[0]
        assert f == pytest.approx(k_lm * delta * abs(delta) ** (P["alpha"] - 1), rel=1e-12)
        assert f < 0
        f_minus = R.contact_force([G - delta], [0.0], P)[0]
        assert f_minus == pytest.approx(-f, rel=1e-12)
    # damping part: s C_LM xi_dot
    assert R.contact_force([-2 * EPS], [0.1], P)[0] - R.contact_force([-2 * EPS], [0.0], P)[0] == pytest.approx(6.7)
    assert R.contact_force([-EPS / 2], [0.1], P)[0] - R.contact_force([-EPS / 2], [0.0], P)[0] == pytest.approx(3.35)
    # the damping ratio of docs/MODEL.md §4
    assert P["C_LM"] / (2 * math.sqrt(P["K_star"] * P["I_L"] / P["r_L"] ** 2)) == pytest.approx(0.04, rel=0.03)


def test_locked_region_formulas_match_contact_law():
    """The per-region right-hand sides of the integrator agree with the plain law."""
    t = 0.0123
    for xi in (-3 * EPS, -EPS / 3, G / 2, G + EPS / 4, G + 5 * EPS):
        v = 0.02
        code = int(np.searchsorted([-EPS, 0.0, G, G + EPS], xi))
        d = R._make_rhs(P, code)(t, np.array([xi, v, 0.0, 0.0]))
        om_l, al_l, f = R.loose_gear(t, np.array([xi]), np.array([v]), P)
        _, _, a_m = R.main_shaft(t, P)
        assert d[1] == pytest.approx(P["r_L"] * al_l[0] - P["r_M"] * a_m, rel=1e-12)
        assert d[2] == pytest.approx(R.smoothing([xi], P)[0] * P["C_LM"] * v * v, rel=1e-12, abs=0)
        assert d[3] == pytest.approx(P["C"] * om_l[0] ** 2, rel=1e-12)


# ---------------------------------------------------------------------------------------
# Integration accuracy and the energy balance (docs/MODEL.md §3)
# ---------------------------------------------------------------------------------------


def test_dop853_and_radau_agree_on_s1_first_50ms():
    a = R.scene("S1", 0.05, 1e-4)
    b = R.scene("S1", 0.05, 1e-4, method="Radau")
    assert len(a.impact_t) >= 10
    assert np.max(np.abs(a.xi - b.xi)) <= 1e-6 * G
    np.testing.assert_allclose(a.impact_t, b.impact_t, rtol=0, atol=1e-9)
    assert np.array_equal(a.impact_flank, b.impact_flank)
    np.testing.assert_allclose(a.E_contact, b.E_contact, rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(a.E_lubricant, b.E_lubricant, rtol=1e-6, atol=1e-12)


def _potential(xi, p):
    """V(xi) = int F_k dxi, zero in the gap."""

    def fk(x):
        return R.contact_force([x], [0.0], p)[0]

    if xi < 0:
        return -quad(fk, xi, 0.0, points=[-p["epsilon"]] if -p["epsilon"] > xi else None, epsabs=0, epsrel=1e-12)[0]
    if xi > p["G"]:
        lim = p["G"] + p["epsilon"]
        return quad(fk, p["G"], xi, points=[lim] if lim < xi else None, epsabs=0, epsrel=1e-12)[0]
    return 0.0


def test_energy_balance_s1():
    """d/dt(1/2 I_L omega_L^2 + V) = -tau_M omega_M - s C_LM xi'^2 - C omega_L^2 (B = omega_S = 0).

    Checks the quadrature states E_contact, E_lubricant and the integration together."""
    p = R.params("S1")
    t_end = 0.02  # covers a full contact with the band crossings (impacts at 6.8, 10.3, 13.3 ms)
    t = np.linspace(0.0, t_end, 40001)
    r = R.simulate(p, t_end, t_eval=t)
    om_l, _, f = r.loose_gear()
    _, om_m, _ = R.main_shaft(t, p)
    power_in = -p["r_M"] * f * om_m  # -tau_M omega_M
    w_in = np.trapezoid(power_in, t)
    ke = 0.5 * p["I_L"] * om_l**2
    lhs = ke[-1] + _potential(r.xi[-1], p) - ke[0]
    rhs = w_in - r.E_contact[-1] - r.E_lubricant[-1]
    assert r.E_contact[-1] > 0 and r.E_lubricant[-1] > 0
    assert np.all(np.diff(r.E_contact) >= 0) and np.all(np.diff(r.E_lubricant) >= 0)
    assert abs(lhs - rhs) < 1e-6 * (abs(w_in) + r.E_contact[-1] + r.E_lubricant[-1])


def test_no_band_variant_runs():
    """eps = 0 (no band): three regions; still rattles, impacts counted on both flanks."""
    r = R.simulate(R.params("S1", epsilon=0.0), 0.05)
    assert set(r.impact_flank.tolist()) == {R.FPLUS, R.FMINUS}


# ---------------------------------------------------------------------------------------
# The table of docs/MODEL.md §5
# ---------------------------------------------------------------------------------------


def _window_runs(r, t0=0.2, t1=1.0):
    sel = (r.impact_t >= t0) & (r.impact_t < t1)
    return [n for _, n in R.runs(r.impact_flank[sel])]


def _scene_rates(scene, rate_plus, rate_minus, **tolerance):
    """The scene's 1 s run, its impact rates over [0.2, 1] s checked."""
    r = R.scene(scene, 1.0)
    rt = R.rates(r.impact_t, r.impact_flank, 0.2, 1.0)
    assert rt[R.FPLUS] == pytest.approx(rate_plus, **tolerance)
    assert rt[R.FMINUS] == pytest.approx(rate_minus, **tolerance)
    return r


def _steady_runs(r, n):
    """Per flank, every run after the first has n impacts, and so has every run of the
    window [0.2, 1] s; returns the run lengths per flank."""
    per = R.runs_per_flank(r.impact_flank)
    for fl in (R.FPLUS, R.FMINUS):
        assert set(per[fl][1:]) == {n}, per[fl]
    assert set(_window_runs(r)) == {n}
    return per


def test_s1_rates_and_runs():
    r = _scene_rates("S1", 150, 150, abs=2)
    # "always 5 (the very first run: 4)": per flank, the first run has 4 impacts, all the
    # others 5. (In time order the runs are 4 (F+), 4 (F-), 5, 5, ...)
    per = _steady_runs(r, 5)
    assert per[R.FPLUS][0] == per[R.FMINUS][0] == 4
    assert r.impact_flank[0] == R.FPLUS


def test_s3_rates_and_runs():
    r = _scene_rates("S3", 90, 90, abs=2)
    # "always 3". Found here: after a start transient (a first impact on F- at 2.2 ms,
    # thrown there by the lubricant drag since omega_L(0) = r_M omega_M(0) / r_L != 0,
    # then 5 on F+), every run has 3 impacts.
    _steady_runs(r, 3)
    # more and stronger impacts than S1? stronger: yes; fewer per second (90 vs 150)
    r1 = R.scene("S1", 1.0)
    sel3, sel1 = r.impact_t >= 0.2, r1.impact_t >= 0.2
    assert r.impact_speed[sel3].max() > r1.impact_speed[sel1].max()


def test_s2_rates_and_runs():
    # docs/MODEL.md: ~125 / ~126 (chaotic: a few % depending on the last digits)
    r = _scene_rates("S2", 125, 126, rel=0.05)
    runs = np.array(_window_runs(r))
    assert set(runs.tolist()) <= {2, 3}
    assert 0.03 <= np.mean(runs == 3) <= 0.2  # "2, a 3 about one run in ten"


def test_no_impacts_below_threshold():
    """docs/MODEL.md §5: the model rattles from about 3.3 rad/s^2 RMS at 30 Hz."""
    quiet = R.simulate(R.params("S1", A_rms=2.0), 0.3)
    assert len(quiet.impact_t) == 0
    assert 0 < quiet.xi_min and quiet.xi_max < G
    loud = R.simulate(R.params("S1", A_rms=6.0), 0.3)
    assert len(loud.impact_t) > 0
