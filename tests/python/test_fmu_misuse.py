"""Misuse of the FMI 2.0 API: each refused call returns a non-OK status and logs why,
the process does not crash, and the instance stays usable where that makes sense.

Driven with fmpy's low-level FMU2Slave and a logger callback that records the messages.
Errors are logged with logging off (the contract: logStatusError is always on)."""

import math

import pytest
from fmpy.fmi2 import fmi2Discard, fmi2Error, fmi2OK, fmi2Warning

from gearrattle import reference as R
from support.slave import REFUSED, Slave

UNKNOWN_VR = 999


@pytest.fixture
def slave(unzipdir, model_description):
    s = Slave(unzipdir, model_description, "misuse")
    yield s
    s.free()


# ---------------------------------------------------------------------------------------


def test_do_step_before_initialization(slave):
    m = slave.mark()
    st = slave.do_step(1e-4, t=0.0)
    assert st in REFUSED
    slave.assert_logged(m, "doStep")
    # the instance can be reset and used
    assert slave.reset() == fmi2OK
    slave.init()
    assert slave.do_step(1e-4) == fmi2OK


@pytest.mark.parametrize("when", ["initialization", "step"])
def test_unknown_value_reference(slave, when):
    if when == "step":
        slave.init()
        assert slave.do_step(1e-4) == fmi2OK
    else:  # fmi2GetReal is not allowed before initialization mode (FMI 2.0)
        assert slave.setup() == fmi2OK
        assert slave.enter_init() == fmi2OK
    m = slave.mark()
    st, _ = slave.get_real([UNKNOWN_VR])
    assert st in REFUSED
    slave.assert_logged(m, str(UNKNOWN_VR))
    m = slave.mark()
    st, _ = slave.get_real([slave.vrs["xi"], UNKNOWN_VR])
    assert st in REFUSED
    slave.assert_logged(m, str(UNKNOWN_VR))
    m = slave.mark()
    assert slave.set_real([UNKNOWN_VR], [1.0]) in REFUSED
    slave.assert_logged(m, str(UNKNOWN_VR))
    # value references are per type: 100 is the Integer `excitation`, 1 the Real `I_L`
    m = slave.mark()
    st, _ = slave.get_real([slave.vrs["excitation"]])
    assert st in REFUSED
    slave.assert_logged(m)
    m = slave.mark()
    st, _ = slave.get_integer([slave.vrs["I_L"]])
    assert st in REFUSED
    slave.assert_logged(m)
    # valid getters still answer
    st, v = slave.get_real([slave.vrs["I_L"]])
    assert st == fmi2OK and v[0] == pytest.approx(R.DEFAULTS["I_L"])


def test_set_output_refused(slave):
    slave.init()
    m = slave.mark()
    assert slave.set_real([slave.vrs["xi"]], [0.0]) in REFUSED
    slave.assert_logged(m)
    assert slave.real("xi") == pytest.approx(0.5 * R.DEFAULTS["G"], abs=1e-18)


def test_negative_communication_step(slave):
    slave.init()
    assert slave.do_step(1e-4) == fmi2OK
    m = slave.mark()
    assert slave.do_step(-1e-4) in REFUSED
    slave.assert_logged(m, "doStep")
    m = slave.mark()
    assert slave.do_step(math.nan) in REFUSED
    slave.assert_logged(m, "doStep")
    assert slave.real("xi") == pytest.approx(0.5 * R.DEFAULTS["G"], abs=1e-15)
    # the refused call changed nothing: stepping on from the same time works
    assert slave.do_step(1e-4) == fmi2OK
    assert math.isfinite(slave.real("xi"))


def test_communication_step_below_the_resolution_of_time(slave):
    """At t = 1e9 s doubles lie 1.2e-7 s apart: a step of 1e-7 s cannot be taken as asked."""
    slave.init(start=1e9)
    m = slave.mark()
    assert slave.do_step(1e-7) in REFUSED
    slave.assert_logged(m, "resolution of time")
    # the refused call changed nothing: a step the time axis resolves goes on
    assert slave.do_step(1e-3) == fmi2OK
    assert math.isfinite(slave.real("xi"))


