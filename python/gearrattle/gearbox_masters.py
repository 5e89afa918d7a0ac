"""GearboxRattle coupled with the Flywheel partner by libcosim and by Ecos (as
gearrattle.masters couples GearRattle): the box in excitation 0, its flywheel driven by the
partner's shaft and its torque back.

Connections:
    Flywheel.theta_M -> GearboxRattle.theta_F   Flywheel.omega_M -> GearboxRattle.omega_F
    Flywheel.alpha_M -> GearboxRattle.alpha_F   GearboxRattle.tau_F -> Flywheel.tau_M
Each run returns, at the communication points t_n = n h (n >= 1: the masters' observers see
values after a step), time, omega_F, phi, tau_F and the per-gear impact counts (N, n)."""

from __future__ import annotations

import numpy as np

from .gearbox_fmu import GEARBOX_FMU
from .masters import FLYWHEEL_FMU, _steps, _vrs

LINKS = (("theta_M", "theta_F"), ("omega_M", "omega_F"), ("alpha_M", "alpha_F"))
BOX_REAL = ("phi", "tau_F")
START = {"excitation": 0}


def _counts(n_gears: int) -> list:
    return [f"gear[{i}].impacts_{f}" for i in range(1, n_gears + 1) for f in ("Fplus", "Fminus")]


def _record(rows: list, n_gears: int) -> dict:
    a = np.array(rows, dtype=float)
    c = a[:, 4:].reshape(len(rows), n_gears, 2).sum(axis=2).T.astype(np.int64)
    return dict(time=a[:, 0], omega_F=a[:, 1], phi=a[:, 2], tau_F=a[:, 3], impacts=c)


def run_libcosim(t_end: float, h: float, n_gears: int = 5) -> dict:
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    n = _steps(t_end, h)
    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_step_size(step_size=int(round(h * 1e9)))
    bi = ex.add_local_slave(CosimLocalSlave(fmu_path=str(GEARBOX_FMU), instance_name="box"))
    fi = ex.add_local_slave(CosimLocalSlave(fmu_path=str(FLYWHEEL_FMU), instance_name="flywheel"))
    if bi < 0 or fi < 0:
        raise RuntimeError("libcosim could not load the FMUs")
    b, f = _vrs(GEARBOX_FMU), _vrs(FLYWHEEL_FMU)
    for name, value in {**START, "n_gears": n_gears}.items():
        assert ex.integer_initial_value(bi, b[name], value), name
    for src, dst in LINKS:
        assert ex.connect_real_variables(fi, f[src], bi, b[dst]) == 0, dst
    assert ex.connect_real_variables(bi, b["tau_F"], fi, f["tau_M"]) == 0
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    rows = []
    for k in range(1, n + 1):
        if not ex.step():
            raise RuntimeError(f"libcosim: step {k} failed")
        omega = obs.last_real_values(fi, [f["omega_M"]])
        real = obs.last_real_values(bi, [b[x] for x in BOX_REAL])
        counts = obs.last_integer_values(bi, [b[x] for x in _counts(n_gears)])
        rows.append([ex.status().current_time * 1e-9, *omega, *real, *counts])
    ex.stop()
    return _record(rows, n_gears)


def run_ecos(t_end: float, h: float, n_gears: int = 5) -> dict:
    from ecospy import EcosLib, EcosSimulation, EcosSimulationStructure

    n = _steps(t_end, h)
    EcosLib.set_log_level("warn")
    rows = []
    with EcosSimulationStructure() as ss:
        ss.add_model("box", str(GEARBOX_FMU))
        ss.add_model("flywheel", str(FLYWHEEL_FMU))
        for src, dst in LINKS:
            ss.make_real_connection(f"flywheel::{src}", f"box::{dst}")
        ss.make_real_connection("box::tau_F", "flywheel::tau_M")
        ss.add_parameter_set("initialValues", {f"box::{k}": v for k, v in {**START, "n_gears": n_gears}.items()})
        with EcosSimulation(structure=ss, step_size=h) as sim:
            if sim.init(parameter_set="initialValues") is False:
                raise RuntimeError(f"Ecos: init failed: {EcosLib.get_last_error()}")
            for _ in range(n):
                sim.step()
                real = [sim.get_real(f"box::{x}") for x in BOX_REAL]
                counts = [sim.get_integer(f"box::{x}") for x in _counts(n_gears)]
                rows.append([sim.get_time(), sim.get_real("flywheel::omega_M"), *real, *counts])
            sim.terminate()
    return _record(rows, n_gears)


MASTERS = {"libcosim": run_libcosim, "ecos": run_ecos}
