"""The FMU in sine mode (excitation = 1, the paper's bench, docs/MODEL.md §5) against the Python
reference (reference.py), run through fmpy on target/fmu/GearRattle.fmu."""

import functools
import math
import tomllib

import numpy as np
import pytest

from gearrattle import reference as R
from support.fmu import CONTRACT_PATH

P = R.params()
G = P["G"]
DT = 1e-4  # communication step = output interval


def _check_times(res, t_end, dt=DT):
    n = int(round(t_end / dt))
    assert res["time"].size == n + 1, (res["time"][:3], res["time"][-3:])
    np.testing.assert_allclose(res["time"], np.arange(n + 1) * dt, rtol=0, atol=1e-12)


def fmu_impacts(res):
    """(flank sequence, index of the output interval of each impact) from the counters."""
    flanks, ambiguous = R.flanks_from_counters(res["impacts_Fplus"], res["impacts_Fminus"])
    assert ambiguous == 0, "both impact counters rose within one output interval"
    dp = np.diff(res["impacts_Fplus"].astype(np.int64), prepend=0)
    dm = np.diff(res["impacts_Fminus"].astype(np.int64), prepend=0)
    idx = np.repeat(np.arange(res["time"].size), dp + dm)
    assert idx.size == flanks.size
    return flanks, idx


def assert_impacts_match(res, ref, slack=1e-7):
    """Same flank sequence as the reference, each impact inside the FMU's output interval."""
    flanks, idx = fmu_impacts(res)
    t = res["time"]
    ref_sel = ref.impact_t <= t[-1]
    ref_t, ref_fl = ref.impact_t[ref_sel], ref.impact_flank[ref_sel]
    assert flanks.tolist() == ref_fl.tolist(), (
        f"FMU runs {R.runs(flanks)[:12]} ... reference runs {R.runs(ref_fl)[:12]} ...; "
        f"FMU {flanks.size} impacts, reference {ref_fl.size}"
    )
    lo = t[np.maximum(idx - 1, 0)] - slack
    hi = t[idx] + slack
    bad = np.nonzero((ref_t < lo) | (ref_t > hi))[0]
    assert bad.size == 0, f"impact times off: reference {ref_t[bad][:5]}, FMU interval end {t[idx][bad][:5]}"


# ---------------------------------------------------------------------------------------
# The packaged FMU and its model description
# ---------------------------------------------------------------------------------------


def test_validate_fmu(fmu_path):
    from fmpy.validation import validate_fmu

    problems = validate_fmu(fmu_path)
    assert problems == [], problems


def test_model_description_matches_contract(model_description):
    """modelDescription.xml carries the contract of modelDescription/GearRattle.toml."""
    contract = tomllib.loads(CONTRACT_PATH.read_text())
    md = model_description
    assert md.fmiVersion == "2.0"
    assert md.coSimulation is not None and md.coSimulation.modelIdentifier == contract["model"]["identifier"]
    assert md.modelName == contract["model"]["name"]
    assert float(md.defaultExperiment.tolerance) == pytest.approx(contract["experiment"]["tolerance"])
    assert float(md.defaultExperiment.stopTime) == pytest.approx(contract["experiment"]["stopTime"])
    assert float(md.defaultExperiment.stepSize) == pytest.approx(contract["experiment"]["stepSize"])
    assert md.coSimulation.canHandleVariableCommunicationStepSize is True
    by_name = {v.name: v for v in md.modelVariables}
    assert len(by_name) == len(contract["variable"])
    for cv in contract["variable"]:
        v = by_name.get(cv["name"])
        assert v is not None, f"{cv['name']} missing from modelDescription.xml"
        assert v.valueReference == cv["vr"], cv["name"]
        assert v.type == cv["type"], cv["name"]
        assert v.causality == cv["causality"], cv["name"]
        if "start" in cv:
            assert float(v.start) == pytest.approx(cv["start"], rel=1e-15, abs=0), cv["name"]
        if "unit" in cv:
            unit = v.unit or (v.declaredType.unit if v.declaredType is not None else None)
            assert unit == cv["unit"], cv["name"]
    # ModelStructure: the outputs and their direct dependencies on the inputs
    # (a missing dependencies attribute, None here, would mean "depends on everything")
    deps = {u.variable.name: u.dependencies for u in md.outputs}
    for cv in contract["variable"]:
        if cv["causality"] == "output":
            assert cv["name"] in deps, f"{cv['name']} not in ModelStructure/Outputs"
            assert deps[cv["name"]] is not None, f"{cv['name']}: no dependencies attribute"
            assert sorted(d.name for d in deps[cv["name"]]) == sorted(cv.get("depends_on", [])), cv["name"]
    assert [c.name for c in md.logCategories] == [c[0] for c in contract["log_categories"]]


