"""GearboxRattle's FMI 3.0 edition (target/fmu/fmi3/GearboxRattle.fmu, fmi3-shell's exports of
the same library) against the FMI 2.0 FMU: FMPy's validation and the FMI 3.0 schema, the
Enumerations and per-gear structured names; co-simulation equal to the bit, Model Exchange
within the tolerance of the FMI 2.0 tests; FMU state and serialization replaying to the bit."""

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi3 import FMU3Slave

from gearrattle import gearbox_fmu as GF

GEARBOX_FMU3_PATH = GF.ROOT / "target" / "fmu" / "fmi3" / "GearboxRattle.fmu"


@pytest.fixture(scope="module")
def box3_path():
    if not GEARBOX_FMU3_PATH.is_file():
        pytest.fail(f"{GEARBOX_FMU3_PATH} does not exist: build it with `make fmu` (or `cargo run "
                    "--release -p packaging -- --model GearboxRattle --fmi 3 --lib "
                    "target/release/libgearbox_rattle.so`)", pytrace=False)
    return str(GEARBOX_FMU3_PATH)


@pytest.fixture(scope="module")
def box3_md(box3_path):
    # validate=True: the FMI 3.0 XML schema and FMPy's checks of the description.
    return read_model_description(box3_path, validate=True)


@pytest.fixture(scope="module")
def box3_unzipdir(box3_path, tmp_path_factory):
    return extract(box3_path, unzipdir=str(tmp_path_factory.mktemp("GearboxRattle_fmi3")))


def test_validates_with_enumerations_and_structured_names(box3_path, box3_md, box_md):
    from fmpy.validation import validate_fmu

    assert validate_fmu(box3_path) == []
    assert box3_md.fmiVersion == "3.0" and box3_md.modelExchange and box3_md.coSimulation
    assert box3_md.variableNamingConvention == "structured"
    types = {v.name: v.type for v in box3_md.modelVariables}
    for name in ("excitation", "solver", "damper_stage", "gear[1].contact", "gear[8].contact"):
        assert types[name] == "Enumeration", name
    assert types["gear[3].xi"] == "Float64" and types["gear[3].impacts_Fplus"] == "Int32"
    items = {t.name: [(i.name, int(i.value)) for i in t.items] for t in box3_md.typeDefinitions}
    assert items["excitation"] == [("flywheel", 0), ("engine", 1), ("input_side", 2)]
    assert items["damper_stage"] == [("pre_damper", 1), ("main", 2)]
    assert [n for n, _ in items["contact"]] == ["gap", "Fplus", "Fminus"]
    assert len(box3_md.derivatives) == 18 and len(box3_md.eventIndicators) == 42
    # The same variables as the FMI 2.0 FMU's, besides the time and the event indicators.
    extra = {"time"} | {f"event_indicator_{k}" for k in range(1, 43)}
    assert {v.name for v in box3_md.modelVariables} - extra == {v.name for v in box_md.modelVariables}
    assert box3_md.instantiationToken == box_md.guid


def test_event_mode_is_refused_with_a_log_line(box3_md, box3_unzipdir):
    """The gearbox's steps do not end at its impacts: no event mode (hasEventMode false)."""
    assert not box3_md.coSimulation.hasEventMode
    messages = []
    fmu = FMU3Slave(guid=box3_md.instantiationToken, unzipDirectory=box3_unzipdir,
                    modelIdentifier="GearboxRattle", instanceName="event mode")
    with pytest.raises(Exception, match="Failed to instantiate"):
        fmu.instantiate(eventModeUsed=True, logMessage=lambda e, s, c, m: messages.append(m.decode()))
    assert any("hasEventMode is false" in m for m in messages)


def test_co_simulation_equals_fmi2_to_the_bit(box_run, box3_unzipdir, box3_md):
    fmi2 = box_run(0.3, 1e-4, excitation=1)
    fmi3 = GF.simulate(box3_unzipdir, 0.3, 1e-4, model_description=box3_md, excitation=1)
    assert GF.impact_counts(fmi2)[:, -1].sum() > 0
    assert sorted(fmi2.dtype.names) == sorted(fmi3.dtype.names)
    for name in fmi2.dtype.names:
        np.testing.assert_array_equal(fmi2[name], fmi3[name], err_msg=name)


def test_model_exchange_agrees_with_fmi2_within_the_tolerance(box_run, box3_unzipdir, box3_md):
    """fmpy's CVode at rtol 1e-12, as the FMI 2.0 Model Exchange tests run it: xi within
    1e-4 G_i and the same impact counts."""
    fmi2 = box_run(0.05, 1e-4, "ModelExchange", 1e-12, excitation=1)
    fmi3 = GF.simulate(box3_unzipdir, 0.05, 1e-4, "ModelExchange", 1e-12, model_description=box3_md,
                       excitation=1)
    assert np.array_equal(fmi2["time"], fmi3["time"])
    start = {v.name: v.start for v in box3_md.modelVariables}
    G = np.array([float(start[f"gear[{i}].G"]) for i in range(1, 6)])
    err = np.max(np.abs(GF.per_gear(fmi2, "xi") - GF.per_gear(fmi3, "xi")), axis=1) / G
    assert np.all(err < 1e-4), err
    assert np.array_equal(GF.impact_counts(fmi2), GF.impact_counts(fmi3))


def test_fmu_state_and_serialization_replay_to_the_bit(box3_md, box3_unzipdir):
    vr = {v.name: v.valueReference for v in box3_md.modelVariables}
    xi = [vr[f"gear[{i}].xi"] for i in range(1, 6)] + [vr["phi"], vr["time"]]
    impacts = [vr[f"gear[{i}].impacts_Fplus"] for i in range(1, 6)]
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
            out.append((fmu.getFloat64(xi), fmu.getInt32(impacts)))
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
