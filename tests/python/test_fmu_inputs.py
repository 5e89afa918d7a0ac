"""The FMU in inputs mode (excitation = 0, the default): the master drives the main shaft
(theta_M, omega_M, alpha_M) at each communication point and the FMU extrapolates it over
the step (docs/MODEL.md §5, drivetrain coupling)."""

import numpy as np
import pytest

from gearrattle import reference as R

P = R.params()
G = P["G"]
DT = 1e-4  # communication step = output interval = input sampling


@pytest.mark.parametrize("scene", ["S1", "S2", "S3"])
def test_inputs_mode_first_50ms_matches_reference(fmu_run, scene):
    p = R.params(scene)
    res = fmu_run("inputs", scene, 0.05, DT)
    ref = R.scene(scene, 0.05, DT)
    t = res["time"]
    assert t.size == ref.t.size
    np.testing.assert_allclose(t, ref.t, rtol=0, atol=1e-12)
    err = np.abs(res["xi"] - ref.xi)
    k = int(np.argmax(err))
    assert err[k] <= 1e-2 * G, f"max |dxi| = {err[k] / G:.3e} G at t = {t[k]:.4f} s"
    # the main-shaft motion the FMU used: the inputs, extrapolated over the step with
    # theta, omega, alpha (the remainder is of order jerk h^3 / 6 ~ 1e-8 rad here)
    th, om, al = R.main_shaft(t, p)
    np.testing.assert_allclose(res["theta_M_out"], th, rtol=0, atol=1e-7)
    np.testing.assert_allclose(res["omega_M_out"], om, rtol=0, atol=1e-3)
    # kinematics hold in inputs mode too
    np.testing.assert_allclose(
        p["r_L"] * res["theta_L"] - p["r_M"] * res["theta_M_out"], res["xi"], rtol=0, atol=1e-6 * G
    )
    # the same impacts as the reference, give or take a grazing one (S1 has a touch of
    # F- at 34.7 ms that dips only 0.0055 G below G: within the 1e-2 G allowed here)
    n_ref = ref.impact_counts(t)
    for name, nr in zip(("impacts_Fplus", "impacts_Fminus"), n_ref):
        assert abs(int(res[name][-1]) - int(nr[-1])) <= 1, (name, res[name][-1], nr[-1])


def test_inputs_mode_omega_only(fmu_run):
    """A master that sets only omega_M (theta_M and alpha_M unconnected, left at their start
    values 0): the FMU integrates the shaft angle itself. Loose check: the gear still
    rattles in its backlash like the reference, no drift of xi."""
    t_end = 0.2
    p = R.params("S1")
    res = fmu_run("inputs", "S1", t_end, DT, fields=("omega_M",))
    ref = R.scene("S1", 1.0)
    t = res["time"]
    xi = res["xi"]
    assert np.all(np.isfinite(xi))
    # bounded near the band: penetrations of the order of the reference's (-0.31 G, +0.27 G)
    margin = 0.5 * G
    assert xi.min() >= ref.xi_min - margin and xi.max() <= ref.xi_max + margin, (xi.min() / G, xi.max() / G)
    # the shaft angle follows the integral of omega_M (the analytic theta_M, zero at t = 0),
    # to within a fraction of the backlash on the pitch line
    th, _, _ = R.main_shaft(t, p)
    dth = np.max(np.abs(res["theta_M_out"] - th))
    assert p["r_M"] * dth <= 0.5 * G, f"theta_M_out off by {dth:.3e} rad"
    # it rattles on both flanks, at roughly the reference's rate
    n_plus, n_minus = res["impacts_Fplus"][-1], res["impacts_Fminus"][-1]
    nr_plus = np.count_nonzero((ref.impact_t <= t_end) & (ref.impact_flank == R.FPLUS))
    nr_minus = np.count_nonzero((ref.impact_t <= t_end) & (ref.impact_flank == R.FMINUS))
    assert 0.5 * nr_plus <= n_plus <= 1.5 * nr_plus, (n_plus, nr_plus)
    assert 0.5 * nr_minus <= n_minus <= 1.5 * nr_minus, (n_minus, nr_minus)