def test_default_parameters_are_the_papers(model_description):
    by_name = {v.name: v for v in model_description.modelVariables}
    for name, value in R.DEFAULTS.items():
        assert float(by_name[name].start) == pytest.approx(value, rel=1e-15), name


# ---------------------------------------------------------------------------------------
# Pointwise accuracy over the first 50 ms (all three scenes are predictable there)
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("scene", ["S1", "S2", "S3"])
def test_sine_first_50ms_matches_reference(fmu_run, scene):
    res = fmu_run("sine", scene, 0.05, DT)
    ref = R.scene(scene, 0.05, DT)
    _check_times(res, 0.05)
    err = np.abs(res["xi"] - ref.xi)
    k = int(np.argmax(err))
    assert err[k] <= 1e-4 * G, f"max |dxi| = {err[k] / G:.3e} G at t = {res['time'][k]:.4f} s"
    err_v = np.max(np.abs(res["xi_dot"] - ref.xi_dot))
    assert err_v <= 1e-4 * G * 3600, f"max |dxi_dot| = {err_v:.3e} m/s"
    assert_impacts_match(res, ref)
    # dissipated energies (quadrature states of the reference)
    for name in ("E_contact", "E_lubricant"):
        e_ref = getattr(ref, name)
        assert e_ref[-1] > 0
        d = np.max(np.abs(res[name] - e_ref))
        assert d <= 1e-3 * e_ref[-1], f"{name}: max diff {d:.3e} J, final reference {e_ref[-1]:.3e} J"


@pytest.mark.parametrize("scene", ["S1", "S3"])
def test_sine_outputs_consistent(fmu_run, scene):
    """The outputs agree with each other, with docs/MODEL.md's formulas and with the excitation."""
    p = R.params(scene)
    res = fmu_run("sine", scene, 0.05, DT)
    t = res["time"]
    xi, xd = res["xi"], res["xi_dot"]
    th_m, om_m, al_m = R.main_shaft(t, p)
    # the built-in excitation (§5)
    np.testing.assert_allclose(res["theta_M_out"], th_m, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res["omega_M_out"], om_m, rtol=0, atol=1e-10)
    np.testing.assert_allclose(res["alpha_M_out"], al_m, rtol=0, atol=1e-8)
    # kinematics (§1)
    np.testing.assert_allclose(p["r_L"] * res["theta_L"] - p["r_M"] * res["theta_M_out"], xi, rtol=0, atol=1e-6 * G)
    np.testing.assert_allclose(p["r_L"] * res["omega_L"] - p["r_M"] * res["omega_M_out"], xd, rtol=0, atol=1e-9)
    # contact law (§2) and equation of motion (§3)
    f_law = R.contact_force(xi, xd, p)
    f_scale = np.max(np.abs(f_law))
    assert f_scale > 1.0
    np.testing.assert_allclose(res["F_contact"], f_law, rtol=0, atol=1e-9 * f_scale)
    np.testing.assert_allclose(res["tau_M"], p["r_M"] * res["F_contact"], rtol=1e-12, atol=1e-15)
    al_l = (p["B"] - p["r_L"] * res["F_contact"] - p["C"] * (res["omega_L"] - p["omega_S"])) / p["I_L"]
    np.testing.assert_allclose(res["alpha_L"], al_l, rtol=0, atol=1e-9 * np.max(np.abs(al_l)))
    np.testing.assert_allclose(res["a_pitch_L"], p["r_L"] * res["alpha_L"], rtol=1e-12, atol=1e-12)
    # contact flag: 0 gap, 1 F+ (xi < 0), 2 F- (xi > G); points right on an edge not judged
    clear = (np.abs(xi) > 1e-15) & (np.abs(xi - G) > 1e-15)
    expected = R.contact_region(xi, p)
    wrong = np.nonzero(clear & (res["contact"] != expected))[0]
    assert wrong.size == 0, f"contact flag {res['contact'][wrong][:5]} for xi/G = {xi[wrong][:5] / G}"
    assert {0, 1, 2} <= set(res["contact"].tolist())
    # impact speed: |xi_dot| at the last onset, as the reference (held between impacts)
    ref = R.scene(scene, 0.05, DT)
    n = res["impacts_Fplus"] + res["impacts_Fminus"]
    after = n > 0
    assert np.all(np.isfinite(res["impact_speed"])) and np.all(res["impact_speed"] >= 0.0)
    assert n[-1] == ref.impact_t.size
    last = ref.impact_speed[n[after] - 1]
    np.testing.assert_allclose(res["impact_speed"][after], last, rtol=1e-3, atol=2e-6)
    # dissipated energies never decrease
    assert np.all(np.diff(res["E_contact"]) >= 0) and np.all(np.diff(res["E_lubricant"]) >= 0)


