"""The mesh forces of an FMU, sampled finely through fmpy (docs/SOUND.md, "The force").

The meshes come from the model description, so that an FMU plugs in by naming its outputs:
GearRattle has one mesh, `F_contact`; the gearbox has `gear[i].F_contact` for i = 1..n_gears
(FMI 2.0 structured names, n_gears a parameter). A mesh's impacts are read from its cumulative
counters `<prefix>impacts_Fplus` and `<prefix>impacts_Fminus` when the FMU has them, else from
the force's onsets (F leaving zero).

The FMU is stepped on the grid t_n = n h, h = 1 / (48 kHz · SUBSAMPLE): every SUBSAMPLE-th
sample is a sample of the WAV, so the pressure at the WAV's instants needs no resampling. Where
the FMU's binary has the sampling entry SAMPLED, a chunk of the grid is one call."""

from dataclasses import dataclass
import re
import time

import numpy as np

from ..calls import SAMPLED, check, raw_calls, sampled_call
from .metrics import FS

SUBSAMPLE = 4  # force samples per WAV sample: h = 5.2 µs (docs/SOUND.md, "Error")
# The simulated time of one call of the sampling entry (gearrattle.calls.SAMPLED) [s].
CHUNK = 0.01
FORCE = "F_contact"
COUNTERS = ("impacts_Fplus", "impacts_Fminus")
# Start values that make a lone FMU run the paper's bench (the FMU's defaults are scene S1).
STANDALONE = {"excitation": 1}


@dataclass
class Mesh:
    name: str  # "gear[2]" or "" (GearRattle's single mesh)
    force: object  # fmpy ScalarVariable of the force
    counters: tuple  # the two counters' variables, or ()

    @property
    def label(self):
        return self.name or "mesh"


@dataclass
class Run:
    """What one FMU run gives the sound: the force samples of each mesh on the grid
    t = t0 + n h, and each mesh's impact instants as intervals (t_lo, t_hi] with their flank
    (1 = F+, 2 = F-, 0 = from the force's onset)."""
    h: float
    t0: float
    forces: list  # one array per mesh
    impacts: list  # per mesh: array of (t_lo, t_hi, flank)
    meshes: list
    values: dict  # the start values set
    cpu_s: float = 0.0
    steps: int = 0


def meshes(md, values):
    """The meshes of a model description, with the start values `values` (for n_gears)."""
    by_name = {v.name: v for v in md.modelVariables}

    def counters(prefix):
        vs = tuple(by_name.get(prefix + c) for c in COUNTERS)
        return vs if all(v is not None and v.causality == "output" for v in vs) else ()

    if "n_gears" in by_name:
        n = int(values.get("n_gears", float(by_name["n_gears"].start)))
        out = []
        for i in range(1, n + 1):
            v = by_name.get(f"gear[{i}].{FORCE}")
            if v is None:
                raise ValueError(f"n_gears = {n} but the FMU has no output gear[{i}].{FORCE}: "
                                 f"set n_gears to at most the number of gear[i] outputs")
            out.append(Mesh(f"gear[{i}]", v, counters(f"gear[{i}].")))
        return out
    if FORCE in by_name:
        return [Mesh("", by_name[FORCE], counters(""))]
    gears = sorted({m[1] for m in (re.match(r"(gear\[\d+\])\.", n) for n in by_name) if m})
    raise ValueError(f"the FMU has no output {FORCE} nor a parameter n_gears"
                     + (f" (it has {', '.join(gears)})" if gears else "")
                     + ": the sound needs each mesh's contact force")


def start_values(md, sets):
    """The start values of a run: STANDALONE where the FMU has it, then the user's sets, each
    checked against the model description. Raises ValueError naming the fix."""
    import difflib

    params = {v.name: v for v in md.modelVariables if v.causality == "parameter"}
    values = {k: v for k, v in STANDALONE.items() if k in params}
    for name, value in sets.items():
        if name not in params:
            near = difflib.get_close_matches(name, list(params), 3)
            raise ValueError(f"--set {name}: not a parameter of this FMU"
                             + (f": did you mean {' or '.join(near)}?" if near else ""))
        values[name] = value
    return values


def simulate(fmu, md, values, duration, t_record=0.0, subsample=SUBSAMPLE):
    """Run the FMU (a .fmu or an extracted directory) from 0 to duration with these start
    values and record each mesh's force from t_record on. Returns a Run."""
    import shutil

    from fmpy import extract, instantiate_fmu

    ms = meshes(md, values)
    packed = str(fmu).endswith(".fmu")
    unzip = extract(fmu) if packed else fmu
    try:
        inst = instantiate_fmu(unzip, md, fmi_type="CoSimulation")
        t_cpu = time.process_time()
        try:
            inst.setupExperiment(startTime=0.0, stopTime=duration)
            _set(inst, md, values)
            inst.enterInitializationMode()
            inst.exitInitializationMode()
            if t_record > 0:
                inst.doStep(0.0, t_record)
            run = record(inst, ms, t_record, duration, subsample)
            inst.terminate()
        finally:
            inst.freeInstance()
    finally:
        if packed:
            shutil.rmtree(unzip, ignore_errors=True)
    run.values = values
    run.cpu_s = time.process_time() - t_cpu
    return run


