"""GearboxRattle.fmu as a user meets it: fmpy's validation, refused parameters named, the
oil's temperature (docs/GEARBOX.md §5), the FMU state's replay, eight gears, a stiff gear."""

import math
import re
import tomllib

import numpy as np
import pytest
from fmpy.fmi2 import fmi2OK

from gearrattle import gearbox_fmu as GF
from gearrattle import gearbox_reference as R
from support.fmu import ROOT
from support.slave import REFUSED, Slave

CONTRACT = ROOT / "modelDescription" / "GearboxRattle.toml"


def test_validate_fmu(gearbox_fmu):
    from fmpy.validation import validate_fmu

    problems = validate_fmu(gearbox_fmu)
    assert not problems, problems


@pytest.mark.parametrize(
    "name,value,named",
    [
        ("n_gears", 9, "n_gears"),
        ("phi_1", 0.0, "phi_1"),
        ("k_2", 10.0, "k_2"),  # below k_1 = 28.6 N m/rad
        ("nu_100", 55e-6, "nu_100"),  # = nu_40
        ("nu_100", 80e-6, "nu_100"),  # > nu_40
        ("T_oil", -95.0, "T_oil"),  # Vogel's law's pole
    ],
)
def test_invalid_parameter_refused(box_unzipdir, box_md, name, value, named):
    """Refused by fmi2SetXxx or at the latest by fmi2ExitInitializationMode, with a message
    naming the parameter."""
    s = Slave(box_unzipdir, box_md, "refusal")
    try:
        assert s.setup() == fmi2OK and s.enter_init() == fmi2OK
        m = s.mark()
        vr = [s.vrs[name]]
        st = s.set_integer(vr, [value]) if isinstance(value, int) else s.set_real(vr, [value])
        if st == fmi2OK:
            assert s.exit_init() in REFUSED, f"{name} = {value} accepted"
        else:
            assert st in REFUSED
        s.assert_logged(m, named)
    finally:
        s.free()


def _vogel(T, nu_40, nu_100):
    """nu(T) / nu_40, docs/GEARBOX.md §5 (Vogel's constant 95 °C)."""
    b = math.log(nu_40 / nu_100) / (1 / 135 - 1 / 195)
    return math.exp(b * (1 / (T + 95) - 1 / 135))


@pytest.mark.parametrize("T", [-10.0, 80.0])
def test_drag_follows_vogel(box_run, T):
    """At constant engine speed (no engine orders), at t = 0 every body turns at the speed of
    rigid meshing, so the drag on the input side scales with nu(T) / nu_40 alone; the defaults'
    oil gives 29 times and 0.27 times the 40 °C drag (docs/GEARBOX.md §5)."""
    flat = dict(a_1=0.0, a_2=0.0)
    warm, other = box_run(1e-3, 1e-4, **flat), box_run(1e-3, 1e-4, T_oil=T, **flat)
    factor = _vogel(T, 55e-6, 9.5e-6)
    assert other["T_drag"][0] / warm["T_drag"][0] == pytest.approx(factor, rel=1e-12)
    assert (round(factor) == 29) if T < 0 else (round(factor, 2) == 0.27)


def test_state_replay_is_bit_exact(box_unzipdir, box_md):
    """Get the state at 0.3 s, run to 0.5 s, set it back, rerun: the same arrays."""
    s = Slave(box_unzipdir, box_md, "replay")
    try:
        s.init()
        h = 1e-4
        names = ["phi", "tau_F"] + GF.gear_names(5, ("xi", "xi_dot"))
        refs = [s.vrs[n] for n in names]
        counts = [s.vrs[n] for n in GF.gear_names(5, ("impacts_Fplus", "impacts_Fminus"))]
        for _ in range(3000):
            assert s.do_step(h) == fmi2OK
        state = s.fmu.getFMUstate()
        t_mark = s.t

        def leg():
            rows = []
            for _ in range(2000):
                assert s.do_step(h) == fmi2OK
                rows.append(s.get_real(refs)[1] + s.get_integer(counts)[1])
            return np.array(rows)

        first = leg()
        s.fmu.setFMUstate(state)
        s.t = t_mark
        again = leg()
        s.fmu.freeFMUstate(state)
        assert np.array_equal(first, again)
        assert first[-1, -10:].sum() > 0  # impacts happened on the way
    finally:
        s.free()


