"""An FMU of the workspace run through fmpy from 0 to t_end with its outputs every dt, in
either interface, as the tests, the demos and the benchmarks run it."""

from __future__ import annotations

import numpy as np


def simulate(fmu, t_end: float, dt: float, output, fmi_type: str = "CoSimulation", tol: float | None = None,
        inputs=None, model_description=None, **start):
    """The outputs `output` from 0 to t_end every dt, with the start values `start` (an int
    sets an Integer); `fmu` a path or an extracted directory. Co-Simulation: communication
    step dt, `tol` to fmi2SetupExperiment (None: the model description's default); Model
    Exchange: fmpy's CVode at the relative tolerance `tol`, the rows fmpy adds at events left
    out (on_grid). inputs: fmpy's structured input array."""
    from fmpy import simulate_fmu

    res = simulate_fmu(
        str(fmu),
        model_description=model_description,
        fmi_type=fmi_type,
        solver="CVode",
        start_time=0.0,
        stop_time=t_end,
        start_values=start,
        input=inputs,
        step_size=dt,
        output_interval=dt,
        relative_tolerance=tol,
        output=list(output),
    )
    return res if fmi_type == "CoSimulation" else on_grid(res, dt)


def on_grid(result, dt: float):
    """The rows of `result` at the output times k dt, the last one where an event repeats a
    time."""
    k = result["time"] / dt
    on = np.abs(k - np.round(k)) < 1e-6
    last = np.append(result["time"][1:] != result["time"][:-1], True)
    return result[on & last]