# ---------------------------------------------------------------------------------------
# The whole second: impact pattern (S1, S3: pointwise predictable; S2: chaotic)
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("scene", ["S1", "S3"])
def test_sine_1s_impact_pattern(fmu_run, scene):
    res = fmu_run("sine", scene, 1.0, DT)
    ref = R.scene(scene, 1.0)
    _check_times(res, 1.0)
    assert_impacts_match(res, ref, slack=1e-6)
    flanks, _ = fmu_impacts(res)
    assert R.runs_per_flank(flanks) == R.runs_per_flank(ref.impact_flank)
    # the end state and the dissipated energies
    assert abs(res["xi"][-1] - ref.final_y[0]) <= 1e-3 * G
    assert res["E_contact"][-1] == pytest.approx(ref.final_y[2], rel=1e-3)
    assert res["E_lubricant"][-1] == pytest.approx(ref.final_y[3], rel=1e-3)


def test_sine_s2_statistics(fmu_run):
    """S2 is chaotic beyond ~80 ms: compare impact rates and run lengths over 0.2-1 s."""
    res = fmu_run("sine", "S2", 1.0, DT)
    ref = R.scene("S2", 1.0)
    _check_times(res, 1.0)
    flanks, idx = fmu_impacts(res)
    t_imp = res["time"][idx]
    rt = R.rates(t_imp, flanks, 0.2, 1.0)
    rr = R.rates(ref.impact_t, ref.impact_flank, 0.2, 1.0)
    for fl in (R.FPLUS, R.FMINUS):
        assert rt[fl] == pytest.approx(rr[fl], rel=0.06), (rt, rr)
    assert sum(rt.values()) == pytest.approx(sum(rr.values()), rel=0.03), (rt, rr)
    sel = t_imp >= 0.2
    runs = np.array([n for _, n in R.runs(flanks[sel])])
    assert set(runs.tolist()) <= {2, 3}, R.runs(flanks[sel])
    assert 0.02 <= np.mean(runs == 3) <= 0.25, np.bincount(runs)
    assert math.isfinite(res["E_contact"][-1]) and res["E_contact"][-1] > 0


# ---------------------------------------------------------------------------------------
# Every parameter reaches the physics; tolerance; relative coordinates; step sizes
# ---------------------------------------------------------------------------------------

PARAMETER_SETS = [
    dict(B=0.01),
    dict(omega_S=5.0),
    dict(omega_mean=100.0),  # drag presses the gear on F+ (a driven gear, no rattle)
    dict(epsilon=0.0),
    dict(alpha=1.5, K_star=5e6),
    dict(gap_start=0.2, xi_dot_start=0.01),
    dict(gap_start=-0.1),  # starts in contact on F+
    dict(I_L=0.5e-3, r_L=0.04, r_M=0.03),
    dict(G=50e-6),
    dict(f_exc=45.0, A_rms=150.0),
]


