"""GearboxRattle's FMI 3.0 edition (target/fmu/fmi3/GearboxRattle.fmu, fmi3-shell's exports of
the same library) against the FMI 2.0 FMU: FMPy's validation and the FMI 3.0 schema, the
Enumerations and the per-gear arrays sized by n_gears; co-simulation equal to the bit (the
default five gears through simulate_fmu, three gears set in configuration mode through the
low-level API), Model Exchange within the tolerance of the FMI 2.0 tests; FMU state and
serialization replaying to the bit; misuse of configuration mode and of the arrays refused."""

import re

import numpy as np
import pytest
from fmpy.fmi3 import FMU3Model, FMU3Slave

from gearrattle import fmpy_run
from gearrattle import gearbox_fmu as GF
from support.early_return import step_to_impacts
from support.fmu import session_fixtures
from support.gearbox import BUILD_GEARBOX_FMU3, GEARBOX_FMU3_PATH


box3_path, box3_md, box3_unzipdir, vr3 = session_fixtures(
    GEARBOX_FMU3_PATH, BUILD_GEARBOX_FMU3, ("box3_path", "box3_md", "box3_unzipdir", "vr3"))
# Model Exchange's continuous states: the box's, then each gear's (an array over n_gears).
BOX_STATES = ["phi", "x_omega_I", "x_theta_F", "x_omega_F", "E_damper", "E_input_drag", "W_flywheel"]
GEAR_STATES = ["xi", "xi_dot", "E_contact", "E_lubricant", "int_a2", "int_F", "int_F2"]


def fmi3_name(fmi2_name: str) -> str:
    """The FMI 3.0 array of an FMI 2.0 per-gear name: gear[3].xi is gear.xi, der(gear[3].xi)
    der(gear.xi)."""
    return re.sub(r"gear\[\d+\]\.", "gear.", fmi2_name)


def simulate3(unzipdir, md, t_end, dt, fmi_type="CoSimulation", tol=None, **start):
    """The FMI 3.0 FMU through simulate_fmu, the outputs GF.simulate records (the gears' as
    arrays)."""
    output = list(GF.BOX_OUTPUTS) + [f"gear.{f}" for f in GF.GEAR_OUTPUTS]
    return fmpy_run.simulate(unzipdir, t_end, dt, output, fmi_type, tol, model_description=md, **start)


def test_validates_with_enumerations_and_arrays(box3_path, box3_md, box_md):
    from fmpy.validation import validate_fmu

    assert validate_fmu(box3_path) == []
    assert box3_md.fmiVersion == "3.0" and box3_md.modelExchange and box3_md.coSimulation
    assert box3_md.variableNamingConvention == "structured"
    var = {v.name: v for v in box3_md.modelVariables}
    n_gears = var["n_gears"]
    assert (n_gears.type, n_gears.causality, n_gears.variability, n_gears.start) == \
        ("UInt64", "structuralParameter", "fixed", "5")
    for name in ("excitation", "solver", "damper_stage", "gear.contact"):
        assert var[name].type == "Enumeration", name
    assert var["gear.xi"].type == "Float64" and var["gear.impacts_Fplus"].type == "Int32"
    items = {t.name: [(i.name, int(i.value)) for i in t.items] for t in box3_md.typeDefinitions}
    assert items["excitation"] == [("flywheel", 0), ("engine", 1), ("input_side", 2)]
    assert items["damper_stage"] == [("pre_damper", 1), ("main", 2)]
    assert [n for n, _ in items["contact"]] == ["gap", "Fplus", "Fminus"]
    # Every per-gear variable one array of length n_gears (five by default), its start the
    # FMI 2.0 FMU's five gears'.
    fmi2 = {v.name: v for v in box_md.modelVariables}
    per_gear = {fmi3_name(n) for n in fmi2 if "gear[" in n}
    for name in per_gear:
        dims = var[name].dimensions
        assert len(dims) == 1 and dims[0].valueReference == n_gears.valueReference, name
        assert var[name].shape == (5,), name
        declared = name.replace("gear.", "gear[{}].")
        if fmi2[declared.format(1)].start is not None:
            assert var[name].start.split() == [fmi2[declared.format(i)].start for i in range(1, 6)], name
    assert len(box3_md.derivatives) == len(BOX_STATES) + len(GEAR_STATES)
    assert box3_md.numberOfContinuousStates == len(BOX_STATES) + 5 * len(GEAR_STATES)
    assert len(box3_md.eventIndicators) == 42
    # The same variables as the FMI 2.0 FMU's, the gears' as arrays, besides the time and the
    # event indicators.
    extra = {"time"} | {f"event_indicator_{k}" for k in range(1, 43)}
    assert set(var) - extra == {fmi3_name(n) for n in fmi2}
    assert box3_md.instantiationToken == box_md.guid


