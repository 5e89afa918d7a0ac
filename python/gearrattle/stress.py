"""The stress cases, as data, and how each one is run and judged.

Shared by tests/python/test_stress.py (pytest: one test per case) and the stability report
(gearrattle.stability, docs/STABILITY.md: one row per case), so that the report says exactly
what the tests check.

Every case runs the FMU in sine mode (excitation = 1, docs/MODEL.md §5) from one scene of
reference.SCENES with parameter overrides, through fmpy's low-level FMU2Slave: every
fmi2DoStep's status is checked, every output is read at every communication point, the
FMU's log is recorded. Then:

* no NaN/Inf in any output, ever;
* `check`, one of
    "ref"     max |Δξ| against reference.simulate (DOP853 at rtol 1e-12, or Radau at 1e-10
              where DOP853 is too slow) at the communication points of [t0, t_end], relative
              to scale = max(G, max |ξ_ref|) (the tolerance is relative: where the teeth go
              deeper than G, as with G = 1 nm, |ξ| is the scale), must be ≤ 10 · rtol, rtol
              being the tolerance given to the FMU; the impact counts per flank must agree;
    "energy"  C = C_LM = 0 (B = 0): the energy balance of docs/MODEL.md §3 from the FMU's outputs
              alone, within 10 · rtol (see _check_energy);
    "hour"    1 h at an idle mean speed, no drift (see _check_hour);
    "refuse"  the FMU must refuse (a communication step below the resolution of time).
* each case is judged "solved" or "gave up" (a refused fmi2DoStep, fmi2Discard or
  fmi2Error): every case must be solved, so a regression from an answer to a refusal fails,
  except where refusing is the right answer, which the case says (`refuse`, with why). There
  the refusal must be clean: a log line at Discard/Error saying what happened and at what
  time, and fmi2GetReal still giving the last good state, finite. fmi2OK with a wrong answer
  never passes.

Windows: the tolerance bounds the error per step, and these errors add up. Measured on S1
(DOPRI5, default ε): 3.6 rtol after one impact, 17 after four, 41 after twelve, while the
model itself does not amplify a perturbation there (a change of ξ(0) comes out ×1.5 after
50 ms). So 10 · rtol is judged over S1's first two impacts (12 ms; at 6.8 and 10.3 ms),
and the other windows are of that length unless said. No case is chaotic within its window
(checked with a perturbed reference: a change of ξ(0) grows at most ~3× there; the
undamped C = C_LM = 0 motion does become chaotic later: ×300 at 50 ms, which is why its
long run is judged by the energy balance only), so ξ is compared pointwise everywhere and
impact rates are not needed.
"""

from __future__ import annotations

import ctypes
import functools
import itertools
import math
import pathlib
import re
import time
from dataclasses import dataclass, field

import numpy as np

from . import reference as R

ROOT = pathlib.Path(__file__).resolve().parents[2]  # the repository (python/gearrattle/..)
FMU_PATH = ROOT / "target" / "fmu" / "GearRattle.fmu"

FACTOR = 10.0  # the error may be up to FACTOR × the requested tolerance
HOUR = 3600.0


# ---------------------------------------------------------------------------------------
# The cases
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Case:
    name: str
    about: str  # what is stressed, for the report
    overrides: dict = field(default_factory=dict)  # parameters (same names in FMU and reference)
    scene: str = "S1"
    t_end: float = 0.012  # end of the run (and of the compared window)
    h: float = 1e-4  # communication step (= output interval)
    rtol: float = 1e-8  # the tolerance given to the FMU (fmi2SetupExperiment)
    t0: float = 0.0  # start time
    check: str = "ref"  # "ref" | "energy" | "hour"
    ref_method: str = "DOP853"  # the reference's method ("Radau" where DOP853 is too slow)
    ref_rtol: float = 1e-12
    # Why refusing is the right answer here (the FMU must then refuse, cleanly); empty: the
    # case must be solved, and a refusal fails it.
    refuse: str = ""
    implicit: bool = False  # stiff for an explicit method: auto mode must hand over to Radau IIA

    def start(self) -> dict:
        """Start values for the FMU: the scene's sine excitation and the overrides."""
        sc = R.SCENES[self.scene]
        return {"excitation": 1, "f_exc": sc["f_exc"], "A_rms": sc["A_rms"], **self.overrides}

    def params(self) -> dict:
        return R.params(self.scene, **self.overrides)

    @property
    def duration(self) -> float:
        return self.t_end - self.t0

    def describe(self) -> str:
        """The parameters that differ from S1, short."""
        parts = [f"{k}={_num(v)}" for k, v in self.overrides.items()]
        if self.scene != "S1":
            parts.insert(0, self.scene)
        return ", ".join(parts) if parts else "S1 (paper's parameters)"


