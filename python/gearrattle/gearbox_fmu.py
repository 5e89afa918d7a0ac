"""GearboxRattle.fmu run through fmpy, as the tests, the demo and the benchmark read it:
the contract's per-gear outputs (`gear[i].NAME`, docs/GEARBOX.md §7) gathered into arrays of one
row per gear."""

from __future__ import annotations

import pathlib

import numpy as np

from . import fmpy_run

ROOT = pathlib.Path(__file__).resolve().parents[2]  # the repository (python/gearrattle/..)
GEARBOX_FMU = ROOT / "target" / "fmu" / "GearboxRattle.fmu"

# The box's outputs every run records, and each gear's.
BOX_OUTPUTS = ("phi", "omega_I_out", "tau_F", "T_clutch", "damper_stage", "T_drag", "stat_rattle_power")
GEAR_OUTPUTS = ("xi", "xi_dot", "impacts_Fplus", "impacts_Fminus", "E_lubricant")
# What a run's statistics read at its end, per gear (docs/METRICS.md).
GEAR_STATS = (
    "stat_impact_rate_Fplus", "stat_impact_rate_Fminus", "stat_runs_Fplus", "stat_runs_Fminus",
    "stat_v_mean_Fplus", "stat_v_mean_Fminus", "stat_rattle_power", "stat_rattle_share",
)


def gear_names(n_gears: int, fields=GEAR_OUTPUTS) -> list:
    return [f"gear[{i}].{f}" for i in range(1, n_gears + 1) for f in fields]


def outputs(n_gears: int, gear_fields=GEAR_OUTPUTS) -> list:
    return list(BOX_OUTPUTS) + gear_names(n_gears, gear_fields)


def simulate(fmu, t_end: float, dt: float = 1e-4, fmi_type: str = "CoSimulation", tol: float | None = None,
             inputs=None, gear_fields=GEAR_OUTPUTS, model_description=None, **start):
    """Run the box from 0 to t_end with the start values `start` (contract names, an int sets
    an Integer), its outputs and each gear's `gear_fields` every dt (see fmpy_run.simulate)."""
    n = int(start.get("n_gears", 5))
    return fmpy_run.simulate(fmu, t_end, dt, outputs(n, gear_fields), fmi_type, tol, inputs, model_description, **start)


def per_gear(result, field: str) -> np.ndarray:
    """gear[i].field of every gear in `result`, one row per gear: (N, len(time))."""
    names = result.dtype.names
    n = sum(1 for s in names if s.endswith(f"].{field}"))
    return np.array([result[f"gear[{i}].{field}"] for i in range(1, n + 1)])


def impact_counts(result) -> np.ndarray:
    """Cumulative impacts per gear, both flanks: (N, len(time))."""
    return per_gear(result, "impacts_Fplus") + per_gear(result, "impacts_Fminus")