EARLY_T_END, EARLY_H, EARLY_TOL = 0.1, 1e-3, 1e-10


def stepped_to_impacts(md, unzipdir, vr, event_mode, early_return=True, update=None):
    """The default box on the engine (scene B1) over EARLY_T_END in communication steps of
    EARLY_H at rtol EARLY_TOL, with early return allowed if `early_return` and the
    intermediateUpdate callback `update` (None: NULL), each early return
    followed by a step from where it stopped to the same communication point: the times
    returned early, the state there (every gear's xi, the impacts of all gears, read in
    event mode if `event_mode`), the impact count at the end and every gear's xi, xi' at
    every communication point."""
    fmu = FMU3Slave(guid=md.instantiationToken, unzipDirectory=unzipdir, modelIdentifier="GearboxRattle",
                    instanceName="early")
    fmu.instantiate(earlyReturnAllowed=early_return, eventModeUsed=event_mode, intermediateUpdate=update)
    fmu.enterInitializationMode(tolerance=EARLY_TOL, startTime=0.0)
    fmu.setInt64([vr["excitation"]], [1])
    fmu.exitInitializationMode()
    counts = [vr["gear.impacts_Fplus"], vr["gear.impacts_Fminus"]]
    gears = [vr["gear.xi"], vr["gear.xi_dot"]]
    returned, at_return, grid = step_to_impacts(
        fmu, EARLY_T_END, EARLY_H, event_mode,
        lambda: (fmu.getFloat64([vr["gear.xi"]], nValues=5), sum(fmu.getInt32(counts, nValues=10))),
        lambda: fmu.getFloat64(gears, nValues=10))
    total = sum(fmu.getInt32(counts, nValues=10))
    fmu.terminate()
    fmu.freeInstance()
    return returned, at_return, total, grid


@pytest.mark.parametrize("event_mode", [False, True], ids=["early return", "event mode"])
def test_early_return_at_each_impact_of_any_gear(box3_md, box3_unzipdir, vr3, event_mode):
    """One early return per impact of any gear, at the independent reference's instants
    (gearrattle.gearbox_reference, scene B1) within 1e-9 s at rtol 1e-10, one gear's xi there on its
    contact edge (0 or G_i) as the integrator locates it, the impact counted by then; the
    trajectory at the communication points that of a master that does not allow early
    return, to the bit."""
    from support.gearbox import reference_scene

    assert box3_md.coSimulation.hasEventMode
    returned, at_return, total, grid = stepped_to_impacts(box3_md, box3_unzipdir, vr3, event_mode)
    ref = reference_scene("B1", EARLY_T_END, EARLY_H)
    ref_t = np.sort(np.concatenate([d["t"] for d in ref.impacts[:5]]))
    assert total > 10 and len(returned) == total == ref_t.size
    assert np.max(np.abs(returned - ref_t)) < 1e-9
    assert [n for _, n in at_return] == list(range(1, total + 1))
    G = np.array([float(g) for g in next(v.start for v in box3_md.modelVariables if v.name == "gear.G").split()])
    on_edge = [np.min(np.minimum(np.abs(xi), np.abs(np.array(xi) - G)) / G) for xi, _ in at_return]
    assert max(on_edge) < 1e-9
    none, _, plain_total, plain = stepped_to_impacts(box3_md, box3_unzipdir, vr3, False, early_return=False)
    assert none.size == 0 and plain_total == total
    np.testing.assert_array_equal(grid, plain)


