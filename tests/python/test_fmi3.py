"""The FMI 3.0 FMU (target/fmu/fmi3/GearRattle.fmu, fmi3-shell's exports of the same library)
against the FMI 2.0 one: the same trajectories to the bit in co-simulation, within the
tolerance in Model Exchange; FMPy's validation and the FMI 3.0 schema; the low-level API
(FMU state, serialization, directional and adjoint derivatives, event indicators as
variables, early return at each impact against the reference's instants, Co-Simulation's
event mode); FMI 3.0's state machine refusing what is not offered, with a log line."""

import ctypes
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi3 import FMU3Model, FMU3Slave
from support.early_return import step_to_impacts
from support.fmu import BUILD_FMU3, FMU3_PATH, FMU_PATH, OUTPUTS, main_shaft_input, session_fixtures

from gearrattle import reference as R

G = 25e-6


fmu3_path, md3, unzipdir3 = session_fixtures(FMU3_PATH, BUILD_FMU3, ("fmu3_path", "md3", "unzipdir3"))


def vr_of(md, name):
    return next(v.valueReference for v in md.modelVariables if v.name == name)


def test_validates_and_declares_fmi3s_types(fmu3_path, md3):
    from fmpy.validation import validate_fmu

    assert validate_fmu(fmu3_path) == []
    assert md3.fmiVersion == "3.0" and md3.modelExchange and md3.coSimulation
    assert md3.coSimulation.hasEventMode and md3.coSimulation.canReturnEarlyAfterIntermediateUpdate
    types = {v.name: v.type for v in md3.modelVariables}
    for name in ("excitation", "solver", "contact", "stat_regime"):
        assert types[name] == "Enumeration", name
    assert types["impacts_Fplus"] == "Int32" and types["xi"] == "Float64"
    excitation = next(t for t in md3.typeDefinitions if t.name == "excitation")
    assert [i.name for i in excitation.items] == ["inputs", "sine", "torque"]
    xi = next(v for v in md3.modelVariables if v.name == "xi")
    assert xi.unit == "m" and xi.displayUnit == "um"
    assert len(md3.eventIndicators) == 5 and len(md3.derivatives) == 10
    # The FMI 2.0 FMU's GUID is the instantiation token, and the binary is the same file.
    md2 = read_model_description(str(FMU_PATH))
    assert md3.instantiationToken == md2.guid
    with zipfile.ZipFile(fmu3_path) as z3, zipfile.ZipFile(FMU_PATH) as z2:
        assert z3.read("binaries/x86_64-linux/GearRattle.so") == z2.read("binaries/linux64/GearRattle.so")


def run(path, fmi_type, **kw):
    return simulate_fmu(str(path), fmi_type=fmi_type, output=OUTPUTS, output_interval=1e-4, **kw)


def assert_bitwise_equal(a, b):
    """Every column equal to the bit (fmpy orders the columns by type: Enumerations last)."""
    assert sorted(a.dtype.names) == sorted(b.dtype.names)
    for name in a.dtype.names:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


@pytest.mark.parametrize("start", [dict(excitation=1, A_rms=500.0), dict(excitation=1, solver=2),
                                   dict(excitation=2, tau_in=2.0, omega_M=83.0)], ids=["sine", "radau", "torque"])
def test_co_simulation_equals_fmi2_to_the_bit(fmu3_path, start):
    kw = dict(start_values=start, stop_time=0.05)
    fmi2, fmi3 = run(FMU_PATH, "CoSimulation", **kw), run(fmu3_path, "CoSimulation", **kw)
    assert fmi2["impacts_Fplus"][-1] + fmi2["impacts_Fminus"][-1] > 0
    assert_bitwise_equal(fmi2, fmi3)


def test_co_simulation_with_inputs_equals_fmi2_to_the_bit(fmu3_path):
    kw = dict(start_values={"excitation": 0}, stop_time=0.03, input=main_shaft_input("S1", 0.03))
    assert_bitwise_equal(run(FMU_PATH, "CoSimulation", **kw), run(fmu3_path, "CoSimulation", **kw))


def test_model_exchange_agrees_with_fmi2_within_the_tolerance(fmu3_path):
    kw = dict(start_values={"excitation": 1}, stop_time=0.03, solver="CVode", relative_tolerance=1e-9)
    fmi2, fmi3 = run(FMU_PATH, "ModelExchange", **kw), run(fmu3_path, "ModelExchange", **kw)
    assert fmi2["impacts_Fplus"][-1] > 0
    np.testing.assert_array_equal(fmi2["impacts_Fplus"], fmi3["impacts_Fplus"])
    np.testing.assert_array_equal(fmi2["impacts_Fminus"], fmi3["impacts_Fminus"])
    assert np.max(np.abs(fmi2["xi"] - fmi3["xi"])) < 1e-4 * G