def record(inst, ms, t0, t_end, subsample=SUBSAMPLE):
    """Step an initialised instance from t0 to t_end on the grid t0 + n h, reading the forces
    at every point and the impact counters between reads;
    an impact is then placed at its force's onset within that interval.

    Where the FMU's binary exports SAMPLED (docs/SOUND.md, "The force"), each CHUNK of the
    run is one call that takes its steps and reads the forces at each, and the counters are
    read at the chunks' ends; else fmi2DoStep and fmi2GetReal are called at every point and
    the counters at every WAV sample. The raw FMI calls on arrays made once keep Python's
    cost to about a µs a call."""
    import ctypes

    h = 1.0 / (FS * subsample)
    n = int(round((t_end - t0) / h))
    m = len(ms)
    vr_f = (ctypes.c_uint * m)(*[x.force.valueReference for x in ms])
    counted = [j for j, x in enumerate(ms) if x.counters]
    vr_c = (ctypes.c_uint * (2 * len(counted)))(
        *[c.valueReference for j in counted for c in ms[j].counters])
    F = np.zeros((m, n + 1))  # each mesh's force contiguous, for the filters
    do_step, get_real, get_int = raw_calls(inst)
    sampled = sampled_call(inst)
    every = max(1, int(round(CHUNK / h))) if sampled else subsample
    at = np.unique(np.r_[np.arange(0, n + 1, every), n])  # where the counters are read
    C = np.zeros((len(at), len(vr_c)), dtype=np.int32)  # fmi2Integer
    rows = np.zeros((every, m))  # the forces between two counter reads, as the FMU writes them
    comp, row, ends = inst.component, 8 * m, at.tolist()
    r_at, c_at = rows.ctypes.data, C.ctypes.data
    vf, vc, n_c = ctypes.addressof(vr_f), ctypes.addressof(vr_c), len(vr_c)  # (arrays kept)
    get_real(comp, vf, m, r_at)
    F[:, 0] = rows[0]
    if counted:
        get_int(comp, vc, n_c, c_at)
    for i in range(1, len(ends)):
        k0, k1 = ends[i - 1], ends[i]
        if sampled:
            check(sampled(comp, t0 + k0 * h, h, k1 - k0, vf, m, r_at), SAMPLED, t0 + k0 * h)
        else:
            for k in range(k0 + 1, k1 + 1):
                check(do_step(comp, t0 + (k - 1) * h, h, 1), "fmi2DoStep", t0 + (k - 1) * h)
                get_real(comp, vf, m, r_at + row * (k - k0 - 1))
        F[:, k0 + 1:k1 + 1] = rows[:k1 - k0].T
        if counted:
            get_int(comp, vc, n_c, c_at + 4 * n_c * i)
    C = C.astype(np.int64)
    impacts = [None if x.counters else _from_force(F[j], t0, h) for j, x in enumerate(ms)]
    for col, j in enumerate(counted):
        impacts[j] = _from_counters(at, C[:, 2 * col], C[:, 2 * col + 1], F[j], t0, h)
    return Run(h=h, t0=t0, forces=list(F), impacts=impacts, meshes=ms, values={}, steps=n)


def _from_counters(at, n_plus, n_minus, F, t0, h):
    """The impacts the counters read at the grid indices `at` show, placed at the force's
    onsets in their reading interval: the i-th impact of a flank at the i-th onset of that
    flank's sign (F+ pushes, F > 0; F- pulls, F < 0), the last such onset when the counters
    show more, any onset when none has that sign, the whole interval when the force shows
    none."""
    onsets = np.nonzero((F[:-1] == 0) & (F[1:] != 0))[0] + 1
    rows = []
    for flank, c, sign in ((1, n_plus, 1.0), (2, n_minus, -1.0)):
        for i in np.nonzero(np.diff(c) > 0)[0]:
            lo, hi = at[i], at[i + 1]
            a, b = np.searchsorted(onsets, [lo, hi], "right")
            inside = onsets[a:b]
            signed = inside[np.sign(F[inside]) == sign]
            inside = signed if len(signed) else inside
            for q in range(int(c[i + 1] - c[i])):
                k = inside[min(q, len(inside) - 1)] if len(inside) else None
                rows.append((t0 + (k - 1) * h, t0 + k * h, flank) if k is not None
                            else (t0 + lo * h, t0 + hi * h, flank))
    rows.sort()
    return np.array(rows, dtype=float).reshape(-1, 3)


def _from_force(F, t0, h):
    k = np.nonzero((F[:-1] == 0) & (F[1:] != 0))[0]
    return np.column_stack([t0 + k * h, t0 + (k + 1) * h, np.zeros(len(k))])


def _set(inst, md, values):
    by_name = {v.name: v for v in md.modelVariables}
    for name, value in values.items():
        v = by_name[name]
        if v.type == "Real":
            inst.setReal([v.valueReference], [float(value)])
        elif v.type == "Boolean":
            inst.setBoolean([v.valueReference], [bool(value)])
        else:
            inst.setInteger([v.valueReference], [int(value)])