def fmi2_gears(result, field, n):
    """gear[1..n].field of an FMI 2.0 result, one column per gear (the FMI 3.0 array's shape)."""
    return np.array([result[f"gear[{i}].{field}"] for i in range(1, n + 1)]).T


@pytest.mark.parametrize("start", [{"excitation": 1}, {"excitation": 2, "omega_I": 84.0, "stats_from": 0.1}],
                         ids=["engine", "input_side"])
def test_co_simulation_equals_fmi2_to_the_bit(box_run, box3_unzipdir, box3_md, start):
    """simulate_fmu on the default FMU: the arrays of five gears, the box behind the damper and
    its gears stepped apart on the input side (held at 84 rad/s)."""
    fmi2 = box_run(0.3, 1e-4, **start)
    fmi3 = simulate3(box3_unzipdir, box3_md, 0.3, 1e-4, **start)
    assert GF.impact_counts(fmi2)[:, -1].sum() > 0
    for name in GF.BOX_OUTPUTS:
        np.testing.assert_array_equal(fmi2[name], fmi3[name], err_msg=name)
    for field in GF.GEAR_OUTPUTS:
        assert fmi3[f"gear.{field}"].shape == (len(fmi2), 5)
        np.testing.assert_array_equal(fmi2_gears(fmi2, field, 5), fmi3[f"gear.{field}"], err_msg=field)


@pytest.mark.parametrize("ramp", [{}, {"rpm_rate": -150.0}], ids=["steady", "run-down"])
def test_model_exchange_agrees_with_fmi2_within_the_tolerance(box_run, box3_unzipdir, box3_md, ramp):
    """fmpy's CVode at rtol 1e-12, as the FMI 2.0 Model Exchange tests run it, at a steady
    speed and on the run-down: xi within 1e-4 G_i and the same impact counts (FMI 3.0's state
    vector holds the flywheel's two, the gears' xi, then their xi_dot)."""
    fmi2 = box_run(0.05, 1e-4, "ModelExchange", 1e-12, excitation=1, **ramp)
    fmi3 = simulate3(box3_unzipdir, box3_md, 0.05, 1e-4, "ModelExchange", 1e-12, excitation=1, **ramp)
    assert np.array_equal(fmi2["time"], fmi3["time"])
    start = {v.name: v.start for v in box3_md.modelVariables}
    G = np.array([float(g) for g in start["gear.G"].split()])
    err = np.max(np.abs(fmi2_gears(fmi2, "xi", 5) - fmi3["gear.xi"]), axis=0) / G
    assert np.all(err < 1e-4), err
    impacts3 = fmi3["gear.impacts_Fplus"] + fmi3["gear.impacts_Fminus"]
    assert np.array_equal(GF.impact_counts(fmi2), impacts3.T)


def test_fmu_state_and_serialization_replay_to_the_bit(box3_md, box3_unzipdir, vr3):
    vr = vr3
    xi = [vr["gear.xi"], vr["phi"], vr["time"]]
    impacts = [vr["gear.impacts_Fplus"]]
    fmu = FMU3Slave(guid=box3_md.instantiationToken, unzipDirectory=box3_unzipdir,
                    modelIdentifier="GearboxRattle", instanceName="state")
    fmu.instantiate()
    fmu.enterInitializationMode(startTime=0.0)
    fmu.setInt64([vr["excitation"]], [1])
    fmu.exitInitializationMode()
    h = 1e-3

    def steps(k0, k1):
        out = []
        for k in range(k0, k1):
            assert fmu.doStep(k * h, h)[2:] == (False, k * h + h)
            out.append((fmu.getFloat64(xi, nValues=5 + 2), fmu.getInt32(impacts, nValues=5)))
        return out

    steps(0, 20)
    state = fmu.getFMUState()
    serialized = fmu.serializeFMUState(state)
    ahead = steps(20, 40)
    assert sum(ahead[-1][1]) > sum(ahead[0][1])  # impacts on the way
    for restore in (lambda: fmu.setFMUState(state),
                    lambda: fmu.setFMUState(fmu.deserializeFMUState(serialized))):
        restore()
        assert steps(20, 40) == ahead
    fmu.freeFMUState(state)
    fmu.terminate()
    fmu.freeInstance()


