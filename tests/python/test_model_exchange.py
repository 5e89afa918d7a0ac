"""Model Exchange: the same GearRattle.fmu integrated by fmpy's CVode (BDF with event
handling) against the independent reference, against its own co-simulation, and refusing
misuse through the Model Exchange calls."""

import ctypes

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.fmi2 import FMU2Model, fmi2Error, fmi2EventInfo, fmi2OK

from gearrattle import reference as R

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
    the impacts of the reference over 0.1 s (28, both flanks)."""
    from support.fmu import main_shaft_input
    inp = main_shaft_input("S1", 0.1, 1e-5, ("theta_M", "omega_M"))
    res = simulate_fmu(unzipdir, model_description=model_description, fmi_type="ModelExchange",
                       solver="CVode", stop_time=0.1, output_interval=1e-5, relative_tolerance=1e-9,
                       input=inp, output=["impacts_Fplus", "impacts_Fminus"])
    ref = R.scene("S1", 0.1)
    assert (res["impacts_Fplus"][-1], res["impacts_Fminus"][-1]) == tuple(int(n[0]) for n in ref.impact_counts([0.1]))


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


# ---------------------------------------------------------------------------------------
# fmi2GetDirectionalDerivative in Model Exchange: the analytic Jacobian of the derivatives
# ---------------------------------------------------------------------------------------

# The drive modes with every parameter that enters the Jacobian switched on (drag, carrier
# speed, external torque, contact damping) and ξ' ≠ 0.
MODES = {
    "inputs": dict(excitation=0, theta_M=4.5, omega_M=83.0),
    "sine": dict(excitation=1),
    "torque": dict(excitation=2, tau_in=2.0, omega_M=83.0),
}
# The statistics window open from the start, so that the stat_* outputs' partials are checked.
PHYSICS = dict(B=0.3, omega_S=12.0, xi_dot_start=0.02, stats_from=0.0)
# ξ in contact on F+, in its band, in the gap, in F-'s band, in contact on F-.
XIS = [-3e-6, -0.6e-6, 10e-6, G + 0.3e-6, G + 4e-6]


def me_instance(unzipdir, model_description, **start):
    """A Model Exchange instance initialised with `start` and in continuous-time mode."""
    vrs = {v.name: v.valueReference for v in model_description.modelVariables}
    fmu = FMU2Model(guid=model_description.guid, unzipDirectory=unzipdir,
                    modelIdentifier=model_description.modelExchange.modelIdentifier, instanceName="jacobian")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    for name, value in start.items():
        if name == "excitation":
            fmu.setInteger([vrs[name]], [value])
        else:
            fmu.setReal([vrs[name]], [value])
    fmu.exitInitializationMode()
    while fmu.newDiscreteStates()[0]:
        pass
    fmu.enterContinuousTimeMode()
    return fmu


class Rhs:
    """The FMU's right-hand side f(t, x) and its Jacobian ∂f/∂x through the Model Exchange
    calls, counting the evaluations."""

    def __init__(self, fmu, model_description):
        self.fmu = fmu
        self.states = [u.variable.derivative.valueReference for u in model_description.derivatives]
        self.derivatives = [u.variable.valueReference for u in model_description.derivatives]
        self.nx = len(self.states)
        self.evaluations = self.jacobians = 0

    def set(self, t, x):
        self.fmu.setTime(t)
        self.fmu.setContinuousStates((ctypes.c_double * self.nx)(*x), self.nx)

    def states_now(self):
        x = (ctypes.c_double * self.nx)()
        self.fmu.getContinuousStates(x, self.nx)
        return np.array(x)

    def derivatives_now(self):
        dx = (ctypes.c_double * self.nx)()
        self.fmu.getDerivatives(dx, self.nx)
        return np.array(dx)

    def f(self, t, x):
        self.evaluations += 1
        self.set(t, x)
        return self.derivatives_now()

    def column(self, known):
        """∂ẋ/∂known, by fmi2GetDirectionalDerivative with a unit seed."""
        return np.array(self.fmu.getDirectionalDerivative(self.derivatives, [known], [1.0]))

    def jac(self, t, x):
        self.jacobians += 1
        self.set(t, x)
        return np.column_stack([self.column(s) for s in self.states])


def settle(fmu):
    """An event iteration, so that the pair's region (behind the outputs) follows ξ."""
    fmu.enterEventMode()
    while fmu.newDiscreteStates()[0]:
        pass
    fmu.enterContinuousTimeMode()