def test_communication_point_mismatch(slave):
    """currentCommunicationPoint must be the instance's time (FMI 2.0: t(k+1) = t(k) + h(k))."""
    slave.init()
    assert slave.do_step(1e-3) == fmi2OK
    m = slave.mark()
    assert slave.do_step(1e-3, t=0.5) in REFUSED
    slave.assert_logged(m, "doStep")
    assert slave.do_step(1e-3) == fmi2OK  # from the right time: goes on
    assert math.isfinite(slave.real("xi"))


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("name", ["theta_M", "omega_M", "alpha_M"])
def test_non_finite_input_refused(slave, name, bad):
    slave.init()
    assert slave.set_real([slave.vrs["omega_M"]], [1.0]) == fmi2OK
    assert slave.do_step(1e-3) == fmi2OK
    before = {n: slave.real(n) for n in ("theta_M_out", "omega_M_out", "alpha_M_out", "xi", "xi_dot")}
    m = slave.mark()
    assert slave.set_real([slave.vrs[name]], [bad]) in REFUSED
    slave.assert_logged(m, name)
    # not applied; the instance goes on
    after = {n: slave.real(n) for n in before}
    assert after == before
    assert slave.do_step(1e-3) == fmi2OK
    for n in ("xi", "xi_dot", "theta_L", "omega_L", "F_contact", "theta_M_out"):
        assert math.isfinite(slave.real(n)), n
    # the shaft's speed is still the last valid input (alpha_M = 0)
    assert slave.real("omega_M_out") == pytest.approx(1.0, rel=1e-12)


INVALID_PARAMETERS = [
    ("I_L", -1.0),
    ("I_L", 0.0),
    ("alpha", 0.5),
    ("G", 0.0),
    ("G", -25e-6),
    ("r_L", 0.0),
    ("r_M", -0.02),
    ("K_star", -3e6),
    ("epsilon", -1e-6),
    ("C_LM", -1.0),
    ("C", -0.025),
    ("I_L", math.nan),
    ("K_star", math.inf),
]


@pytest.mark.parametrize("name,value", INVALID_PARAMETERS)
def test_invalid_parameter_refused(slave, name, value):
    """Refused by setReal or at the latest by exitInitializationMode, with a message naming
    the parameter; after fmi2Reset a valid initialisation works."""
    assert slave.setup() == fmi2OK
    assert slave.enter_init() == fmi2OK
    m = slave.mark()
    st_set = slave.set_real([slave.vrs[name]], [value])
    if st_set == fmi2OK:
        st_exit = slave.exit_init()
        assert st_exit in REFUSED, f"{name} = {value} accepted"
    else:
        assert st_set in REFUSED
    slave.assert_logged(m, name)
    # reset: back to the start values, and a valid run
    assert slave.reset() == fmi2OK
    slave.init()
    assert slave.real(name) == pytest.approx(R.DEFAULTS[name], rel=1e-15)
    assert slave.do_step(1e-3) == fmi2OK
    assert slave.real("xi") == pytest.approx(0.5 * R.DEFAULTS["G"], abs=1e-15)


def _ranged_parameters(fmu_path):
    """(name, type, bound, exclusive, side) of every bound the model description states, read
    as the study runner reads it (gearrattle.study.model)."""
    from gearrattle.study.model import read_model

    for v in read_model(fmu_path).parameters.values():
        if v.min is not None:
            yield v.name, v.type, v.min, v.min_exclusive, -1
        if v.max is not None:
            yield v.name, v.type, v.max, v.max_exclusive, +1


def test_the_fmu_enforces_every_range_its_model_description_states(unzipdir, model_description,
                                                                  fmu_path):
    """Each stated bound: a value beyond it (at it, for an exclusive one) is refused at the
    latest by exitInitializationMode with a message naming the parameter and its range, and
    an inclusive bound itself is accepted."""
    bounds = list(_ranged_parameters(fmu_path))
    assert {"I_L", "G", "alpha", "excitation"} <= {b[0] for b in bounds}, bounds
    for name, kind, bound, exclusive, side in bounds:
        step = 1 if kind == "Integer" else max(abs(bound), 1.0) * 1e-9
        for value, accepted in ([(bound, False)] if exclusive else
                                [(bound + side * step, False), (bound, True)]):
            s = Slave(unzipdir, model_description, "ranges")
            try:
                assert s.setup() == fmi2OK and s.enter_init() == fmi2OK
                m = s.mark()
                if kind == "Integer":
                    assert s.set_integer([s.vrs[name]], [int(value)]) == fmi2OK
                else:
                    assert s.set_real([s.vrs[name]], [value]) == fmi2OK
                status = s.exit_init()
                if accepted:
                    assert status == fmi2OK, (name, value, s.new_logs(m))
                else:
                    assert status in REFUSED, f"{name} = {value} accepted"
                    s.assert_logged(m, name, "is invalid: allowed")
            finally:
                s.free()