def _num(v) -> str:
    if isinstance(v, int):
        return str(v)
    if v == 0:
        return "0"
    if abs(v - 10 / 9) < 1e-15:
        return "10/9"
    if 1e-3 <= abs(v) < 1e5:
        return f"{v:g}"
    return f"{v:.0e}".replace("e-0", "e-").replace("e+0", "e").replace("e+", "e")


CLM = R.DEFAULTS["C_LM"]

CASES: list[Case] = [
    Case("S1", "baseline: the paper's bench S1 (30 Hz, 300 rad/s² RMS), two impacts"),
    Case("S1 rtol 1e-6", "S1 at the model description's default tolerance", rtol=1e-6),
    # smoothing band ε
    Case("eps 0", "no smoothing band: the contact force switches on at once", {"epsilon": 0.0}),
    Case("eps 1e-12", "a band far thinner than any step", {"epsilon": 1e-12}),
    Case("eps 1e-9", "a thin band", {"epsilon": 1e-9}),
    # contact stiffness K* (default 3e6 N/m)
    Case("K* 1e3", "very soft contact: deep penetration (12 G)", {"K_star": 1e3}),
    Case("K* 1e5", "soft contact", {"K_star": 1e5}),
    Case("K* 1e8", "hard contact", {"K_star": 1e8}),
    Case("K* 1e10", "very hard contact: contact frequency 2e5 rad/s", {"K_star": 1e10}),
    # contact exponent α (default 4/3)
    Case("alpha 1", "linear contact", {"alpha": 1.0}),
    Case("alpha 10/9", "line contact", {"alpha": 10 / 9}),
    Case("alpha 3/2", "point contact", {"alpha": 1.5}),
    Case("alpha 2", "quadratic contact", {"alpha": 2.0}),
    # damping
    Case("C_LM 0", "no contact damping", {"C_LM": 0.0}),
    Case("C_LM x1000", "contact damping ×1000 (67 kN·s/m): overdamped, stiff", {"C_LM": 1000 * CLM}, implicit=True),
    Case("C 0", "no lubricant drag", {"C": 0.0}),
    # inertia of the loose gear (default 0.32e-3 kg·m²)
    Case(
        "I_L 1e-8",
        "tiny idler: drag rate C/I_L = 2.5e6 1/s, stiff everywhere",
        {"I_L": 1e-8},
        ref_method="Radau",
        ref_rtol=1e-10,
        implicit=True,
    ),
    Case("I_L 1e-6", "light idler", {"I_L": 1e-6}),
    Case("I_L 1e-2", "heavy idler", {"I_L": 1e-2}),
    Case("I_L 1", "very heavy idler: the teeth stay pressed (42 G deep)", {"I_L": 1.0}),
    Case(
        "I_L 1e-8 + C_LM x1000",
        "tiny idler and heavy contact damping: damping rate 9e9 1/s (explicit: ~1e6 steps per ms)",
        {"I_L": 1e-8, "C_LM": 1000 * CLM},
        t_end=0.002,
        ref_method="Radau",
        ref_rtol=1e-10,
        implicit=True,
    ),
    # backlash G (default 25e-6 m)
    Case("G 1e-9", "1 nm backlash: the band (1 µm) is 1000 G wide", {"G": 1e-9}),
    Case("G 1e-7", "0.1 µm backlash", {"G": 1e-7}),
    Case("G 1e-5", "10 µm backlash", {"G": 1e-5}),
    Case("G 1e-3", "1 mm backlash: no impact in the window", {"G": 1e-3}),
    # excitation level and frequency
    Case("A_rms 1e4", "violent excitation", {"A_rms": 1e4}),
    Case("A_rms 1e5", "extreme excitation: impacts at ~10× S1's speed", {"A_rms": 1e5}),
    Case("f 0.1 Hz", "slow excitation: ω_M starts at −675 rad/s, the drag presses one flank", {"f_exc": 0.1}),
    Case("f 2 kHz", "fast excitation: 0.08 µm of shaft motion, free flight", {"f_exc": 2000.0}),
    # communication step
    Case(
        "h 1e-7",
        "communication step 1e-7 s over an impact (started 0.05 G from F+ at −0.02 m/s), 1.5 ms",
        {"gap_start": 0.05, "xi_dot_start": -0.02},
        t_end=0.0015,
        h=1e-7,
    ),
    Case("h 1e-6", "communication step 1e-6 s", h=1e-6),
    Case("h 1e-3", "communication step 1e-3 s", h=1e-3),
    Case(
        "h 1 s",
        "communication step 1 s (one step), f = 0.1 Hz: an impact then a pressed flank",
        {"f_exc": 0.1},
        t_end=1.0,
        h=1.0,
    ),
    Case(
        "h 1e-7 at t = 1e9 s",
        "communication step 1e-7 s at t = 1e9 s, below the resolution of time (1.2e-7 s): must refuse",
        t0=1e9,
        t_end=1e9 + 1e-5,
        h=1e-7,
        refuse="the step does not exist on the time axis there: t + 1e-7 is 1e9 + 1.19e-7, so any "
        "answer would be for another step than the one asked, and stretching or shrinking it "
        "silently would shift every later communication point",
    ),
    # invariants
    Case(
        "energy forced",
        "C = C_LM = 0 under S1: ½ I_L ω_L² + V(ξ) − ∫ −τ_M ω_M dt constant (docs/MODEL.md §3), the work "
        "from the outputs every 2 µs and their derivatives; 50 ms, 12 impacts",
        {"C": 0.0, "C_LM": 0.0},
        t_end=0.05,
        h=2e-6,
        check="energy",
    ),
    Case(
        "energy free rattling",
        "C = C_LM = 0, main shaft at rest (A_rms = 0), ξ'(0) = 0.05 m/s: the gear bounces between "
        "the flanks, ½ (I_L/r_L²) ξ'² + V(ξ) constant; 8 impacts",
        {"C": 0.0, "C_LM": 0.0, "A_rms": 0.0, "xi_dot_start": 0.05},
        check="energy",
    ),
    Case(
        "1 h at 84 rad/s",
        "1 h simulated at an idle mean speed of 84 rad/s (S1 oscillation on top): ξ must not drift",
        {"omega_mean": 84.0},
        t_end=HOUR,
        h=1e-3,
        check="hour",
    ),
]

