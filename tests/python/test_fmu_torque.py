"""The FMU in torque mode (excitation = 2): the main shaft is an inertia I_M driven by
the master's torque tau_in and pushed back by the contact, I_M omega_M' = tau_in + r_M F; the
FMU outputs the shaft's motion (theta_M_out, omega_M_out, alpha_M_out) for a master that
couples by torque. Checked against reference.simulate_torque (scipy, from the equations in
reference.py), the master's torque given exactly as the FMU is told it: held over each
communication step, or ramped with its first derivative."""

import math

import numpy as np
import pytest
from fmpy.fmi2 import FMU2Slave, fmi2OK

from gearrattle import reference as R
from test_fmu_misuse import REFUSED, Slave

P = R.params()
G, R_M, I_M = P["G"], P["r_M"], P["I_M"]
DT = 2e-4  # communication step
T_END = 0.05
# An S1-like torque: I_M times the bench's acceleration amplitude, at 30 Hz.
W = 2 * math.pi * 30.0
AMP = I_M * math.sqrt(2) * 300.0
OMEGA0 = -AMP / I_M / W  # zero-mean shaft speed, as the bench's -A/w cos(wt)
# Error weights of the FMU's tolerance (1e-6): G on xi, G * 3600 rad/s on xi_dot (the
# weights test_fmu_sine uses), and the same on the pitch line for the shaft: / r_M.
XI_TOL = 1e-4 * G
OMEGA_TOL = 1e-4 * G * 3600.0 / R_M


def slave(unzipdir, md, name):
    s = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
    s.instantiate()
    return s


def run(unzipdir, md, vrs, tau, rate=None, omega0=0.0, theta0=0.0, n=int(round(T_END / DT)), h=DT, reals=None):
    """Torque mode stepped by hand: tau(t) (and its derivative rate(t), if given) set at each
    communication point; outputs read after each step, before the next inputs. reals: other
    parameters by name."""
    names = ["xi", "xi_dot", "theta_M_out", "omega_M_out", "alpha_M_out", "theta_L", "F_contact", "tau_M"]
    s = slave(unzipdir, md, "torque")
    try:
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.setInteger([vrs["excitation"]], [2])
        s.setReal([vrs["theta_M"], vrs["omega_M"], vrs["tau_in"]], [theta0, omega0, tau(0.0)])
        for name, value in (reals or {}).items():
            s.setReal([vrs[name]], [value])
        if rate is not None:
            s.setRealInputDerivatives([vrs["tau_in"]], [1], [rate(0.0)])
        s.exitInitializationMode()
        rows = [s.getReal([vrs[k] for k in names])]
        for k in range(n):
            t = k * h
            s.setReal([vrs["tau_in"]], [tau(t)])
            if rate is not None:
                s.setRealInputDerivatives([vrs["tau_in"]], [1], [rate(t)])
            s.doStep(t, h)
            rows.append(s.getReal([vrs[k] for k in names]))
        counts = s.getInteger([vrs["impacts_Fplus"], vrs["impacts_Fminus"]])
        s.terminate()
    finally:
        s.freeInstance()
    out = {k: np.array(v) for k, v in zip(names, zip(*rows))}
    out["time"] = np.arange(n + 1) * h
    out["impacts"] = counts
    return out


def sine_torque(t):
    return AMP * math.sin(W * t)


def sine_rate(t):
    return AMP * W * math.cos(W * t)


def compare(res, ref):
    dxi = np.max(np.abs(res["xi"] - ref.xi))
    dom = np.max(np.abs(res["omega_M_out"] - ref.omega_M))
    return dxi, dom


