"""The `solver` parameter and the `solver_method` output: each method against the
independent reference (gearrattle/reference.py), and the automatic hand-over to Radau IIA
on a stiff gear pair, which must give the explicit method's answer for far fewer right-hand
sides (counted by the FMU: deterministic, not a timing)."""

import numpy as np
import pytest

from gearrattle import reference as R

AUTO, EXPLICIT, IMPLICIT = 0, 1, 2
DOPRI5, RADAU = 1, 2


@pytest.mark.parametrize("solver,method", [(AUTO, DOPRI5), (EXPLICIT, DOPRI5), (IMPLICIT, RADAU)], ids=["auto", "explicit", "implicit"])
def test_each_method_matches_the_reference_on_s1(fmu_run, solver, method):
    """S1 over 50 ms (7 impacts) at rtol 1e-6: S1 is not stiff, so auto stays explicit."""
    dt, t_end = 1e-4, 0.05
    res = fmu_run("sine", "S1", t_end, dt, solver=solver)
    ref = R.scene("S1", t_end, dt)
    G = R.DEFAULTS["G"]
    err = np.max(np.abs(res["xi"] - ref.xi))
    assert err <= 1e-4 * G, f"max |dxi| = {err / G:.2e} G"
    assert set(res["solver_method"].tolist()) == {method}
    implicit = res["solver_implicit_steps"][-1]
    assert (implicit > 0) == (method == RADAU), implicit
    assert res["impacts_Fplus"][-1] + res["impacts_Fminus"][-1] == sum(ref.impact_counts(t_end))


def test_auto_hands_over_on_a_tiny_idler(fmu_run):
    """I_L = 1e-8 kg m² (drag rate C/I_L = 2.5e6 1/s: stiff everywhere): auto switches to
    Radau IIA and agrees with DOPRI5 alone and with the reference (Radau, rtol 1e-10), for a
    fraction of DOPRI5's right-hand sides."""
    dt, t_end, tol = 1e-4, 0.012, 1e-6
    auto = fmu_run("sine", "S1", t_end, dt, tol=tol, solver=AUTO, I_L=1e-8)
    explicit = fmu_run("sine", "S1", t_end, dt, tol=tol, solver=EXPLICIT, I_L=1e-8)
    p = R.params("S1", I_L=1e-8)
    ref = R.simulate(p, t_end, t_eval=auto["time"], method="Radau", rtol=1e-10)
    G = p["G"]
    for res in (auto, explicit):
        err = np.max(np.abs(res["xi"] - ref.xi))
        assert err <= 10 * tol * G, f"max |dxi| = {err / (tol * G):.1f} rtol G"
    assert RADAU in set(auto["solver_method"].tolist())
    assert set(explicit["solver_method"].tolist()) == {DOPRI5}
    rhs_auto, rhs_explicit = auto["solver_rhs"][-1], explicit["solver_rhs"][-1]
    print(f"I_L 1e-8, 12 ms: auto {rhs_auto:.0f} rhs ({auto['solver_implicit_steps'][-1]:.0f} implicit steps), DOPRI5 alone {rhs_explicit:.0f} rhs")
    assert rhs_auto * 5 < rhs_explicit


def test_sine_cost_does_not_depend_on_the_communication_step(fmu_run):
    """In sine mode communication points are served from the dense output of natural
    steps, so 10 µs communication steps cost the right-hand sides of 10 ms ones (counted by the
    FMU), and their values agree with the reference at every point."""
    t_end = 0.05
    ref_fine = R.scene("S1", t_end, 1e-5)
    fine = fmu_run("sine", "S1", t_end, 1e-5)
    coarse = fmu_run("sine", "S1", t_end, 1e-2)
    G = R.DEFAULTS["G"]
    assert np.max(np.abs(fine["xi"] - ref_fine.xi)) <= 1e-4 * G
    rhs_fine, rhs_coarse = fine["solver_rhs"][-1], coarse["solver_rhs"][-1]
    print(f"S1 50 ms: {rhs_fine:.0f} rhs at 10 µs, {rhs_coarse:.0f} at 10 ms")
    assert rhs_fine <= 1.1 * rhs_coarse
