"""The gearbox benchmark (`make bench-gearbox`, docs/GEARBOX.md's benchmark section): what the
coupled box costs against its gears stepped one by one as GearRattle instances on the same
input-side motion, against scipy on the same equations at equal error, over a rattle map,
and against the number of gears. Wall times on this machine; no assertion."""

from __future__ import annotations

import time

import numpy as np

from gearrattle import gearbox_fmu as GF
from gearrattle import gearbox_reference as R
from gearrattle.masters import GEAR_FMU

T_END, H = 2.0, 1e-4
WINDOW = 0.35  # B1's pointwise-predictable window: errors are measured over it
SHARED = ("I_L", "r_L", "r_M", "G", "K_star", "alpha", "epsilon", "C_LM", "C", "B", "gap_start")


class Stepper:
    """An FMU2Slave stepped by hand at H, its outputs read by name after each step."""

    def __init__(self, fmu, name, start: dict, tol=None):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave

        md = read_model_description(str(fmu))
        self.vrs = {v.name: v.valueReference for v in md.modelVariables}
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu)),
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate()
        self.fmu.setupExperiment(tolerance=tol, startTime=0.0)
        self.fmu.enterInitializationMode()
        for k, v in start.items():
            (self.fmu.setInteger if isinstance(v, int) else self.fmu.setReal)([self.vrs[k]], [v])

    def refs(self, names):
        return [self.vrs[n] for n in names]


def coupled_box(t_end=T_END, names=("theta_I_out", "omega_I_out", "alpha_I_out"), h=H, tol=None, **start):
    """The box (by default the defaults, excitation 1) stepped at h: the wall time [s] of the
    steps and the outputs `names` at every communication point, (steps + 1, len(names))."""
    s = Stepper(GF.GEARBOX_FMU, "box", start, tol)
    s.fmu.exitInitializationMode()
    refs = s.refs(names)
    n = int(round(t_end / h))
    rec = np.empty((n + 1, len(names)))
    rec[0] = s.fmu.getReal(refs)
    t0 = time.perf_counter()
    for k in range(n):
        s.fmu.doStep(k * h, h)
        rec[k + 1] = s.fmu.getReal(refs)
    wall = time.perf_counter() - t0
    s.fmu.terminate()
    s.fmu.freeInstance()
    return wall, rec


def gears_one_by_one(rec, t_end=T_END):
    """Each default gear as a GearRattle instance (excitation 0) driven at every H by the
    recorded motion: the summed wall time [s]."""
    p = R.params()
    wall = 0.0
    n = int(round(t_end / H))
    for i in range(1, p["n_gears"] + 1):
        start = {k: p[f"gear[{i}].{k}"] for k in SHARED}
        s = Stepper(GEAR_FMU, f"gear{i}", start)
        inputs = s.refs(["theta_M", "omega_M", "alpha_M"])
        s.fmu.setReal(inputs, list(rec[0]))
        s.fmu.exitInitializationMode()
        t0 = time.perf_counter()
        for k in range(n):
            s.fmu.setReal(inputs, list(rec[k]))
            s.fmu.doStep(k * H, H)
        wall += time.perf_counter() - t0
        s.fmu.terminate()
        s.fmu.freeInstance()
    return wall


def fmu_error_and_cost(tol=None, t_end=WINDOW):
    """The FMU's largest |xi_i - xi_ref| / G_i over B1's window at its tolerance `tol` (None:
    the contract's 1e-6) and its wall time per simulated second."""
    n = R.params()["n_gears"]
    wall, xi = coupled_box(t_end, [f"gear[{i}].xi" for i in range(1, n + 1)], tol=tol)
    return _err(xi.T, R.scene("B1", t_end, H)), wall / t_end


def _err(xi, ref) -> float:
    G = np.array([R.gear(ref.params, i + 1)["G"] for i in range(xi.shape[0])])
    return float(np.max(np.abs(xi - ref.xi) / G[:, None]))


def scipy_at_error(target: float, method="DOP853", t_end=WINDOW):
    """The reference's solve (scipy's `method`, edges located) at the loosest rtol of a
    decade ladder whose error over B1's window is at most `target`: (rtol, error, wall time
    per simulated second)."""
    ref = R.scene("B1", t_end, H)
    last = None
    for rtol in (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10):
        t0 = time.perf_counter()
        res = R.simulate(R.params("B1"), t_end, t_eval=ref.t, method=method, rtol=rtol)
        wall = (time.perf_counter() - t0) / t_end
        last = (rtol, _err(res.xi, ref), wall)
        if last[1] <= target:
            return last
    return last


def cost_per_gear_count(t_end=T_END, counts=range(1, 9), repeats=3):
    """Wall time per simulated second of the default box against n_gears (the contract's
    gears 1..n), stepped at 1 ms: the best of `repeats` runs (the machine is shared)."""
    return [(n, min(coupled_box(t_end, ["phi"], 1e-3, n_gears=n)[0] for _ in range(repeats)) / t_end) for n in counts]


def cost_figure(path, rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n, c = zip(*rows)
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(n, c, "o-")
    ax.set_xlabel("n_gears")
    ax.set_ylabel("wall time per simulated second [s]")
    ax.set_title("GearboxRattle, default box at idle (Co-Simulation, 1 ms steps)")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