def slave3(md3, unzipdir3, name, messages=None, **kw):
    fmu = FMU3Slave(guid=md3.instantiationToken, unzipDirectory=unzipdir3,
                    modelIdentifier=md3.coSimulation.modelIdentifier, instanceName=name)
    log = None if messages is None else (lambda env, status, category, message: messages.append(message.decode()))
    fmu.instantiate(logMessage=log, **kw)
    return fmu


def started(md3, unzipdir3, name, messages=None, **kw):
    """A co-simulation instance on the paper's bench sine (the Enumeration set through Int64),
    scene S1; kw to fmi3InstantiateCoSimulation."""
    fmu = slave3(md3, unzipdir3, name, messages, **kw)
    fmu.enterInitializationMode(startTime=0.0)
    fmu.setInt64([vr_of(md3, "excitation")], [1])
    fmu.setFloat64([vr_of(md3, "f_exc"), vr_of(md3, "A_rms")], [R.SCENES["S1"]["f_exc"], R.SCENES["S1"]["A_rms"]])
    fmu.exitInitializationMode()
    return fmu


def test_steps_fmu_state_and_serialization(md3, unzipdir3):
    fmu = started(md3, unzipdir3, "state")
    xi, impacts, t_vr = vr_of(md3, "xi"), vr_of(md3, "impacts_Fplus"), vr_of(md3, "time")
    h = 1e-3
    for k in range(10):
        event, terminate, early, last = fmu.doStep(k * h, h)
        assert (event, terminate, early, last) == (False, False, False, k * h + h)
    state = fmu.getFMUState()
    serialized = fmu.serializeFMUState(state)
    ahead = []
    for k in range(10, 20):
        fmu.doStep(k * h, h)
        ahead.append((fmu.getFloat64([xi, t_vr]), fmu.getInt32([impacts])))
    for restore in (lambda: fmu.setFMUState(state),
                    lambda: fmu.setFMUState(fmu.deserializeFMUState(serialized))):
        restore()
        assert fmu.getFloat64([t_vr]) == [9 * h + h]
        again = []
        for k in range(10, 20):
            fmu.doStep(k * h, h)
            again.append((fmu.getFloat64([xi, t_vr]), fmu.getInt32([impacts])))
        assert again == ahead
    fmu.freeFMUState(state)
    fmu.terminate()
    fmu.freeInstance()


def test_directional_and_adjoint_derivatives_in_model_exchange(md3, unzipdir3):
    fmu = FMU3Model(guid=md3.instantiationToken, unzipDirectory=unzipdir3,
                    modelIdentifier=md3.modelExchange.modelIdentifier, instanceName="jacobian")
    fmu.instantiate()
    fmu.enterInitializationMode(startTime=0.0)
    fmu.setInt64([vr_of(md3, "excitation")], [1])
    fmu.setFloat64([vr_of(md3, "B"), vr_of(md3, "xi_dot_start")], [0.3, 0.02])
    fmu.exitInitializationMode()
    fmu.updateDiscreteStates()
    fmu.enterContinuousTimeMode()
    assert fmu.getNumberOfContinuousStates() == 10 and fmu.getNumberOfEventIndicators() == 5
    # The event indicators read as variables are fmi3GetEventIndicators's.
    z = (ctypes.c_double * 5)()
    fmu.getEventIndicators(z, 5)
    assert fmu.getFloat64([e.variable.valueReference for e in md3.eventIndicators]) == list(z)
    states = [d.variable.derivative.valueReference for d in md3.derivatives]
    derivatives = [d.variable.valueReference for d in md3.derivatives]
    jacobian = np.array([fmu.getDirectionalDerivative(derivatives, [s], [1.0]) for s in states]).T
    assert np.any(jacobian != 0)
    seed = np.linspace(-1.0, 2.0, len(derivatives))
    adjoint = fmu.getAdjointDerivative(derivatives, states, list(seed))
    np.testing.assert_allclose(adjoint, jacobian.T @ seed, rtol=1e-14, atol=1e-300)
    fmu.terminate()
    fmu.freeInstance()


EARLY_T_END, EARLY_H = 0.1, 1e-3