def test_direct_feedthrough(slave, vrs):
    """Setting theta_M (omega_M) moves xi (xi_dot) at once by -r_M delta, the loose gear
    itself (theta_L, omega_L) unchanged: xi = r_L theta_L - r_M theta_M."""
    r_M = P["r_M"]
    fmu = slave("feedthrough")
    names = ["xi", "xi_dot", "theta_L", "omega_L", "theta_M_out", "omega_M_out"]

    def get():
        return dict(zip(names, fmu.getReal([vrs[n] for n in names])))

    s0 = get()
    assert s0["xi"] == pytest.approx(0.5 * G, abs=1e-18)
    assert s0["xi_dot"] == 0.0
    # a few steps at rest: nothing moves (B = 0, omega_S = 0, shaft at rest)
    t = 0.0
    for _ in range(5):
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=1e-3)
        t += 1e-3
    s1 = get()
    assert s1["xi"] == pytest.approx(0.5 * G, abs=1e-15)
    # theta_M -> xi, at once
    d_theta = 1e-4
    fmu.setReal([vrs["theta_M"]], [d_theta])
    s2 = get()
    assert s2["theta_M_out"] == pytest.approx(d_theta, rel=1e-12)
    assert s2["xi"] - s1["xi"] == pytest.approx(-r_M * d_theta, rel=1e-9)
    assert s2["theta_L"] == pytest.approx(s1["theta_L"], abs=1e-15)
    # omega_M -> xi_dot, at once
    d_omega = 0.5
    fmu.setReal([vrs["omega_M"]], [d_omega])
    s3 = get()
    assert s3["omega_M_out"] == pytest.approx(d_omega, rel=1e-12)
    assert s3["xi_dot"] - s2["xi_dot"] == pytest.approx(-r_M * d_omega, rel=1e-9)
    assert s3["omega_L"] == pytest.approx(s2["omega_L"], abs=1e-15)
    assert s3["xi"] == pytest.approx(s2["xi"], abs=1e-18)
    # one step with constant omega_M (alpha_M = 0): the shaft angle is extrapolated
    h = 1e-4
    fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
    s4 = get()
    assert s4["theta_M_out"] == pytest.approx(d_theta + d_omega * h, rel=1e-9)
    # in the gap over this short step the loose gear only feels the drag: theta_L ~ same
    assert abs(s4["theta_L"] - s3["theta_L"]) < 1e-9


@pytest.mark.parametrize("scene", ["S1", "S2", "S3"])
def test_inputs_mode_drivetrain_step_1ms(fmu_run, scene):
    """A drivetrain master's usual 1 ms communication step (theta_M, omega_M, alpha_M given):
    the run completes and stays close to the reference (the quadratic extrapolation of the
    shaft leaves r_M jerk h^3 / 6 ~ 0.015 G per step)."""
    t_end, h = 0.3, 1e-3
    res = fmu_run("inputs", scene, t_end, h)
    ref = R.scene(scene, 1.0)
    n50 = int(round(0.05 / h))
    r50 = R.simulate(R.params(scene), 0.05, t_eval=res["time"][: n50 + 1])
    err = np.max(np.abs(res["xi"][: n50 + 1] - r50.xi))
    assert err <= 0.25 * G, f"max |dxi| over 50 ms = {err / G:.3f} G"
    n_ref = ref.impact_counts([t_end])
    for name, nr in zip(("impacts_Fplus", "impacts_Fminus"), n_ref):
        assert res[name][-1] == pytest.approx(int(nr[0]), rel=0.15), (name, res[name][-1], nr[0])


def test_inputs_mode_contact_edge_crossing_one_step(slave, vrs):
    """One 1 ms step from a contact on F- (xi = G + 4.1 um, xi_dot = -5.6 mm/s) with the
    shaft decelerating (S3's inputs at t = 0.03 s): xi crosses G + eps downwards at ~0.66 ms
    (|xi_dot| ~ 1.3 mm/s), turns inside the band and goes back into full contact."""
    w, amp, t0, h = 2 * np.pi * 30.0, np.sqrt(2) * 500.0, 0.03, 1e-3
    th, om, al = -amp / w**2 * np.sin(w * t0), -amp / w * np.cos(w * t0), amp * np.sin(w * t0)
    xi0, xd0 = 2.9106500619317545e-05, -0.005591932535582747
    p = R.params(gap_start=xi0 / G, xi_dot_start=xd0)
    ref = R.simulate(p, t0 + h, shaft=lambda t: (om + al * (t - t0), al), t_start=t0)
    fmu = slave("edge", start_time=t0, tolerance=1e-6, gap_start=xi0 / G, xi_dot_start=xd0,
                theta_M=th, omega_M=om, alpha_M=al)
    fmu.doStep(currentCommunicationPoint=t0, communicationStepSize=h)
    xi = fmu.getReal([vrs["xi"]])[0]
    # the FMU's xi at the end includes -r_M (theta_M extrapolated - reference's theta_M);
    # the reference integrates the same extrapolated shaft, so they agree closely
    assert xi == pytest.approx(ref.final_y[0], abs=1e-4 * G)
