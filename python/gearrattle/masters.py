"""The coupled pair GearRattle + Flywheel run by three co-simulation masters that no one here
wrote the stepping of: a hand-written Jacobi loop on fmpy's FMU2Slave, libcosim (PyPI
libcosimpy) and Ecos (PyPI ecospy). Each `run_*` returns the same record, sampled at the
communication points t_n = n h: time, theta_M, omega_M, alpha_M (the Flywheel's outputs),
tau_M, xi, impacts_Fplus, impacts_Fminus (GearRattle's).

Connections (names as in both model descriptions):
    Flywheel.theta_M -> GearRattle.theta_M     Flywheel.omega_M -> GearRattle.omega_M
    Flywheel.alpha_M -> GearRattle.alpha_M     GearRattle.tau_M -> Flywheel.tau_M
GearRattle starts with its loose gear at rest in the backlash relative to the shaft
(xi_dot = 0), so its omega_M input must hold the shaft's idle speed before
fmi2ExitInitializationMode (set later, it would move the shaft under the resting loose gear:
xi_dot would jump by -r_M omega_M, 2.4 m/s). libcosim and Ecos pass the connected values in
initialisation mode by themselves; the fmpy loop exchanges once before leaving it.
"""

from __future__ import annotations

import math
import pathlib

import numpy as np

from . import monolithic as M

ROOT = pathlib.Path(__file__).resolve().parents[2]  # the repository (python/gearrattle/..)
GEAR_FMU = ROOT / "target" / "fmu" / "GearRattle.fmu"
FLYWHEEL_FMU = ROOT / "target" / "fmu" / "Flywheel.fmu"

FIELDS = ("time", "theta_M", "omega_M", "alpha_M", "tau_M", "xi", "impacts_Fplus", "impacts_Fminus")
FLYWHEEL_OUT = ("theta_M", "omega_M", "alpha_M")
GEAR_OUT = ("tau_M", "xi")
GEAR_COUNTS = ("impacts_Fplus", "impacts_Fminus")
OMEGA_IDLE = M.FLYWHEEL["omega_idle"]
# The coupled run of the tests: 0.5 s at 0.1 ms communication steps.
T_TEST, H_TEST = 0.5, 1e-4


def _vrs(fmu) -> dict:
    from fmpy import read_model_description

    return {v.name: v.valueReference for v in read_model_description(str(fmu)).modelVariables}


def can_interpolate_inputs(fmu=GEAR_FMU) -> bool:
    """Whether the model description declares canInterpolateInputs (fmi2SetRealInputDerivatives)."""
    from fmpy import read_model_description

    return bool(read_model_description(str(fmu)).coSimulation.canInterpolateInputs)


def max_output_derivative_order(fmu=GEAR_FMU) -> int:
    from fmpy import read_model_description

    return int(read_model_description(str(fmu)).coSimulation.maxOutputDerivativeOrder or 0)


def _record(n: int) -> dict:
    return {f: np.zeros(n + 1, dtype=np.int64 if f.startswith("impacts") else float) for f in FIELDS}


def _steps(t_end: float, h: float) -> int:
    n = int(round(t_end / h))
    if not math.isclose(n * h, t_end, rel_tol=1e-9):
        raise ValueError(f"t_end = {t_end} is not a multiple of h = {h}")
    return n


# ----------------------------------------------------------------------------------------
# fmpy: a hand-written Jacobi master on FMU2Slave
# ----------------------------------------------------------------------------------------

#: What the fmpy master exchanges besides theta_M, omega_M (to GearRattle) and tau_M (back):
#: "alpha": alpha_M too, as an input (GearRattle extrapolates the shaft quadratically); what
#:   the libcosim and Ecos runs connect;
#: "linear": nothing more (alpha_M stays 0: a linear extrapolation of the shaft);
#: "derivatives": the time derivatives of theta_M and omega_M, read with the Flywheel's
#:   fmi2GetRealOutputDerivatives and passed with fmi2SetRealInputDerivatives (theta_M orders
#:   1 and 2, omega_M order 1); alpha_M unconnected. Needs GearRattle's canInterpolateInputs;
#: "derivatives+tau": as "derivatives", and d tau_M / dt from GearRattle's
#:   fmi2GetRealOutputDerivatives into the Flywheel (a ramp of tau_M over the step instead of
#:   a hold). Needs also GearRattle's maxOutputDerivativeOrder >= 1.
INPUT_MODES = ("alpha", "linear", "derivatives", "derivatives+tau")


