"""The FMUs of the gearbox benchmark stepped by fmpy's FMU2Slave and timed: the coupled box
against its gears stepped one by one as GearRattle instances on the same input-side motion,
and against the number of gears. Wall times on this machine; no assertion."""

from __future__ import annotations

import functools
import time

import numpy as np

from gearrattle import gearbox_fmu as GF
from gearrattle import gearbox_reference as R
from gearrattle.masters import GEAR_FMU

T_END, H = 2.0, 1e-4
SHARED = ("I_L", "r_L", "r_M", "G", "K_star", "alpha", "epsilon", "C_LM", "C", "B", "gap_start")


@functools.lru_cache(maxsize=None)
def _unzipped(fmu: str):
    """The FMU's model description and the directory it is unzipped into, once per process."""
    from fmpy import extract, read_model_description

    return read_model_description(fmu), extract(fmu)


class Stepper:
    """An FMU2Slave (its library loaded) stepped by hand, its outputs read by name after each
    step. `start` instantiates it: what a run costs counts from there."""

    def __init__(self, fmu, name):
        from fmpy.fmi2 import FMU2Slave

        md, unzipped = _unzipped(str(fmu))
        self.vrs = {v.name: v.valueReference for v in md.modelVariables}
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped,
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)

    def start(self, start: dict, tol=None):
        """Instantiated at the tolerance `tol` (None: the FMU's own) and left in
        initialization mode with the start values `start` set."""
        self.fmu.instantiate()
        self.fmu.setupExperiment(tolerance=tol, startTime=0.0)
        self.fmu.enterInitializationMode()
        for k, v in start.items():
            (self.fmu.setInteger if isinstance(v, int) else self.fmu.setReal)([self.vrs[k]], [v])
        return self

    def refs(self, names):
        return [self.vrs[n] for n in names]

    def record(self, names, n: int, h: float) -> np.ndarray:
        """n steps of h from t = 0: the outputs `names` at every communication point, (n + 1, len(names))."""
        refs = self.refs(names)
        rec = np.empty((n + 1, len(names)))
        rec[0] = self.fmu.getReal(refs)
        for k in range(n):
            self.fmu.doStep(k * h, h)
            rec[k + 1] = self.fmu.getReal(refs)
        return rec

    def free(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def coupled_box(t_end=T_END, names=("theta_I_out", "omega_I_out", "alpha_I_out"), h=H, tol=None, **start):
    """The box (by default the defaults, excitation 1) stepped at h: the wall time [s] of the
    steps and the outputs `names` at every communication point, (steps + 1, len(names))."""
    s = Stepper(GF.GEARBOX_FMU, "box").start(start, tol)
    s.fmu.exitInitializationMode()
    t0 = time.perf_counter()
    rec = s.record(names, int(round(t_end / h)), h)
    wall = time.perf_counter() - t0
    s.free()
    return wall, rec


def gears_one_by_one(rec, t_end=T_END):
    """Each default gear as a GearRattle instance (excitation 0) driven at every H by the
    recorded motion: the summed wall time [s]."""
    p = R.params()
    wall = 0.0
    n = int(round(t_end / H))
    for i in range(1, p["n_gears"] + 1):
        start = {k: p[f"gear[{i}].{k}"] for k in SHARED}
        s = Stepper(GEAR_FMU, f"gear{i}").start(start)
        inputs = s.refs(["theta_M", "omega_M", "alpha_M"])
        s.fmu.setReal(inputs, list(rec[0]))
        s.fmu.exitInitializationMode()
        t0 = time.perf_counter()
        for k in range(n):
            s.fmu.setReal(inputs, list(rec[k]))
            s.fmu.doStep(k * H, H)
        wall += time.perf_counter() - t0
        s.free()
    return wall


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