def agree(exact, fd, scale, h):
    """The analytic entries against central differences: 1e-5 relative, plus the rounding of
    the differenced values (of size `scale`) over the step h."""
    tol = 1e-5 * np.maximum(np.abs(exact), np.abs(fd)) + 8 * np.finfo(float).eps * scale / h + 1e-9
    return np.abs(exact - fd) <= tol


OUTPUTS_CHECKED = ["theta_L", "omega_L", "alpha_L", "a_pitch_L", "xi_dot", "F_contact", "tau_M", "omega_M_out",
                   "stat_a_rms", "stat_F_std", "stat_P_contact", "stat_P_lubricant", "stat_v_mean_Fplus"]
# The quadratures (E_contact, E_lubricant, W_shaft, ∫a², ∫F, ∫F²) at the point: the window's
# statistics non-zero, ∫F² above (∫F)²/t for a positive variance of F.
QUADRATURES = [0.1, 0.2, 0.3, 0.4, 0.5, 30.0]


@pytest.mark.parametrize("mode", MODES)
def test_directional_derivative_matches_differences_of_derivatives(unzipdir, model_description, mode):
    """At ξ in each region of the contact law: ∂ẋ/∂x and ∂ẋ/∂u (θ_M, ω_M in the inputs
    mode, τ_in in the torque mode) and the outputs' partials from fmi2GetDirectionalDerivative
    against central differences of fmi2GetDerivatives and fmi2GetReal, the states moved by
    fmi2SetContinuousStates and the inputs by fmi2SetReal, as an importer does."""
    vrs = {v.name: v.valueReference for v in model_description.modelVariables}
    fmu = me_instance(unzipdir, model_description, **MODES[mode], **PHYSICS)
    rhs = Rhs(fmu, model_description)
    outputs = [vrs[o] for o in OUTPUTS_CHECKED]
    inputs = {"inputs": ["theta_M", "omega_M"], "torque": ["tau_in"], "sine": []}[mode]
    t = 0.0123
    try:
        fmu.setTime(t)
        for xi in XIS:
            x = rhs.states_now()
            x[0] = xi
            x[-len(QUADRATURES):] = QUADRATURES
            rhs.set(t, x)
            settle(fmu)

            def unknowns():
                return np.concatenate([rhs.derivatives_now(), fmu.getReal(outputs)])

            # Known: (value reference, step, how to move it by d).
            knowns = []
            for k, s in enumerate(rhs.states):
                step = 1e-10 if k == 0 else 1e-6 * max(1.0, abs(x[k]))
                knowns.append((s, step, lambda d, k=k: rhs.set(t, x + d * np.eye(rhs.nx)[k])))
            for name in inputs:
                value = fmu.getReal([vrs[name]])[0]
                knowns.append((vrs[name], 1e-6, lambda d, name=name, value=value: fmu.setReal([vrs[name]], [value + d])))
            for known, h, move in knowns:
                exact = np.array(fmu.getDirectionalDerivative(rhs.derivatives + outputs, [known], [1.0]))
                move(h)
                up = unknowns()
                move(-h)
                down = unknowns()
                move(0.0)
                fd = (up - down) / (2 * h)
                ok = agree(exact, fd, np.maximum(np.abs(up), np.abs(down)), h)
                assert ok.all(), (mode, xi, known, np.nonzero(~ok)[0], exact[~ok], fd[~ok])
    finally:
        fmu.terminate()
        fmu.freeInstance()