@pytest.mark.parametrize("overrides", PARAMETER_SETS, ids=lambda d: ",".join(f"{k}={v:g}" for k, v in d.items()))
def test_sine_parameters_match_reference(fmu_run, overrides):
    """Off-default parameters (50 ms, default tolerance) against the reference."""
    p = R.params("S1", **overrides)
    g = p["G"]
    res = fmu_run("sine", "S1", 0.05, DT, **overrides)
    ref = R.simulate(p, 0.05, t_eval=np.arange(501) * DT)
    _check_times(res, 0.05)
    err = np.abs(res["xi"] - ref.xi)
    k = int(np.argmax(err))
    assert err[k] <= 1e-4 * g, f"max |dxi| = {err[k] / g:.3e} G at t = {res['time'][k]:.4f} s"
    assert_impacts_match(res, ref)
    for name in ("E_contact", "E_lubricant"):
        e_ref = getattr(ref, name)
        assert np.max(np.abs(res[name] - e_ref)) <= 1e-3 * e_ref[-1] + 1e-15, name
    np.testing.assert_allclose(p["r_L"] * res["theta_L"] - p["r_M"] * res["theta_M_out"], res["xi"], rtol=0, atol=1e-6 * g)
    np.testing.assert_allclose(res["F_contact"], R.contact_force(res["xi"], res["xi_dot"], p), rtol=0, atol=1e-9 * max(1.0, np.max(np.abs(res["F_contact"]))))


def test_sine_conservative_at_tight_tolerance(fmu_run):
    """C_LM = C = 0 (no dissipation: errors are not damped), at tolerance 1e-8."""
    ov = dict(C_LM=0.0, C=0.0)
    res = fmu_run("sine", "S1", 0.05, DT, tol=1e-8, **ov)
    ref = R.simulate(R.params("S1", **ov), 0.05, t_eval=np.arange(501) * DT)
    assert np.max(np.abs(res["xi"] - ref.xi)) <= 1e-4 * G
    assert_impacts_match(res, ref)
    assert np.all(res["E_contact"] == 0.0) and np.all(res["E_lubricant"] == 0.0)


@pytest.mark.parametrize("tol,bound", [(1e-8, 1e-5), (1e-10, 1e-6)])
def test_sine_tolerance_is_honoured(fmu_run, tol, bound):
    """A tighter tolerance (fmi2SetupExperiment) gives a more accurate xi."""
    res = fmu_run("sine", "S1", 0.05, DT, tol=tol)
    ref = R.scene("S1", 0.05, DT)
    err = np.max(np.abs(res["xi"] - ref.xi))
    assert err <= bound * G, f"tolerance {tol:g}: max |dxi| = {err / G:.2e} G"


def test_sine_shaft_at_speed_relative_coordinates(fmu_run):
    """omega_mean = 1000 rad/s (theta_M reaches 1000 rad in 1 s, r_M theta_M = 28 m) with the
    carrier shaft at the synchronous speed omega_S = omega_mean r_M / r_L: xi obeys exactly
    the equations of S1, so the whole second must match S1 (docs/MODEL.md §3: integrate a
    relative coordinate, not theta_L, or the micrometres are lost to cancellation)."""
    w = 1000.0
    ov = dict(omega_mean=w, omega_S=w * P["r_M"] / P["r_L"])
    res = fmu_run("sine", "S1", 1.0, DT, **ov)
    ref = R.scene("S1", 1.0)
    assert res["theta_M_out"][-1] == pytest.approx(w * 1.0, rel=1e-12)
    assert_impacts_match(res, ref, slack=1e-6)
    assert abs(res["xi"][-1] - ref.final_y[0]) <= 1e-3 * G
    assert res["E_contact"][-1] == pytest.approx(ref.final_y[2], rel=1e-3)
    assert res["E_lubricant"][-1] == pytest.approx(ref.final_y[3], rel=1e-3)