def _contract_gear_starts() -> dict:
    """gear[i].X of gears 1..8 as the contract's start values give them."""
    with open(CONTRACT, "rb") as f:
        variables = tomllib.load(f)["variable"]
    out = {}
    for v in variables:
        if v.get("array") == "gear" and v["causality"] == "parameter" and v["name"] in R.GEAR_KEYS:
            start = v["start"] if isinstance(v["start"], list) else [v["start"]] * 8
            out.update({f"gear[{i}].{v['name']}": float(x) for i, x in enumerate(start, start=1)})
    return out


def test_eight_gears_against_the_reference(box_run):
    """n_gears = 8 with the contract's gears 6-8, over 0.15 s against the reference."""
    t_end, dt = 0.15, 1e-4
    fmu = box_run(t_end, dt, tol=1e-10, n_gears=8)
    starts = _contract_gear_starts()
    ref = R.simulate(R.params(n_gears=8, **starts), t_end,
                     t_eval=fmu["time"])
    xi = GF.per_gear(fmu, "xi")
    assert xi.shape[0] == 8
    G = np.array([starts[f"gear[{i}].G"] for i in range(1, 9)])
    err = np.max(np.abs(xi - ref.xi), axis=1) / G
    assert np.all(err < 1e-4), err
    assert np.array_equal(GF.impact_counts(fmu)[:, -1], ref.impact_counts([t_end])[:, -1])


STEP_LOG = re.compile(r"(\d+) accepted \((\d+) by Radau IIA\).* (\d+) rhs evaluations in total; next step \S+ s by (.+)$")


def _stepped_with_log(box_unzipdir, box_md, t_end, h, **start):
    """Steps the box with logStep on: each step's (Radau IIA steps so far, rhs evaluations so
    far, the method of the next step), and gear 1's xi at each step."""
    s = Slave(box_unzipdir, box_md, "stiff")
    try:
        assert s.set_debug_logging(True, ["logStep"]) == fmi2OK
        s.init(reals={k: v for k, v in start.items() if not isinstance(v, int)},
               integers={k: v for k, v in start.items() if isinstance(v, int)})
        xi = []
        for _ in range(int(round(t_end / h))):
            assert s.do_step(h) == fmi2OK
            xi.append(s.real("gear[1].xi"))
        steps = [STEP_LOG.search(m) for _, _, m in s.logs]
        steps = [(int(m[2]), int(m[3]), m[4].strip()) for m in steps if m]
        assert steps, f"no logStep message with the solver's counts: {s.logs[:3]}"
        return steps, np.array(xi)
    finally:
        s.free()


def test_stiff_gear_hands_over_to_radau_and_back(box_unzipdir, box_md):
    """Gear 1 a thousand times lighter (I_L = 0.75e-6 kg m²: stiff while it is pressed on its
    flank) with a thirtieth of its drag: the automatic solver hands over to Radau IIA (after
    some 90 ms) and back to DOPRI5 (after some 220 ms), and gives the explicit method's
    answer."""
    light = {"gear[1].I_L": 0.75e-6, "gear[1].C": 2e-3 / 30}
    t_end, h = 0.3, 1e-4
    auto, xi_auto = _stepped_with_log(box_unzipdir, box_md, t_end, h, **light)
    explicit, xi_explicit = _stepped_with_log(box_unzipdir, box_md, t_end, h, solver=1, **light)
    methods = [m for _, _, m in auto]
    radau = [k for k, m in enumerate(methods) if m == "Radau IIA"]
    assert radau, "auto never handed over to Radau IIA"
    assert "DOPRI5" in methods[radau[0]:], "auto never came back to DOPRI5"
    assert auto[-1][0] > 0 and explicit[-1][0] == 0
    G = 80e-6
    assert np.max(np.abs(xi_auto - xi_explicit)) < 1e-4 * G
    print(f"stiff gear 1, {t_end:g} s: auto {auto[-1][1]} rhs ({auto[-1][0]} Radau IIA steps), "
          f"DOPRI5 alone {explicit[-1][1]} rhs")