def configured(unzipdir, md, cls, name, n_gears, messages):
    """An instance of `cls` (FMU3Slave, FMU3Model) with n_gears set in configuration mode,
    its log lines appended to `messages`."""
    fmu = cls(guid=md.instantiationToken, unzipDirectory=unzipdir, modelIdentifier="GearboxRattle",
              instanceName=name)
    fmu.instantiate(logMessage=lambda e, s, c, m: messages.append(m.decode()))
    n_vr = next(v.valueReference for v in md.modelVariables if v.name == "n_gears")
    fmu.enterConfigurationMode()
    fmu.setUInt64([n_vr], [n_gears])
    assert fmu.getUInt64([n_vr]) == [n_gears]
    fmu.exitConfigurationMode()
    return fmu


def test_three_gears_set_in_configuration_mode_run_as_fmi2s_three_to_the_bit(
        box_run, box3_unzipdir, box3_md, vr3):
    """n_gears = 3 through configuration mode: every array has three values, and 0.2 s of the
    engine in communication steps of 1e-4 s (as simulate_fmu steps) give the FMI 2.0 FMU's
    trajectory with n_gears = 3, every gear's xi, xi_dot and impacts to the bit."""
    dt, n_steps = 1e-4, 2000
    fmi2 = box_run(n_steps * dt, dt, excitation=1, n_gears=3)
    fmu = configured(box3_unzipdir, box3_md, FMU3Slave, "three gears", 3, [])
    fmu.enterInitializationMode(startTime=0.0)
    fmu.setInt64([vr3["excitation"]], [1])
    fmu.exitInitializationMode()
    assert len(fmu.getFloat64([vr3["gear.I_L"]], nValues=3)) == 3
    gears = [vr3["gear.xi"], vr3["gear.xi_dot"]]
    counts = [vr3["gear.impacts_Fplus"], vr3["gear.impacts_Fminus"]]
    rows, t = [], 0.0
    for k in range(n_steps):
        t_next = (k + 1) * dt
        fmu.doStep(t, t_next - t)
        t = t_next
        rows.append(fmu.getFloat64(gears + [vr3["phi"]], nValues=7) + fmu.getInt32(counts, nValues=6))
    fmu.terminate()
    fmu.freeInstance()
    rows = np.array(rows)
    assert np.array_equal(fmi2["time"][1:], dt * np.arange(1, n_steps + 1))
    fmi2_rows = np.hstack([fmi2_gears(fmi2, f, 3)[1:] for f in
                           ("xi", "xi_dot")] + [fmi2["phi"][1:, None]]
                          + [fmi2_gears(fmi2, f, 3)[1:] for f in ("impacts_Fplus", "impacts_Fminus")])
    assert fmi2_rows[-1, 7:].sum() > 0  # the gears rattle
    np.testing.assert_array_equal(rows, fmi2_rows)