@pytest.mark.parametrize(
    "integers,reals,named",
    [
        ({"excitation": 3}, {}, "excitation"),
        ({"excitation": -1}, {}, "excitation"),
        ({"excitation": 1}, {"f_exc": 0.0}, "f_exc"),
        ({"solver": 3}, {}, "solver"),
        ({"solver": -1}, {}, "solver"),
    ],
)
def test_invalid_excitation_refused(slave, integers, reals, named):
    assert slave.setup() == fmi2OK
    assert slave.enter_init() == fmi2OK
    m = slave.mark()
    statuses = [slave.set_integer([slave.vrs[k]], [v]) for k, v in integers.items()]
    statuses += [slave.set_real([slave.vrs[k]], [v]) for k, v in reals.items()]
    if all(s == fmi2OK for s in statuses):
        assert slave.exit_init() in REFUSED
    else:
        assert any(s in REFUSED for s in statuses)
    slave.assert_logged(m, named)
    assert slave.reset() == fmi2OK
    slave.init(integers={"excitation": 1})
    assert slave.do_step(1e-3) == fmi2OK


def test_unknown_log_category(slave):
    m = slave.mark()
    st = slave.set_debug_logging(True, ["noSuchCategory"])
    assert st in (fmi2Warning, fmi2Discard, fmi2Error)
    slave.assert_logged(m, "noSuchCategory")
    # the known categories are accepted; logEvents reports the impacts
    assert slave.set_debug_logging(True, ["logEvents"]) == fmi2OK
    slave.init(integers={"excitation": 1})
    for _ in range(10):  # 10 ms of S1: the first impact is at 6.8 ms (on F+)
        assert slave.do_step(1e-3) == fmi2OK
    st, n = slave.get_integer([slave.vrs["impacts_Fplus"]])
    assert st == fmi2OK and n[0] == 1
    assert any(cat == "logEvents" for _, cat, _ in slave.logs), slave.logs[-5:]
    assert slave.set_debug_logging(False, []) == fmi2OK


def test_calls_after_terminate(slave):
    slave.init()
    assert slave.do_step(1e-3) == fmi2OK
    assert slave.terminate() == fmi2OK
    m = slave.mark()
    assert slave.do_step(1e-3) in REFUSED
    slave.assert_logged(m)
    # getters still answer after terminate (FMI 2.0: state "terminated")
    assert math.isfinite(slave.real("xi"))
    assert slave.reset() == fmi2OK
    slave.init()
    assert slave.do_step(1e-3) == fmi2OK


def test_fixed_parameter_not_settable_after_init(slave, model_description):
    var = next(v for v in model_description.modelVariables if v.name == "I_L")
    if var.variability == "tunable":
        pytest.skip("I_L is declared tunable")
    slave.init()
    m = slave.mark()
    assert slave.set_real([slave.vrs["I_L"]], [1e-3]) in REFUSED
    slave.assert_logged(m, "I_L")
    assert slave.real("I_L") == pytest.approx(R.DEFAULTS["I_L"])
    assert slave.do_step(1e-3) == fmi2OK


def test_many_instances_in_one_process(unzipdir, model_description):
    """canBeInstantiatedOnlyOncePerProcess = false: independent instances side by side."""
    a = Slave(unzipdir, model_description, "a")
    b = Slave(unzipdir, model_description, "b")
    try:
        a.init(integers={"excitation": 1})
        b.init(integers={"excitation": 1}, reals={"A_rms": 500.0})
        for _ in range(10):
            assert a.do_step(1e-3) == fmi2OK
            assert b.do_step(1e-3) == fmi2OK
        ra = R.scene("S1", 0.05, 1e-4)
        rb = R.scene("S3", 0.05, 1e-4)
        assert a.real("xi") == pytest.approx(ra.xi[100], abs=1e-3 * R.DEFAULTS["G"])
        assert b.real("xi") == pytest.approx(rb.xi[100], abs=1e-3 * R.DEFAULTS["G"])
    finally:
        a.free()
        b.free()