BY_NAME = {c.name: c for c in CASES}
assert len(BY_NAME) == len(CASES), "case names must be unique"


# ---------------------------------------------------------------------------------------
# Driving the FMU: fmpy's low-level FMU2Slave, every status checked, the log recorded
# ---------------------------------------------------------------------------------------

# fmpy's native logger proxy keeps ONE process-wide target (the last one registered): a
# single permanent callback dispatches the messages by instance name (as in
# test_fmu_misuse.py), so that no callback is left dangling.
_RECORDERS: dict[str, list] = {}
_instance_count = itertools.count()
_LOGGER = None
STATUS_NAMES = ["OK", "Warning", "Discard", "Error", "Fatal", "Pending"]


def _dispatch(env, instance, status, category, message):
    from fmpy.fmi1 import printLogMessage

    name = (instance or b"").decode("utf-8", "replace")
    logs = _RECORDERS.get(name)
    if logs is None:
        printLogMessage(env, instance, status, category, message)
        return
    logs.append(
        (
            int(status),
            (category or b"").decode("utf-8", "replace"),
            (message or b"").decode("utf-8", "replace"),
        )
    )


def _logger():
    global _LOGGER
    if _LOGGER is None:
        from fmpy.fmi2 import fmi2CallbackLoggerTYPE

        _LOGGER = fmi2CallbackLoggerTYPE(_dispatch)
    return _LOGGER


def _status_name(status: int) -> str:
    return STATUS_NAMES[status] if 0 <= status < len(STATUS_NAMES) else f"status {status}"


@dataclass
class Run:
    """What one FMU run gave."""

    t: np.ndarray  # recorded communication points
    real: dict  # output name -> array at t (and name + "'" -> first derivative, if asked)
    integer: dict  # output name -> array at t
    status: str  # "ok", or the FMI status name of the refused fmi2DoStep
    refused_at: float | None = None  # communication point the refused fmi2DoStep started from
    refused_h: float | None = None
    logs: list = field(default_factory=list)  # (status, category, message) at Warning or worse
    after_refusal: dict | None = None  # fmi2GetReal after the refusal: status, values
    cpu: float = 0.0  # CPU seconds spent in fmi2DoStep
    wall: float = 0.0  # wall seconds spent in fmi2DoStep
    steps: float = math.nan  # solver_steps, solver_rejected, solver_rhs at the end
    rejected: float = math.nan
    rhs: float = math.nan
    methods: tuple = ()  # distinct solver_method values seen
    n_do_step: int = 0
    coarse: dict = field(default_factory=dict)  # Real outputs at the coarse points before record_from