def test_three_gears_in_model_exchange_have_twenty_eight_states(box3_unzipdir, box3_md, vr3):
    """FMI 3.0's state vector of three gears: phi, x_omega_I, the flywheel's x_theta_F and
    x_omega_F, the box's energies, then each array of the gears' states (xi, xi_dot, their
    energies and window integrals) of three elements, as the variables read them (the engine
    ramped, so that every state is in use: x_omega_F at omega_F(0), its derivative alpha_F(0);
    the window open from the start)."""
    from ctypes import c_double

    fmu = configured(box3_unzipdir, box3_md, FMU3Model, "three gears ME", 3, [])
    fmu.enterInitializationMode(startTime=0.0)
    fmu.setFloat64([vr3["rpm_rate"], vr3["stats_from"]], [-150.0, 0.0])
    fmu.exitInitializationMode()
    n = len(BOX_STATES) + 3 * len(GEAR_STATES)
    assert fmu.getNumberOfContinuousStates() == n == 28
    x = (c_double * n)()
    fmu.getContinuousStates(x, n)
    expected = fmu.getFloat64([vr3[s] for s in BOX_STATES] + [vr3[f"gear.{s}"] for s in GEAR_STATES], nValues=n)
    assert list(x) == expected
    assert x[3] == pytest.approx(800 * np.pi / 30) and x[3] == x[1]
    dx = (c_double * n)()
    fmu.getContinuousStateDerivatives(dx, n)
    assert list(dx) == fmu.getFloat64([vr3[f"der({s})"] for s in BOX_STATES]
                                      + [vr3[f"der(gear.{s})"] for s in GEAR_STATES], nValues=n)
    a2 = len(BOX_STATES) + 3 * GEAR_STATES.index("int_a2")
    assert all(d > 0 for d in dx[a2:a2 + 3])  # the window's integrand a^2, the window open
    assert dx[2] == x[3] and dx[3] == pytest.approx(-150 * np.pi / 30 + 600 + 120)
    fmu.terminate()
    fmu.freeInstance()


def test_misuse_of_configuration_mode_and_arrays_is_refused_with_a_log_line(box3_unzipdir, box3_md, vr3):
    from fmpy.fmi1 import FMICallException

    messages = []
    fmu = FMU3Slave(guid=box3_md.instantiationToken, unzipDirectory=box3_unzipdir,
                    modelIdentifier="GearboxRattle", instanceName="misuse")
    fmu.instantiate(logMessage=lambda e, s, c, m: messages.append(m.decode()))
    n_vr = vr3["n_gears"]

    def refused(call, text):
        messages.clear()
        with pytest.raises(FMICallException):
            call()
        assert any(text in m for m in messages), (text, messages)

    refused(lambda: fmu.setUInt64([n_vr], [3]), "n_gears is a structural parameter: set it in configuration mode")
    refused(lambda: fmu.setInt32([n_vr], [3]), "is a structural parameter, of type UInt64")
    refused(fmu.exitConfigurationMode, "fmi3ExitConfigurationMode is allowed in state ConfigurationMode only")
    fmu.enterConfigurationMode()
    for n in (0, 9):
        refused(lambda: fmu.setUInt64([n_vr], [n]), f"n_gears = {n} refused: 1 <= n_gears <= 8")
    refused(lambda: fmu.setFloat64([vr3["gear.I_L"]], [1e-4] * 5),
            "illegal call sequence: fmi3SetFloat64 is not allowed in state ConfigurationMode")
    refused(lambda: fmu.enterInitializationMode(startTime=0.0), "illegal call sequence")
    fmu.setUInt64([n_vr], [3])
    fmu.exitConfigurationMode()
    # Three gears: an array reference holds three values.
    refused(lambda: fmu.setFloat64([vr3["gear.I_L"]], [1e-4] * 5), "nValues = 5")
    fmu.setFloat64([vr3["gear.I_L"], vr3["I_I"]], [1e-4, 2e-4, 3e-4, 0.01])
    fmu.enterInitializationMode(startTime=0.0)
    assert fmu.getFloat64([vr3["gear.I_L"], vr3["I_I"]], nValues=4) == [1e-4, 2e-4, 3e-4, 0.01]
    refused(lambda: fmu.getFloat64([vr3["gear.xi"]], nValues=5), "nValues = 5")
    refused(lambda: fmu.getInt32([vr3["gear.impacts_Fplus"]], nValues=1), "nValues = 1")
    refused(fmu.enterConfigurationMode, "fmi3EnterConfigurationMode is allowed in state Instantiated only")
    fmu.exitInitializationMode()
    assert fmu.doStep(0.0, 1e-3)[3] == 1e-3  # still usable
    fmu.terminate()
    fmu.freeInstance()
