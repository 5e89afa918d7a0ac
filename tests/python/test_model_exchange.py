"""Model Exchange: the same GearRattle.fmu integrated by fmpy's CVode (BDF with event
handling) against the independent reference, against its own co-simulation, and refusing
misuse through the Model Exchange calls."""

import ctypes

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.fmi2 import FMU2Model, fmi2Error, fmi2EventInfo, fmi2OK

import reference as R

G = R.DEFAULTS["G"]


def me_run(unzipdir, model_description, t_end, dt=1e-4, rtol=1e-9, **start):
    return simulate_fmu(unzipdir, model_description=model_description, fmi_type="ModelExchange",
                        solver="CVode", stop_time=t_end, output_interval=dt, relative_tolerance=rtol,
                        start_values=start, output=["xi", "impacts_Fplus", "impacts_Fminus", "impact_speed"])


def at_times(res, t):
    """The rows of a Model Exchange result at the output times t (event rows skipped)."""
    return res[np.searchsorted(res["time"], np.asarray(t) + 1e-12, side="right") - 1]


def impacts(res):
    """(time, flank) of each impact from the counters (event rows included)."""
    t, p, m = res["time"], res["impacts_Fplus"], res["impacts_Fminus"]
    rise = np.nonzero((np.diff(p) > 0) | (np.diff(m) > 0))[0] + 1
    return t[rise], np.where(np.diff(p)[rise - 1] > 0, R.FPLUS, R.FMINUS)


@pytest.mark.parametrize("scene,t_end,window", [("S1", 1.0, 1.0), ("S3", 1.0, 1.0), ("S2", 0.2, 0.07)])
def test_scenes_against_the_reference(unzipdir, model_description, scene, t_end, window):
    """At rtol 1e-9: ξ within 1e-4 G over the predictable window, the impacts per flank equal
    (S1 and S3 over the whole second, S2 over its predictable 70 ms), each at the reference's
    time."""
    sc = R.SCENES[scene]
    res = me_run(unzipdir, model_description, t_end, excitation=1, f_exc=sc["f_exc"], A_rms=sc["A_rms"])
    ref = R.scene(scene, t_end, 1e-4)
    w = ref.t <= window
    err = np.max(np.abs(at_times(res, ref.t[w])["xi"] - ref.xi[w]))
    assert err <= 1e-4 * G, f"max |dxi| = {err / G:.2e} G"
    t_imp, flank = impacts(res)
    sel, rsel = t_imp <= window, ref.impact_t <= window
    assert np.array_equal(flank[sel], ref.impact_flank[rsel])
    assert np.max(np.abs(t_imp[sel] - ref.impact_t[rsel])) < 1e-6


def test_model_exchange_and_co_simulation_agree(unzipdir, model_description, fmu_run):
    """S1 over 0.5 s: the two interfaces give the same impacts, onset for onset."""
    me = me_run(unzipdir, model_description, 0.5, excitation=1)
    cs = fmu_run("sine", "S1", 0.5, 1e-5)
    t_me, f_me = impacts(me)
    t_cs, f_cs = impacts(cs)
    assert np.array_equal(f_me, f_cs)
    assert np.max(np.abs(t_me - t_cs)) <= 1e-5  # the co-simulation's output interval


def test_inputs_mode_by_input_signals(unzipdir, model_description):
    """The kinematic mode driven by fmpy input signals (θ_M, ω_M of S1's sine every 10 µs):
    the impacts of the reference over 0.2 s."""
    from conftest import main_shaft_input
    inp = main_shaft_input("S1", 0.2, 1e-5, ("theta_M", "omega_M"))
    res = simulate_fmu(unzipdir, model_description=model_description, fmi_type="ModelExchange",
                       solver="CVode", stop_time=0.2, output_interval=1e-5, relative_tolerance=1e-9,
                       input=inp, output=["impacts_Fplus", "impacts_Fminus"])
    ref = R.scene("S1", 0.2)
    assert (res["impacts_Fplus"][-1], res["impacts_Fminus"][-1]) == tuple(int(n[0]) for n in ref.impact_counts([0.2]))