class Driver:
    """Runs the FMU extracted in `unzipdir` (its model description `md`) step by step."""

    def __init__(self, unzipdir: str, md):
        self.unzipdir = unzipdir
        self.md = md
        self.vars = {v.name: v for v in md.modelVariables}
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.real_out = [v.name for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
        self.int_out = [v.name for v in md.modelVariables if v.causality == "output" and v.type == "Integer"]

    def run(
        self,
        start: dict,
        t_end: float,
        h: float,
        tol: float | None = None,
        t0: float = 0.0,
        record_from: float | None = None,
        h_coarse: float | None = None,
        derivatives=(),
    ) -> Run:
        """Steps from t0 to t_end with communication step h, reading every output after
        each step from record_from on (default t0; t0 itself is read too). Before
        record_from, steps of h_coarse (default h) are taken and only the Real outputs are
        read (into Run.coarse, for the NaN/Inf check).
        derivatives: Real outputs whose first derivative (fmi2GetRealOutputDerivatives) is
        read too, as real[name + "'"].

        start: start values (Integer variables by their type in the model description).
        A refused fmi2DoStep ends the run: its status, the log, and what fmi2GetReal gives
        afterwards are kept."""
        from fmpy import calloc, free
        from fmpy.fmi1 import FMICallException
        from fmpy.fmi2 import (
            FMU2Slave,
            fmi2CallbackAllocateMemoryTYPE,
            fmi2CallbackFreeMemoryTYPE,
            fmi2CallbackFunctions,
            fmi2Integer,
            fmi2Real,
            fmi2ValueReference,
        )
        from fmpy.logging import addLoggerProxy

        name = f"stress_{next(_instance_count)}"
        logs: list = []
        _RECORDERS[name] = logs
        callbacks = fmi2CallbackFunctions()
        callbacks.logger = _logger()
        callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(ctypes.byref(callbacks))
        fmu = FMU2Slave(
            guid=self.md.guid,
            unzipDirectory=self.unzipdir,
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        instantiated = False
        try:
            fmu.instantiate(callbacks=callbacks, loggingOn=False)
            instantiated = True
            comp = fmu.component
            fmu.setupExperiment(tolerance=tol, startTime=t0)
            fmu.enterInitializationMode()
            ints = {k: v for k, v in start.items() if self.vars[k].type == "Integer"}
            reals = {k: v for k, v in start.items() if self.vars[k].type == "Real"}
            if ints:
                fmu.setInteger([self.vr[k] for k in ints], [int(v) for v in ints.values()])
            if reals:
                fmu.setReal([self.vr[k] for k in reals], [float(v) for v in reals.values()])
            fmu.exitInitializationMode()

            nr, ni, nd = len(self.real_out), len(self.int_out), len(derivatives)
            rvr = (fmi2ValueReference * nr)(*[self.vr[k] for k in self.real_out])
            ivr = (fmi2ValueReference * ni)(*[self.vr[k] for k in self.int_out])
            rbuf, ibuf = (fmi2Real * nr)(), (fmi2Integer * ni)()
            dvr = (fmi2ValueReference * max(nd, 1))(*[self.vr[k] for k in derivatives])
            dord = (fmi2Integer * max(nd, 1))(*([1] * nd))
            dbuf = (fmi2Real * max(nd, 1))()
            get_real, get_int, do_step = fmu.fmi2GetReal, fmu.fmi2GetInteger, fmu.fmi2DoStep
            get_der = fmu.fmi2GetRealOutputDerivatives

            # communication points: coarse up to record_from, then every h
            if record_from is None or record_from <= t0:
                record_from = t0
                pts = [t0]
            else:
                hc = h if h_coarse is None else h_coarse
                n = max(1, int(round((record_from - t0) / hc)))
                pts = list(t0 + np.arange(n + 1) * hc)
                pts[-1] = record_from
            n = max(1, int(round((t_end - record_from) / h)))
            fine = record_from + np.arange(1, n + 1) * h
            fine[-1] = t_end
            pts = np.concatenate([np.asarray(pts, dtype=float), fine])
            i_rec = len(pts) - n - 1  # index of record_from

            rec_t, rec_r, rec_i, rec_d, rec_c = [], [], [], [], []

            def read(t):
                rec_t.append(t)
                get_real(comp, rvr, nr, rbuf)
                get_int(comp, ivr, ni, ibuf)
                rec_r.append(list(rbuf))
                rec_i.append(list(ibuf))
                if nd:
                    get_der(comp, dvr, nd, dord, dbuf)
                    rec_d.append(list(dbuf)[:nd])

            status, refused = "ok", None
            cpu = wall = 0.0
            n_steps = 0
            if i_rec == 0:
                read(pts[0])
            clock_cpu, clock_wall = time.process_time, time.perf_counter
            for k in range(1, pts.size):
                t, hk = pts[k - 1], pts[k] - pts[k - 1]
                c0, w0 = clock_cpu(), clock_wall()
                try:
                    do_step(comp, t, hk, 1)
                except FMICallException as e:
                    cpu += clock_cpu() - c0
                    wall += clock_wall() - w0
                    status, refused = _status_name(e.status), (t, hk)
                    break
                cpu += clock_cpu() - c0
                wall += clock_wall() - w0
                n_steps += 1
                if k >= i_rec:
                    read(pts[k])
                else:
                    get_real(comp, rvr, nr, rbuf)
                    rec_c.append(list(rbuf))
            after = None
            if refused is not None:
                try:
                    get_real(comp, rvr, nr, rbuf)
                    after = {"status": "OK", "values": dict(zip(self.real_out, list(rbuf)))}
                except FMICallException as e:
                    after = {"status": _status_name(e.status), "values": None}
            diag = {}
            for k in ("solver_steps", "solver_rejected", "solver_rhs"):
                if k in self.vr:
                    try:
                        diag[k] = fmu.getReal([self.vr[k]])[0]
                    except FMICallException:
                        diag[k] = math.nan
            r = np.array(rec_r, dtype=float).reshape(-1, nr)
            i = np.array(rec_i, dtype=np.int64).reshape(-1, ni)
            real = {k: r[:, j] for j, k in enumerate(self.real_out)}
            if nd:
                d = np.array(rec_d, dtype=float).reshape(-1, nd)
                real.update({k + "'": d[:, j] for j, k in enumerate(derivatives)})
            run = Run(
                t=np.array(rec_t, dtype=float),
                real=real,
                integer={k: i[:, j] for j, k in enumerate(self.int_out)},
                status=status,
                refused_at=None if refused is None else refused[0],
                refused_h=None if refused is None else refused[1],
                logs=[m for m in logs if m[0] >= 1],
                after_refusal=after,
                cpu=cpu,
                wall=wall,
                steps=diag.get("solver_steps", math.nan),
                rejected=diag.get("solver_rejected", math.nan),
                rhs=diag.get("solver_rhs", math.nan),
                n_do_step=n_steps,
                coarse={k: np.array(rec_c, dtype=float).reshape(-1, nr)[:, j] for j, k in enumerate(self.real_out)},
            )
            if run.integer["solver_method"].size:
                run.methods = tuple(sorted(set(run.integer["solver_method"].tolist())))
            return run
        finally:
            if instantiated:
                try:
                    fmu.terminate()
                except Exception:
                    pass  # after a refused step the instance may be in its error state
                fmu.freeInstance()
            else:
                fmu.freeLibrary()
            _RECORDERS.pop(name, None)


# ---------------------------------------------------------------------------------------
# Judging a run
# ---------------------------------------------------------------------------------------


@dataclass
class Verdict:
    case: Case
    run: Run | None
    passed: bool
    outcome: str  # "solved", "gave up", "refused as it should", or what went wrong
    error: float = math.nan  # the case's error measure (see `measure`)
    bound: float = math.nan  # its allowed maximum
    measure: str = ""  # what `error` is
    problems: list = field(default_factory=list)  # why it failed
    notes: list = field(default_factory=list)  # what else was seen
    ref_seconds: float = 0.0  # wall time of the reference computations
    extra: dict = field(default_factory=dict)

    def message(self) -> str:
        c = self.case
        r = self.run
        head = f"{c.name} ({c.describe()}; rtol {c.rtol:g}, h {c.h:g} s, {c.duration:g} s): {self.outcome}"
        if r is not None:
            head += f"; {r.steps:.0f} steps, {r.rhs:.0f} rhs, {r.wall:.3f} s in fmi2DoStep"
        if self.measure:
            head += f"; {self.measure} = {self.error:.3g} (allowed {self.bound:.3g})"
        lines = [head] + [f"  problem: {p}" for p in self.problems] + [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)


def _nonfinite(run: Run) -> list[str]:
    bad = []
    for k, v in run.real.items():
        n = int(np.count_nonzero(~np.isfinite(v)))
        if n:
            first = run.t[np.nonzero(~np.isfinite(v))[0][0]]
            bad.append(f"{k}: {n} non-finite value(s), the first at t = {first:.9g} s")
    for k, v in run.coarse.items():
        n = int(np.count_nonzero(~np.isfinite(v)))
        if n:
            bad.append(f"{k}: {n} non-finite value(s) at the coarse communication points")
    return bad


_TIME_RE = re.compile(r"\bt\s*=\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)")


def refusal_problems(run: Run) -> list[str]:
    """What is wrong with a refusal (empty: clean)."""
    p = []
    if run.status not in ("Discard", "Error"):
        p.append(f"fmi2DoStep returned {run.status}: a refusal must be fmi2Discard or fmi2Error")
    msgs = [m for m in run.logs if m[0] >= 2]
    if not msgs:
        p.append("no log message at Discard/Error level")
    else:
        t, h = run.refused_at, run.refused_h
        lo, hi = t - 1e-12 * max(1.0, abs(t)), t + h + 1e-12 * max(1.0, abs(t))
        timed = [m for m in msgs if any(lo <= float(x) <= hi for x in _TIME_RE.findall(m[2]))]
        if not timed:
            p.append(f"no log message gives the time of the failure (within [{t}, {t + h}]): {[m[2] for m in msgs]}")
        elif all(len(m[2]) < 40 for m in timed):
            p.append(f"the log message does not say what happened: {[m[2] for m in timed]}")
    a = run.after_refusal
    if a is None or a["status"] != "OK":
        p.append(f"fmi2GetReal after the refusal returned {None if a is None else a['status']}")
    else:
        vals = a["values"]
        bad = [k for k, v in vals.items() if not math.isfinite(v)]
        if bad:
            p.append(f"non-finite values after the refusal: {bad}")
        if run.t.size and vals["xi"] != run.real["xi"][-1]:
            p.append(
                f"after the refusal xi = {vals['xi']!r}, not the last good state's {run.real['xi'][-1]!r} "
                f"(t = {run.t[-1]})"
            )
    return p


@functools.lru_cache(maxsize=None)
def _reference(case_name: str, t_eval: tuple, t_start: float = 0.0, overrides: tuple = ()):
    c = BY_NAME[case_name]
    p = R.params(c.scene, **{**c.overrides, **dict(overrides)})
    t_eval = np.array(t_eval)
    return R.simulate(p, t_eval[-1], t_eval=t_eval, method=c.ref_method, rtol=c.ref_rtol, t_start=t_start)


def reference_for(case: Case, t_eval, t_start: float = 0.0, **overrides):
    """reference.simulate for the case (cached by case and times)."""
    return _reference(case.name, tuple(np.asarray(t_eval, dtype=float).tolist()), t_start, tuple(sorted(overrides.items())))


def xi_error(case: Case, t, xi, xi_ref) -> tuple[float, float, float]:
    """(max |Δξ| / scale, time of the max, scale) with scale = max(G, max |ξ_ref|)."""
    G = case.params()["G"]
    scale = max(G, float(np.max(np.abs(xi_ref))))
    d = np.abs(np.asarray(xi) - np.asarray(xi_ref))
    k = int(np.argmax(d))
    return float(d[k] / scale), float(t[k]), scale


def main_run(case: Case, driver: Driver) -> Run:
    """The case's FMU run (the one its cost is measured on)."""
    if case.check == "hour":
        return driver.run(
            case.start(), case.t_end, case.h, tol=case.rtol, t0=case.t0, record_from=case.t_end - HOUR_TAIL, h_coarse=1.0
        )
    derivs = ()
    if case.check == "energy" and _forced(case.params()):
        derivs = ("tau_M", "omega_M_out")
    return driver.run(case.start(), case.t_end, case.h, tol=case.rtol, t0=case.t0, derivatives=derivs)


def _forced(p: dict) -> bool:
    return p["A_rms"] != 0.0 or p["omega_mean"] != 0.0


def evaluate(case: Case, driver: Driver) -> Verdict:
    """Runs the case on the FMU and judges it."""
    if case.refuse:
        return _check_refuse(case, driver)
    fn = {"ref": _check_ref, "energy": _check_energy, "hour": _check_hour}[case.check]
    return fn(case, driver)


def _common(case: Case, run: Run) -> Verdict | None:
    """The judgement shared by all the cases: non-finite outputs, refusals. None: go on."""
    v = Verdict(case, run, False, "failed")
    bad = _nonfinite(run)
    if bad:
        v.problems += bad
        return v
    if run.status != "ok":
        v.notes.append(
            f"fmi2DoStep({float(run.refused_at)!r}, {float(run.refused_h)!r}) -> {run.status}: "
            + " | ".join(m[2] for m in run.logs if m[0] >= 2)
        )
        if case.refuse:
            v.outcome = "refused as it should"
            v.notes.append(f"refusing is right: {case.refuse}")
            v.problems += refusal_problems(run)
        else:
            v.outcome = "gave up"
            v.problems.append("gave up: this case must be solved (only a case that says why may pass by refusing)")
        v.passed = not v.problems
        return v
    if run.logs:
        v.notes.append("log: " + " | ".join(m[2] for m in run.logs[:3]))
    return None


def _check_method(case: Case, run: Run, v: Verdict):
    """A non-stiff scene stays explicit, a stiff one hands over to Radau IIA."""
    if case.name.startswith("S1") and run.methods != (1,):
        v.problems.append(f"S1 is not stiff but solver_method took the values {run.methods} (1 = explicit expected)")
    if case.implicit and 2 not in run.methods:
        v.problems.append(f"stiff case, but solver_method was never 2 (Radau IIA) at a communication point: {run.methods}")


def _check_ref(case: Case, driver: Driver) -> Verdict:
    run = main_run(case, driver)
    v = _common(case, run)
    if v is not None:
        return v
    v = Verdict(case, run, False, "solved")
    w0 = time.perf_counter()
    ref = reference_for(case, run.t, t_start=case.t0)
    v.ref_seconds = time.perf_counter() - w0
    v.error, t_max, scale = xi_error(case, run.t, run.real["xi"], ref.xi)
    v.bound = FACTOR * case.rtol
    G = case.params()["G"]
    v.measure = "max|Δξ|/G" if scale == G else f"max|Δξ|/max|ξ_ref| (= {scale / G:.3g} G)"
    n_fmu = int(run.integer["impacts_Fplus"][-1]), int(run.integer["impacts_Fminus"][-1])
    n_ref = tuple(int(np.count_nonzero(ref.impact_flank == f)) for f in (R.FPLUS, R.FMINUS))
    v.extra.update(t_max=t_max, impacts_fmu=n_fmu, impacts_ref=n_ref, ref_nfev=ref.nfev)
    v.notes.append(f"impacts F+/F-: FMU {n_fmu[0]}/{n_fmu[1]}, reference {n_ref[0]}/{n_ref[1]}; largest error at t = {t_max:.6g} s")
    if not v.error <= v.bound:
        v.problems.append(f"{v.measure} = {v.error:.3g} at t = {t_max:.6g} s, above {FACTOR:g} × rtol = {v.bound:.3g}")
    if n_fmu != n_ref:
        v.problems.append(f"impact counts F+/F- differ: FMU {n_fmu}, reference {n_ref}")
    _check_method(case, run, v)
    v.passed = not v.problems
    v.outcome = "solved" if v.passed else "wrong answer with fmi2OK"
    return v


def potential(xi, p: dict):
    """V(ξ) = ∫ F_k dξ from the flank's edge (docs/MODEL.md §3), zero in the gap (vectorised)."""
    from scipy.integrate import quad

    xi = np.asarray(xi, dtype=float)
    K, a, eps, G = p["K_star"], p["alpha"], p["epsilon"], p["G"]
    c = K / G ** (a - 1.0)
    u = np.where(xi < 0.0, -xi, np.where(xi > G, xi - G, 0.0))  # penetration |δ|

    def band(w):  # s(δ) as a function of the penetration w in [0, ε]
        return 0.5 * (1.0 - math.sin(math.pi / eps * (eps / 2.0 - w)))

    def v_band(x):
        return quad(lambda w: band(w) * c * w**a, 0.0, x, epsabs=0.0, epsrel=1e-13, limit=200)[0]

    v = np.zeros_like(u)
    if eps > 0.0:
        v_eps = v_band(eps)
        inside = (u > 0.0) & (u < eps)
        v[inside] = [v_band(x) for x in u[inside]]
        out = u >= eps
        v[out] = v_eps + c / (a + 1.0) * (u[out] ** (a + 1.0) - eps ** (a + 1.0))
    else:
        v = c / (a + 1.0) * u ** (a + 1.0)
    return v


def _check_energy(case: Case, driver: Driver) -> Verdict:
    """C = C_LM = 0 (and B = 0): the energy balance of docs/MODEL.md §3 from the FMU's outputs.

    Shaft at rest (A_rms = 0, ω_M = 0): H = ½ I_L ω_L² + V(ξ) must stay at H(0) (no work,
    nothing to integrate: any communication step). Forced: H − ∫ −τ_M ω_M dt must stay at
    H(0), the work being integrated from outputs every h with the derivatives of τ_M and ω_M
    (trapezoid with its end correction, 4th order; with h = 2 µs its own error is ~1e-8 of
    the largest kinetic energy, measured: it limits the FMU's internal steps to h). Drift
    relative to H(0) (shaft at rest) or to the largest kinetic energy ½ I_L ω_L² (forced)."""
    p = case.params()
    assert p["C"] == 0.0 and p["C_LM"] == 0.0 and p["B"] == 0.0
    forced = _forced(p)
    run = main_run(case, driver)
    v = _common(case, run)
    if v is not None:
        return v
    v = Verdict(case, run, False, "solved")
    r, t = run.real, run.t
    kinetic = 0.5 * p["I_L"] * r["omega_L"] ** 2
    H = kinetic + potential(r["xi"], p)
    if forced:
        P = -r["tau_M"] * r["omega_M_out"]  # power fed in by the main shaft
        dP = -(r["tau_M'"] * r["omega_M_out"] + r["tau_M"] * r["omega_M_out'"])
        dt = np.diff(t)
        pieces = 0.5 * dt * (P[1:] + P[:-1]) + dt**2 / 12.0 * (dP[:-1] - dP[1:])
        W = np.concatenate([[0.0], np.cumsum(pieces)])
        scale = float(np.max(kinetic))
        v.measure = "max|ΔH − W|/max(½ I_L ω_L²)"
        what = f"max kinetic energy {scale:.3e} J, ∫|P|dt = {np.sum(np.abs(pieces)):.3e} J"
    else:
        W = np.zeros_like(H)
        scale = float(H[0])
        v.measure = "max|ΔH|/H(0)"
        what = f"H(0) = {scale:.3e} J"
    drift = H - H[0] - W
    k = int(np.argmax(np.abs(drift)))
    v.error = abs(drift[k]) / scale
    v.bound = FACTOR * case.rtol
    n = int(run.integer["impacts_Fplus"][-1]), int(run.integer["impacts_Fminus"][-1])
    v.extra.update(t_max=float(t[k]), scale=scale, final=float(drift[-1] / scale))
    v.notes.append(
        f"largest drift {drift[k]:+.3e} J at t = {t[k]:.6g} s, at the end {drift[-1] / scale:+.3g} of the scale; "
        f"{what}; impacts F+/F- {n[0]}/{n[1]}"
    )
    if not v.error <= v.bound:
        v.problems.append(f"energy balance off by {v.error:.3g} ({v.measure}) at t = {t[k]:.6g} s, above {v.bound:.3g}")
    v.passed = not v.problems
    v.outcome = "solved" if v.passed else "wrong answer with fmi2OK"
    return v


HOUR_TAIL = 1.0  # the last second of the hour is compared
HOUR_REF = 0.1  # ... and its first 0.1 s with the reference


def _check_hour(case: Case, driver: Driver) -> Verdict:
    """1 h at an idle mean speed (ω_mean = 84 rad/s, S1's oscillation on top).

    With ω_mean = 84 rad/s the lubricant drag (1.6 N·m) keeps the teeth pressed on F+
    while the excitation shakes them: a forced, damped oscillation in contact with the
    period of the excitation, which forgets its start within ~0.05 s. Three comparisons,
    over the last second [T − 1 s, T], T = 3600 s, a multiple of the excitation's period
    (so the sine phase at T − 1 s is that at 0):
      (a) drift: the same last second of a short FMU run from the default start, [1 s, 2 s]:
          the hour must end on the same periodic motion;
      (b) large times: a short FMU run started at t = 0 from the hour's relative state at
          T − 1 s (gap_start = ξ/G, xi_dot_start = ξ'): the same motion from there, with
          the resolution of time of t ≈ 0;
      (c) the reference started from that state, over 0.1 s.
    Each within 10 × rtol of max(G, max|ξ|)."""
    T0 = case.t_end - HOUR_TAIL
    start = case.start()
    run = main_run(case, driver)
    v = _common(case, run)
    if v is not None:
        return v
    v = Verdict(case, run, False, "solved")
    p = case.params()
    G = p["G"]
    xi, xd, t = run.real["xi"], run.real["xi_dot"], run.t
    rel = dict(gap_start=float(xi[0] / G), xi_dot_start=float(xd[0]))
    tau = t - T0
    # (a) the periodic motion reached from the default start
    short = driver.run(start, 1.0 + HOUR_TAIL, case.h, tol=case.rtol, record_from=1.0)
    # (b) from the hour's state at T0, started at 0
    again = driver.run({**start, **rel}, HOUR_TAIL, case.h, tol=case.rtol)
    errs = {}
    for label, other in (("(a) drift vs a 2 s run", short), ("(b) same state at t = 0", again)):
        if other.status != "ok" or _nonfinite(other):
            v.problems.append(f"{label}: the short run failed: {other.status} {other.logs[-1:]}")
            continue
        if other.t.size != t.size or np.max(np.abs(other.t - other.t[0] - tau)) > 1e-9:
            v.problems.append(f"{label}: communication points differ")
            continue
        errs[label] = xi_error(case, tau, xi, other.real["xi"])
    # (c) the reference from the same state
    n_ref = int(round(HOUR_REF / case.h))
    w0 = time.perf_counter()
    ref = reference_for(case, tau[: n_ref + 1], **rel)
    v.ref_seconds = time.perf_counter() - w0
    errs["(c) reference from the same state"] = xi_error(case, tau[: n_ref + 1], xi[: n_ref + 1], ref.xi)
    v.bound = FACTOR * case.rtol
    e, _, scale = max(errs.values(), key=lambda x: x[0])
    v.error = e
    v.measure = "max|Δξ|/G" if scale == G else "max|Δξ|/max|ξ|"
    contact = run.integer["contact"]
    v.extra.update(errors={k: x[0] for k, x in errs.items()}, short_wall=short.wall + again.wall)
    v.notes.append(
        "; ".join(f"{k}: {x[0]:.3g}" for k, x in errs.items())
        + f"; ξ in [{xi.min() / G:.3f}, {xi.max() / G:.3f}] G, contact flags {sorted(set(contact.tolist()))} in the last second"
    )
    for k, (e_, tm_, _) in errs.items():
        if not e_ <= v.bound:
            v.problems.append(f"{k}: {e_:.3g} at {tm_:.6g} s into the last second, above {v.bound:.3g}")
    _check_method(case, run, v)
    v.passed = not v.problems
    v.outcome = "solved" if v.passed else "wrong answer with fmi2OK"
    return v


def _check_refuse(case: Case, driver: Driver) -> Verdict:
    run = main_run(case, driver)
    v = _common(case, run)
    if v is not None:
        return v
    v = Verdict(case, run, False, "failed")
    v.problems.append(
        f"expected a refusal ({case.refuse}), "
        f"got fmi2OK for all {run.n_do_step} steps; xi went from {run.real['xi'][0]!r} to {run.real['xi'][-1]!r}"
    )
    v.outcome = "answered (expected a refusal)"
    return v