def run_fmpy(t_end: float, h: float, inputs: str = "alpha", gear_params: dict | None = None, tolerance: float | None = None) -> dict:
    """Jacobi stepping: at each t_n the outputs are exchanged in dependency order (Flywheel's
    theta_M, omega_M -> GearRattle -> its tau_M -> Flywheel -> its alpha_M -> GearRattle), then
    both FMUs step from t_n to t_n + h with what they were given. `tolerance` goes to
    GearRattle's fmi2SetupExperiment (None: its default)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    if inputs not in INPUT_MODES:
        raise ValueError(f"inputs must be one of {INPUT_MODES}")
    if inputs.startswith("derivatives") and not can_interpolate_inputs():
        raise RuntimeError("GearRattle does not declare canInterpolateInputs: no input derivatives")
    if inputs == "derivatives+tau" and max_output_derivative_order() < 1:
        raise RuntimeError("GearRattle does not declare maxOutputDerivativeOrder >= 1: no d tau_M / dt")
    gear_params = {**M.GEAR, **(gear_params or {})}
    n = _steps(t_end, h)
    slaves = []
    vrs = {}
    for name, fmu in (("gear", GEAR_FMU), ("flywheel", FLYWHEEL_FMU)):
        md = read_model_description(str(fmu))
        vrs[name] = {v.name: v.valueReference for v in md.modelVariables}
        slave = FMU2Slave(
            guid=md.guid,
            unzipDirectory=extract(str(fmu)),
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        slave.instantiate()
        slaves.append(slave)
    gear, fw = slaves
    g, f = vrs["gear"], vrs["flywheel"]
    rec = _record(n)
    try:
        gear.setupExperiment(tolerance=tolerance, startTime=0.0)
        fw.setupExperiment(startTime=0.0)
        for s in slaves:
            s.enterInitializationMode()
        gear.setReal([g[k] for k in gear_params], list(gear_params.values()))

        def exchange():
            shaft = fw.getReal([f[k] for k in FLYWHEEL_OUT])
            gear.setReal([g["theta_M"], g["omega_M"]], shaft[:2])
            fw.setReal([f["tau_M"]], gear.getReal([g["tau_M"]]))
            alpha = fw.getReal([f["alpha_M"]])[0]
            if inputs == "alpha":
                gear.setReal([g["alpha_M"]], [alpha])
            return [shaft[0], shaft[1], alpha]

        exchange()  # initial values, in initialisation mode
        for s in slaves:
            s.exitInitializationMode()
        t = 0.0
        for k in range(n + 1):
            shaft = exchange()
            if inputs.startswith("derivatives"):
                d_theta, d_omega = fw.getRealOutputDerivatives([f["theta_M"], f["omega_M"]], [1, 1])
                gear.setRealInputDerivatives([g["theta_M"], g["theta_M"], g["omega_M"]], [1, 2, 1], [d_theta, d_omega, d_omega])
            if inputs == "derivatives+tau":
                fw.setRealInputDerivatives([f["tau_M"]], [1], gear.getRealOutputDerivatives([g["tau_M"]], [1]))
            rec["time"][k] = t
            rec["theta_M"][k], rec["omega_M"][k], rec["alpha_M"][k] = shaft
            rec["tau_M"][k], rec["xi"][k] = gear.getReal([g[x] for x in GEAR_OUT])
            rec["impacts_Fplus"][k], rec["impacts_Fminus"][k] = gear.getInteger([g[x] for x in GEAR_COUNTS])
            if k == n:
                break
            fw.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            gear.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            t = (k + 1) * h
        for s in slaves:
            s.terminate()
    finally:
        for s in slaves:
            s.freeInstance()
    return rec


# ----------------------------------------------------------------------------------------
# libcosim (Open Simulation Platform): its fixed-step algorithm, time in nanoseconds
# ----------------------------------------------------------------------------------------


def run_libcosim(t_end: float, h: float, gear_params: dict | None = None) -> dict:
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    gear_params = {**M.GEAR, **(gear_params or {})}
    n = _steps(t_end, h)
    h_ns = int(round(h * 1e9))
    if not math.isclose(h_ns * 1e-9, h, rel_tol=1e-12):
        raise ValueError(f"h = {h} is not a whole number of nanoseconds")
    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_step_size(step_size=h_ns)
    gi = ex.add_local_slave(CosimLocalSlave(fmu_path=str(GEAR_FMU), instance_name="gear"))
    fi = ex.add_local_slave(CosimLocalSlave(fmu_path=str(FLYWHEEL_FMU), instance_name="flywheel"))
    if gi < 0 or fi < 0:
        raise RuntimeError("libcosim could not load the FMUs")
    g, f = _vrs(GEAR_FMU), _vrs(FLYWHEEL_FMU)
    for name, value in gear_params.items():
        assert ex.real_initial_value(gi, g[name], value), name
    for name in FLYWHEEL_OUT:
        assert ex.connect_real_variables(fi, f[name], gi, g[name]) == 0, name
    assert ex.connect_real_variables(gi, g["tau_M"], fi, f["tau_M"]) == 0
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    rec = _record(n)

    def sample(k):
        rec["time"][k] = ex.status().current_time * 1e-9
        rec["theta_M"][k], rec["omega_M"][k], rec["alpha_M"][k] = obs.last_real_values(fi, [f[x] for x in FLYWHEEL_OUT])
        rec["tau_M"][k], rec["xi"][k] = obs.last_real_values(gi, [g[x] for x in GEAR_OUT])
        rec["impacts_Fplus"][k], rec["impacts_Fminus"][k] = obs.last_integer_values(gi, [g[x] for x in GEAR_COUNTS])

    assert ex.step(), "libcosim: the first step failed"  # initialisation happens in the first step
    sample(1)
    for k in range(2, n + 1):
        if not ex.step():
            raise RuntimeError(f"libcosim: step {k} failed")
        sample(k)
    # t = 0: the initial state (the observer only sees values after a step)
    rec["time"][0] = 0.0
    rec["theta_M"][0], rec["omega_M"][0] = 0.0, OMEGA_IDLE
    rec["alpha_M"][0], rec["tau_M"][0] = np.nan, np.nan
    rec["xi"][0] = M.gear_params(**gear_params)["gap_start"] * M.gear_params(**gear_params)["G"]
    ex.stop()
    return rec


# ----------------------------------------------------------------------------------------
# Ecos: its fixed-step algorithm on a simulation structure
# ----------------------------------------------------------------------------------------


def run_ecos(t_end: float, h: float, gear_params: dict | None = None) -> dict:
    from ecospy import EcosLib, EcosSimulation, EcosSimulationStructure

    gear_params = {**M.GEAR, **(gear_params or {})}
    n = _steps(t_end, h)
    EcosLib.set_log_level("warn")
    rec = _record(n)
    with EcosSimulationStructure() as ss:
        ss.add_model("gear", str(GEAR_FMU))
        ss.add_model("flywheel", str(FLYWHEEL_FMU))
        for name in FLYWHEEL_OUT:
            ss.make_real_connection(f"flywheel::{name}", f"gear::{name}")
        ss.make_real_connection("gear::tau_M", "flywheel::tau_M")
        ss.add_parameter_set("initialValues", {f"gear::{k}": float(v) for k, v in gear_params.items()})
        with EcosSimulation(structure=ss, step_size=h) as sim:
            if sim.init(parameter_set="initialValues") is False:
                raise RuntimeError(f"Ecos: init failed: {EcosLib.get_last_error()}")

            def sample(k):
                rec["time"][k] = sim.get_time()
                for x in FLYWHEEL_OUT:
                    rec[x][k] = sim.get_real(f"flywheel::{x}")
                for x in GEAR_OUT:
                    rec[x][k] = sim.get_real(f"gear::{x}")
                for x in GEAR_COUNTS:
                    rec[x][k] = sim.get_integer(f"gear::{x}")

            sample(0)
            for k in range(1, n + 1):
                sim.step()
                sample(k)
            sim.terminate()
    return rec


MASTERS = {"fmpy": run_fmpy, "libcosim": run_libcosim, "ecos": run_ecos}


# ----------------------------------------------------------------------------------------
# Comparison with the monolithic reference
# ----------------------------------------------------------------------------------------


def impact_rate(rec: dict, t0: float, t1: float) -> float:
    """Impacts per second (both flanks) over [t0, t1] from the sampled counters."""
    t = rec["time"]
    i0, i1 = np.searchsorted(t, t0 - 1e-12), np.searchsorted(t, t1 - 1e-12)
    total = rec["impacts_Fplus"] + rec["impacts_Fminus"]
    return float(total[i1] - total[i0]) / (t[i1] - t[i0])


def compare(rec: dict, ref: M.Result, t0: float = 0.0) -> dict:
    """Errors of a co-simulated run against the reference sampled at the same times: the
    largest |omega_M| difference and the relative error of the impact rate over [t0, t_end]."""
    t = rec["time"]
    if ref.t.size != t.size or np.max(np.abs(ref.t - t)) > 1e-9:
        raise ValueError("the reference is not sampled at the run's communication points")
    sel = t >= t0
    d_omega = float(np.max(np.abs(rec["omega_M"][sel] - ref.omega_M[sel])))
    n_ref = sum(c[-1] - c[np.argmax(sel)] for c in ref.impact_counts(t))
    rate_ref = n_ref / (t[-1] - t[sel][0])
    rate = impact_rate(rec, t[sel][0], t[-1])
    return dict(omega_M=d_omega, rate=rate, rate_ref=rate_ref, rate_rel=abs(rate - rate_ref) / rate_ref)