def test_sine_communication_steps_do_not_matter(slave, vrs):
    """canHandleVariableCommunicationStepSize: irregular steps (7 us to 2.3 ms) and one single
    50 ms step give the reference's xi and impact counts at the communication points."""
    rng = np.random.default_rng(20090801)
    hs = []
    while sum(hs) < 0.05 - 2.3e-3:
        hs.append(float(rng.choice([7e-6, 1e-5, 1.3e-4, 3.7e-4, 1e-3, 2.3e-3])))
    hs.append(0.05 - sum(hs))
    times = np.concatenate([[0.0], np.cumsum(hs)])
    ref = R.simulate(R.params("S1"), times[-1], t_eval=times)
    ints = [vrs["impacts_Fplus"], vrs["impacts_Fminus"]]

    fmu = slave("irregular", excitation=1)
    xi = [fmu.getReal([vrs["xi"]])[0]]
    counts = [fmu.getInteger(ints)]
    for t, h in zip(times[:-1], hs):
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        xi.append(fmu.getReal([vrs["xi"]])[0])
        counts.append(fmu.getInteger(ints))
    xi = np.array(xi)
    counts = np.array(counts)
    assert np.max(np.abs(xi - ref.xi)) <= 1e-4 * G
    n_plus, n_minus = ref.impact_counts(times)
    assert counts[:, 0].tolist() == n_plus.tolist()
    assert counts[:, 1].tolist() == n_minus.tolist()

    fmu = slave("one_step", excitation=1)
    fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=times[-1])
    assert fmu.getReal([vrs["xi"]])[0] == pytest.approx(ref.xi[-1], abs=1e-4 * G)
    assert fmu.getInteger(ints) == [int(n_plus[-1]), int(n_minus[-1])]


# ---------------------------------------------------------------------------------------
# Robustness: grazing contacts (a flank left and touched again within ~0.1 ms, by a few nm)
# ---------------------------------------------------------------------------------------

# Configurations of the paper's sweep (30-60 Hz, 100-700 rad/s^2 RMS) whose first 0.1 s
# contain grazing touches: (f_exc, A_rms, allowed difference of the impact counts)
GRAZING = [
    # leaves F- through G at 65.31 ms, 11.7 nm (4.7e-4 G) into the gap, back at 65.41 ms
    (30.0, 400.0, 0),
    # leaves F+ through 0 at 78.76 ms by 0.27 nm (1e-5 G, below the accuracy asked of the
    # FMU: whether it is seen is a matter of luck), back at 78.78 ms
    (32.0, 500.0, 1),
]


@pytest.mark.parametrize("f_exc,a_rms,slack", GRAZING)
@pytest.mark.parametrize("h", [1e-3, 1e-4])
def test_sine_grazing_touches(fmu_run, f_exc, a_rms, slack, h):
    """Grazing touches are integrated through (no fmi2Error) and counted as the reference does."""
    ov = dict(f_exc=f_exc, A_rms=a_rms)
    t_end = 0.1
    res = fmu_run("sine", "S1", t_end, h, **ov)
    ref = _ref_cached(f_exc, a_rms, t_end)
    n_plus, n_minus = ref.impact_counts([t_end])
    assert abs(int(res["impacts_Fplus"][-1]) - int(n_plus[0])) <= slack, (res["impacts_Fplus"][-1], n_plus[0])
    assert abs(int(res["impacts_Fminus"][-1]) - int(n_minus[0])) <= slack, (res["impacts_Fminus"][-1], n_minus[0])
    assert abs(res["xi"][-1] - ref.final_y[0]) <= 1e-3 * G


@functools.lru_cache(maxsize=None)
def _ref_cached(f_exc, a_rms, t_end):
    return R.simulate(R.params(f_exc=f_exc, A_rms=a_rms), t_end)


SWEEP = [(f, a) for f in (30.0, 36.0, 42.0, 48.0, 54.0, 60.0) for a in (100.0, 400.0, 700.0)]


def test_sine_paper_sweep_runs_through(fmu_run):
    """A subset of the paper's sweep, 0.3 s each at a 1 ms communication step: every run
    completes, rattles on both flanks and stays near the backlash band."""
    failures = []
    for f_exc, a_rms in SWEEP:
        try:
            res = fmu_run("sine", "S1", 0.3, 1e-3, f_exc=f_exc, A_rms=a_rms)
        except Exception as e:  # fmpy raises FMICallException on fmi2Error
            failures.append(f"f_exc={f_exc:g} A_rms={a_rms:g}: {e}")
            continue
        xi = res["xi"]
        if not (res["impacts_Fplus"][-1] > 0 and res["impacts_Fminus"][-1] > 0):
            failures.append(f"f_exc={f_exc:g} A_rms={a_rms:g}: no rattle")
        if not (xi.min() > -G and xi.max() < 2 * G):
            failures.append(f"f_exc={f_exc:g} A_rms={a_rms:g}: xi/G in [{xi.min() / G:.2f}, {xi.max() / G:.2f}]")
    assert not failures, "\n".join(failures)