def test_derivatives_dependencies_are_the_jacobians_pattern(unzipdir, model_description):
    """ModelStructure/Derivatives as fmpy reads it: each derivative depends on exactly the
    states and inputs whose column of fmi2GetDirectionalDerivative is non-zero at some ξ of
    XIS in some mode."""
    vrs = {v.name: v.valueReference for v in model_description.modelVariables}
    knowns = [u.variable.derivative.name for u in model_description.derivatives]
    knowns += [v.name for v in model_description.modelVariables if v.causality == "input"]
    ders = [u.variable.valueReference for u in model_description.derivatives]
    moved = np.zeros((len(ders), len(knowns)), dtype=bool)
    for mode in MODES:
        fmu = me_instance(unzipdir, model_description, **MODES[mode], **PHYSICS)
        rhs = Rhs(fmu, model_description)
        try:
            for xi in XIS:
                x = rhs.states_now()
                x[0] = xi
                rhs.set(0.0123, x)
                for j, name in enumerate(knowns):
                    moved[:, j] |= rhs.column(vrs[name]) != 0.0
        finally:
            fmu.terminate()
            fmu.freeInstance()
    for i, u in enumerate(model_description.derivatives):
        declared = sorted(d.name for d in u.dependencies)
        assert declared == sorted(np.array(knowns)[moved[i]]), u.variable.name


def test_directional_derivative_refuses_misuse(unzipdir, model_description, model):
    """Before initialisation, a known that is neither a state nor an input, an unknown that
    is neither a derivative nor an output (nor one given), a seed that is not finite: each
    refused with fmi2Error, the instance usable afterwards."""
    vrs = {v.name: v.valueReference for v in model_description.modelVariables}
    u = (ctypes.c_uint * 1)(vrs["der(xi)"])
    out = (ctypes.c_double * 1)()

    def directional(unknown, known, seed=1.0):
        u[0] = unknown
        return call(model, "fmi2GetDirectionalDerivative", u, 1, (ctypes.c_uint * 1)(known), 1,
                    (ctypes.c_double * 1)(seed), out)

    assert directional(vrs["der(xi)"], vrs["omega_L"]) == fmi2Error  # instantiated
    model.setupExperiment(startTime=0.0)
    model.enterInitializationMode()
    model.exitInitializationMode()
    model.enterContinuousTimeMode()
    assert directional(vrs["der(xi)"], vrs["I_L"]) == fmi2Error  # a parameter
    assert directional(vrs["der(xi)"], vrs["F_contact"]) == fmi2Error  # an output, not a state
    assert directional(vrs["x_theta_M"], vrs["omega_L"]) == fmi2Error  # a state, not a derivative
    assert directional(vrs["I_L"], vrs["omega_L"]) == fmi2Error  # a parameter as unknown
    assert directional(vrs["der(xi)"], vrs["omega_L"], float("nan")) == fmi2Error
    assert directional(vrs["der(xi)"], vrs["omega_L"], 2.0) == fmi2OK
    assert out[0] == pytest.approx(2 * R.DEFAULTS["r_L"], rel=1e-15)


def test_bdf_with_the_jacobian_needs_fewer_evaluations(unzipdir, model_description):
    """scipy's BDF on the stiff I_L = 1e-8 (S1's sine, 5 ms, through contacts, no event
    handling: the derivatives are smooth across the edges), once with the Jacobian from
    fmi2GetDirectionalDerivative and once with its own finite differences: the same end
    state, with fewer evaluations of the right-hand side. The counts are printed."""
    from scipy.integrate import solve_ivp

    runs = {}
    for name in ("directional derivatives", "finite differences"):
        fmu = me_instance(unzipdir, model_description, excitation=1, I_L=1e-8)
        rhs = Rhs(fmu, model_description)
        try:
            x0 = rhs.states_now()
            atol = np.array([1e-6 * G, 1e-3] + [1e-3] * (rhs.nx - 2))
            jac = rhs.jac if name == "directional derivatives" else None
            sol = solve_ivp(rhs.f, (0.0, 0.005), x0, method="BDF", rtol=1e-6, atol=atol, jac=jac)
            assert sol.success, sol.message
            runs[name] = (sol.y[:, -1], rhs.evaluations, rhs.jacobians, sol.njev, sol.nlu, sol.t.size - 1)
        finally:
            fmu.terminate()
            fmu.freeInstance()
    for name, (_, evaluations, jacobians, njev, nlu, steps) in runs.items():
        print(f"BDF, I_L = 1e-8, 5 ms, {name}: {evaluations} evaluations of f, {njev} Jacobians "
              f"({jacobians * len(model_description.derivatives)} directional derivatives), {nlu} LU, {steps} steps")
    exact, fd = runs["directional derivatives"], runs["finite differences"]
    assert abs(exact[0][0] - fd[0][0]) <= 1e-4 * G
    assert exact[1] < fd[1]