def stepped_to_impacts(md3, unzipdir3, event_mode):
    """S1 over EARLY_T_END in communication steps of EARLY_H with early return allowed, each
    early return followed by a step from where it stopped to the same communication point:
    the times returned early, the state there (xi, impacts_Fplus + impacts_Fminus, read in
    event mode if `event_mode`), the impact count at the end and xi, xi' at every
    communication point."""
    fmu = started(md3, unzipdir3, "early", earlyReturnAllowed=True, eventModeUsed=event_mode)
    counts = [vr_of(md3, "impacts_Fplus"), vr_of(md3, "impacts_Fminus")]
    xi = [vr_of(md3, "xi"), vr_of(md3, "xi_dot")]
    returned, at_return, grid = step_to_impacts(
        fmu, EARLY_T_END, EARLY_H, event_mode,
        lambda: (fmu.getFloat64(xi[:1])[0], sum(fmu.getInt32(counts))), lambda: fmu.getFloat64(xi))
    total = sum(fmu.getInt32(counts))
    fmu.terminate()
    fmu.freeInstance()
    return returned, at_return, total, grid


@pytest.mark.parametrize("event_mode", [False, True], ids=["early return", "event mode"])
def test_early_return_at_each_impact(md3, unzipdir3, event_mode):
    """One early return per impact, at the reference's instants within the FMI 2.0 sine tests'
    1e-7 s, the state there on the contact edge (xi = 0 or G) as the integrator locates it,
    the impact counted by then; the trajectory at the communication points that of a master
    that does not allow early return, to the bit."""
    returned, at_return, total, grid = stepped_to_impacts(md3, unzipdir3, event_mode)
    ref = R.scene("S1", EARLY_T_END)
    assert total > 10 and len(returned) == total == ref.impact_t.size
    assert np.max(np.abs(returned - ref.impact_t)) < 1e-7
    assert [n for _, n in at_return] == list(range(1, total + 1))
    assert max(min(abs(x), abs(x - G)) for x, _ in at_return) < 1e-9 * G
    fmu = started(md3, unzipdir3, "no early return")
    plain = []
    for k in range(1, round(EARLY_T_END / EARLY_H) + 1):
        assert fmu.doStep((k - 1) * EARLY_H, EARLY_H * k - (k - 1) * EARLY_H)[2:] == (False, k * EARLY_H)
        plain.append(fmu.getFloat64([vr_of(md3, "xi"), vr_of(md3, "xi_dot")]))
    fmu.freeInstance()
    np.testing.assert_array_equal(grid, np.array(plain))


def test_inputs_set_in_event_mode_as_in_step_mode(md3, unzipdir3):
    """Inputs mode: the main shaft's motion set in Co-Simulation's event mode moves the pair
    as the same values set in step mode do."""
    shaft = [vr_of(md3, n) for n in ("theta_M", "omega_M", "alpha_M")]
    xi = [vr_of(md3, "xi"), vr_of(md3, "xi_dot")]
    runs = []
    for event_mode in (False, True):
        fmu = slave3(md3, unzipdir3, "inputs", eventModeUsed=event_mode)
        fmu.enterInitializationMode(startTime=0.0)
        fmu.exitInitializationMode()
        if event_mode:
            fmu.updateDiscreteStates()
            fmu.enterStepMode()
        fmu.doStep(0.0, 1e-3)
        if event_mode:
            fmu.enterEventMode()
        fmu.setFloat64(shaft, [0.05, 80.0, 2e3])
        if event_mode:
            fmu.updateDiscreteStates()
            fmu.enterStepMode()
        runs.append(fmu.getFloat64(xi) + [fmu.doStep(1e-3, 1e-3)[3]] + fmu.getFloat64(xi))
        fmu.freeInstance()
    assert runs[0] == runs[1]


def test_misuse_of_the_state_machine_is_refused_with_a_log_line(md3, unzipdir3):
    messages = []
    # A token from another build.
    with pytest.raises(Exception, match="Failed to instantiate"):
        FMU3Slave(guid="{not this one}", unzipDirectory=unzipdir3, modelIdentifier="GearRattle",
                  instanceName="token").instantiate(logMessage=lambda e, s, c, m: messages.append(m.decode()))
    assert any("does not match" in m for m in messages)
    messages.clear()
    fmu = slave3(md3, unzipdir3, "misuse", messages)
    with pytest.raises(FMICallException):
        fmu.doStep(0.0, 1e-3)  # before initialisation
    assert any("illegal call sequence: fmi3DoStep" in m for m in messages)
    fmu.enterInitializationMode(startTime=0.0)
    fmu.exitInitializationMode()
    for call, text in [(fmu.enterConfigurationMode, "structural parameters are not offered"),
                       (lambda: fmu.getClock([0]), "clocks are not offered"),
                       (fmu.enterEventMode, "needs eventModeUsed = true at instantiation"),
                       (fmu.enterStepMode, "illegal call sequence: fmi3EnterStepMode")]:
        messages.clear()
        with pytest.raises(FMICallException):
            call()
        assert any(text in m for m in messages), (text, messages)
    # Still usable.
    assert fmu.doStep(0.0, 1e-3)[3] == 1e-3
    fmu.terminate()
    fmu.freeInstance()