def test_torque_mode(unzipdir, model_description, fmu_run):
    """The torque mode: the shaft's own states, driven by a constant τ_in from rest, against
    the co-simulation of the same (the gear is thrown onto F+ and stays)."""
    start = dict(excitation=2, tau_in=0.5)
    me = simulate_fmu(unzipdir, model_description=model_description, fmi_type="ModelExchange", solver="CVode",
                      stop_time=0.05, output_interval=1e-4, relative_tolerance=1e-9, start_values=start,
                      output=["xi", "omega_M_out", "impacts_Fplus", "impacts_Fminus"])
    cs = fmu_run("sine", "S1", 0.05, 1e-4, **start, tol=1e-9)
    assert me["impacts_Fplus"][-1] == cs["impacts_Fplus"][-1] >= 1
    assert me["omega_M_out"][-1] == pytest.approx(cs["omega_M_out"][-1], rel=1e-6)
    assert at_times(me, [0.05])["xi"][0] == pytest.approx(cs["xi"][-1], abs=1e-4 * G)


@pytest.mark.parametrize("overrides", [{"I_L": 1e-8}, {"C_LM": 1000 * R.DEFAULTS["C_LM"]}],
                         ids=["I_L 1e-8", "C_LM x1000"])
def test_stiff_cases_run_through_cvode(unzipdir, model_description, overrides):
    """The stiff cases of the stress suite: CVode's BDF integrates them without failure."""
    res = me_run(unzipdir, model_description, 0.05, excitation=1, **overrides)
    assert res["time"][-1] == pytest.approx(0.05)
    assert np.all(np.isfinite(res["xi"]))


@pytest.fixture
def model(unzipdir, model_description):
    """A Model Exchange instance, instantiated."""
    fmu = FMU2Model(guid=model_description.guid, unzipDirectory=unzipdir,
                    modelIdentifier=model_description.modelExchange.modelIdentifier, instanceName="me")
    fmu.instantiate()
    yield fmu
    fmu.freeInstance()


def call(fmu, name, *args):
    """The raw status of an fmi2 function (fmpy's wrappers raise on an error)."""
    return getattr(fmu.dll, name)(ctypes.c_void_p(fmu.component), *args)


def test_misuse_is_refused(model):
    """Derivatives before initialisation, states of the wrong length, NaN states, event mode
    out of order: each refused with fmi2Error, the instance usable afterwards."""
    nx = 10
    x = (ctypes.c_double * nx)()
    assert call(model, "fmi2GetDerivatives", x, nx) == fmi2Error  # instantiated
    model.setupExperiment(startTime=0.0)
    model.enterInitializationMode()
    model.setInteger([model_vr(model, "excitation")], [1])
    model.exitInitializationMode()
    assert call(model, "fmi2GetDerivatives", x, nx - 1) == fmi2Error  # wrong length
    assert call(model, "fmi2EnterContinuousTimeMode") == fmi2OK
    assert call(model, "fmi2NewDiscreteStates", ctypes.byref(fmi2EventInfo())) == fmi2Error  # not in event mode
    assert call(model, "fmi2GetContinuousStates", x, nx) == fmi2OK
    good = list(x)
    x[0] = float("nan")
    assert call(model, "fmi2SetContinuousStates", x, nx) == fmi2Error
    assert call(model, "fmi2SetContinuousStates", x, nx + 1) == fmi2Error
    assert call(model, "fmi2DoStep", ctypes.c_double(0.0), ctypes.c_double(1e-3), 1) == fmi2Error
    # Still usable: the states as they were, derivatives at them.
    out = (ctypes.c_double * nx)()
    assert call(model, "fmi2GetContinuousStates", out, nx) == fmi2OK
    assert list(out) == good
    assert call(model, "fmi2GetDerivatives", out, nx) == fmi2OK
    assert all(np.isfinite(out))


def model_vr(fmu, name):
    from fmpy import read_model_description
    md = read_model_description(fmu.unzipDirectory)
    return next(v.valueReference for v in md.modelVariables if v.name == name)