def test_constant_torque_matches_reference(unzipdir, model_description, vrs):
    """0.5 N m on a shaft at rest: it accelerates at ~61 rad/s^2, the loose gear lags, hits
    flank F+ and bounces on it while the pair speeds up together."""
    tau = 0.5
    res = run(unzipdir, model_description, vrs, lambda t: tau)
    ref = R.simulate_torque(P, T_END, tau=lambda t: tau, t_eval=res["time"])
    dxi, dom = compare(res, ref)
    assert dxi <= XI_TOL, f"max |dxi| = {dxi / G:.2e} G"
    assert dom <= OMEGA_TOL, f"max |domega_M| = {dom:.2e} rad/s"
    # it does something: contact on F+ and a shaft speed that rose
    assert ref.impact_flank.size >= 1 and np.all(ref.impact_flank == R.FPLUS)
    assert res["omega_M_out"][-1] > 2.0
    assert list(res["impacts"]) == [int(np.sum(ref.impact_flank == R.FPLUS)), int(np.sum(ref.impact_flank == R.FMINUS))]
    # kinematics and the shaft's equation, read from the outputs
    np.testing.assert_allclose(P["r_L"] * res["theta_L"] - R_M * res["theta_M_out"], res["xi"], rtol=0, atol=1e-6 * G)
    np.testing.assert_allclose(res["tau_M"], R_M * res["F_contact"], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(res["alpha_M_out"], ref.alpha_M, rtol=0, atol=1e-3 * abs(tau) / I_M + 1e-6)


@pytest.mark.parametrize("with_rate", [False, True], ids=["held", "ramped"])
def test_sine_torque_matches_reference(unzipdir, model_description, vrs, with_rate):
    """An S1-like torque sampled at each 0.2 ms step, held or ramped with its derivative
    (fmi2SetRealInputDerivatives order 1): the FMU against the reference told the same
    piecewise torque: only the integrators differ."""
    rate = sine_rate if with_rate else None
    res = run(unzipdir, model_description, vrs, sine_torque, rate, omega0=OMEGA0)
    t_k = res["time"][:-1]
    held = R.held_torque(t_k, [sine_torque(t) for t in t_k], [rate(t) for t in t_k] if rate else None)
    ref = R.simulate_torque(P, T_END, held=held, omega_M0=OMEGA0, t_eval=res["time"])
    dxi, dom = compare(res, ref)
    assert ref.impact_t.size >= 5, "it rattles"
    assert dxi <= XI_TOL, f"max |dxi| = {dxi / G:.2e} G"
    assert dom <= OMEGA_TOL, f"max |domega_M| = {dom:.2e} rad/s"
    assert res["impacts"][0] + res["impacts"][1] == ref.impact_t.size


def test_ramp_is_closer_to_the_smooth_torque_than_the_hold(unzipdir, model_description, vrs):
    """Against the smooth sine torque itself: holding tau_in over a step lags it by half a step
    (an error of order AMP W h / 2 in torque), the ramp only by its curvature (AMP W^2 h^2 / 2):
    the input derivative must make the run closer to the smooth drive, by a wide margin."""
    smooth = R.simulate_torque(P, T_END, tau=sine_torque, omega_M0=OMEGA0, t_eval=np.arange(int(round(T_END / DT)) + 1) * DT)
    held = run(unzipdir, model_description, vrs, sine_torque, None, omega0=OMEGA0)
    ramped = run(unzipdir, model_description, vrs, sine_torque, sine_rate, omega0=OMEGA0)
    _, dom_held = compare(held, smooth)
    dxi_ramp, dom_ramp = compare(ramped, smooth)
    assert dom_ramp < 0.1 * dom_held, (dom_ramp, dom_held)
    # the ramp misses the torque's curvature: AMP W^2 h^2 / 6 sin(W t) on average over a
    # step, which integrates to at most AMP W h^2 / 3 / I_M on omega_M (bound with a margin
    # of 1.5; the contact's reaction is the same in both runs to first order)
    assert dom_ramp <= AMP * W * DT**2 / 2 / I_M + OMEGA_TOL, dom_ramp
    assert dxi_ramp <= 1e-2 * G, f"max |dxi| = {dxi_ramp / G:.2e} G"


def test_heavy_shaft_is_the_bench(unzipdir, model_description, vrs):
    """A shaft so heavy that the contact cannot move it, driven by I_M a_M(t) (the bench's
    acceleration) from the bench's initial speed, moves as the bench's sine: torque mode then
    reproduces scene S1 of the kinematic reference (reference.simulate, docs/MODEL.md §5), which
    shares nothing with the torque mode but the contact law. The reference's own torque mode
    agrees with it within 2e-6 G; the FMU within its coupling error: the ramp's curvature,
    A w^2 h^2 / 2 on a_M, is the same as that of the inputs mode's extrapolation, which
    test_fmu_inputs bounds by 1e-2 G over the same 50 ms."""
    heavy = 1e3
    a = math.sqrt(2) * 300.0
    p = R.params("S1", I_M=heavy)
    res = run(
        unzipdir,
        model_description,
        vrs,
        lambda t: heavy * a * math.sin(W * t),
        lambda t: heavy * a * W * math.cos(W * t),
        omega0=-a / W,
        reals={"I_M": heavy},
    )
    bench = R.scene("S1", T_END, DT)
    own = R.simulate_torque(p, T_END, tau=lambda t: heavy * a * math.sin(W * t), omega_M0=-a / W, t_eval=res["time"])
    assert np.max(np.abs(own.xi - bench.xi)) <= 2e-6 * G
    assert own.impact_t.size == bench.impact_t.size >= 10
    err = np.max(np.abs(res["xi"] - bench.xi))
    assert err <= 1e-2 * G, f"max |dxi| = {err / G:.2e} G"
    # the shaft: the ramp misses the torque's curvature, -a_M'' (t - t_k)^2 / 2 on a_M, which
    # is a W^2 h^2 / 6 sin(W t) on average over a step; integrated, a W h^2 / 6 (1 - cos W t)
    # on omega_M (at most a W h^2 / 3) and a W h^2 t / 6 on theta_M (a drift): bounds with
    # a margin of 1.5
    th, om, _ = R.main_shaft(res["time"], R.params("S1"))
    np.testing.assert_allclose(res["omega_M_out"], om, rtol=0, atol=a * W * DT**2 / 2)
    np.testing.assert_allclose(res["theta_M_out"], th, rtol=0, atol=a * W * DT**2 * T_END / 4)


def test_initial_shaft_and_direct_feedthrough(unzipdir, model_description, vrs):
    """theta_M, omega_M set in initialisation are the shaft's start; a new tau_in moves
    alpha_M_out at once by dtau / I_M (the declared dependency and the directional
    derivative), and nothing else: the state does not jump."""
    s = slave(unzipdir, model_description, "feedthrough")
    try:
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.setInteger([vrs["excitation"]], [2])
        s.setReal([vrs["theta_M"], vrs["omega_M"], vrs["tau_in"]], [1.5, 80.0, 0.2])
        s.exitInitializationMode()
        names = ["theta_M_out", "omega_M_out", "alpha_M_out", "xi", "xi_dot", "omega_L", "tau_M"]

        def get():
            return dict(zip(names, s.getReal([vrs[n] for n in names])))

        s0 = get()
        assert s0["theta_M_out"] == 1.5 and s0["omega_M_out"] == 80.0
        assert s0["xi"] == pytest.approx(0.5 * G, abs=1e-18)
        # the loose gear spins with the shaft: omega_L = r_M omega_M / r_L at xi_dot = 0
        assert s0["omega_L"] == pytest.approx(R_M * 80.0 / P["r_L"], rel=1e-12)
        assert s0["alpha_M_out"] == pytest.approx(0.2 / I_M, rel=1e-12)
        for k in range(5):
            s.doStep(k * 1e-3, 1e-3)
        s1 = get()
        d_tau = 0.7
        s.setReal([vrs["tau_in"]], [0.2 + d_tau])
        s2 = get()
        for n in ("theta_M_out", "omega_M_out", "xi", "xi_dot", "omega_L", "tau_M"):
            assert s2[n] == s1[n], n
        assert s2["alpha_M_out"] - s1["alpha_M_out"] == pytest.approx(d_tau / I_M, rel=1e-9)
        dd = s.getDirectionalDerivative([vrs["alpha_M_out"], vrs["xi"], vrs["tau_M"]], [vrs["tau_in"]], [1.0])
        assert dd[0] == pytest.approx(1.0 / I_M, rel=1e-12)
        assert dd[1] == 0.0 and dd[2] == 0.0
        # theta_M, omega_M are start values only in torque mode: setting them later is ignored
        s.setReal([vrs["omega_M"]], [0.0])
        assert get()["omega_M_out"] == s2["omega_M_out"]
        s.terminate()
    finally:
        s.freeInstance()


@pytest.mark.parametrize("value", [0.0, -0.008, math.nan, math.inf])
def test_invalid_inertia_refused(unzipdir, model_description, value):
    s = Slave(unzipdir, model_description, "inertia")
    try:
        assert s.setup() == fmi2OK
        assert s.enter_init() == fmi2OK
        assert s.set_integer([s.vrs["excitation"]], [2]) == fmi2OK
        m = s.mark()
        st = s.set_real([s.vrs["I_M"]], [value])
        if st == fmi2OK:
            assert s.exit_init() in REFUSED
        else:
            assert st in REFUSED
        s.assert_logged(m, "I_M")
        # corrected, the instance initialises and steps
        assert s.set_real([s.vrs["I_M"]], [0.008]) == fmi2OK
        assert s.exit_init() == fmi2OK
        assert s.do_step(1e-3) == fmi2OK
    finally:
        s.free()


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_non_finite_torque_refused(unzipdir, model_description, bad):
    s = Slave(unzipdir, model_description, "badtorque")
    try:
        s.init(integers={"excitation": 2}, reals={"tau_in": 0.5})
        assert s.do_step(1e-3) == fmi2OK
        names = ("alpha_M_out", "omega_M_out", "xi", "xi_dot")
        before = {n: s.real(n) for n in names}
        m = s.mark()
        assert s.set_real([s.vrs["tau_in"]], [bad]) in REFUSED
        s.assert_logged(m, "tau_in")
        assert {n: s.real(n) for n in names} == before
        # a non-finite derivative is refused too, and a derivative of order 2 is not one
        for order, value in ((1, bad), (2, 1.0)):
            m = s.mark()
            st = s._status(s.fmu.setRealInputDerivatives, [s.vrs["tau_in"]], [order], [value])
            assert st in REFUSED
            s.assert_logged(m)
        assert s.do_step(1e-3) == fmi2OK
        for n in names:
            assert math.isfinite(s.real(n)), n
    finally:
        s.free()
