"""The drivetrain of docs/COUPLING.md integrated monolithically through GearRattle's Model
Exchange interface: one state vector, one solver, the FMU's event indicators as events.

GearRattle runs in its inputs mode (excitation = 0): it reads the main shaft's theta_M and
omega_M as inputs and gives the contact's torque on the shaft, tau_M = r_M F. The main shaft,
the clutch damper and the engine around it are monolithic.drivetrain, the reference's own
equations. The inputs mode rather than the torque mode (excitation = 2, the shaft inside the
FMU driven by tau_in): the FMU then runs with the connections of the co-simulation rows
(theta_M, omega_M in, tau_M out), so that the comparison changes the coupling only, and the
shaft's equation is the reference's. There is no algebraic loop: with omega_L a state,
tau_M depends on the states and on theta_M, omega_M, not on alpha_M (docs/MODEL_EXCHANGE.md).

State vector y = [x (GearRattle's nx states, docs/MODEL_EXCHANGE.md), theta_M, omega_M, phi,
omega_E], phi = theta_E - theta_M as in monolithic.py. One evaluation of the right-hand side
is fmi2SetTime, fmi2SetReal(theta_M, omega_M), fmi2SetContinuousStates, fmi2GetDerivatives,
fmi2GetReal(tau_M), then the drivetrain's accelerations. The Jacobian of the whole state vector
(`Drivetrain.jac`, passed to the solver unless `simulate(jacobian=False)`) is exact: the gear
pair's block from fmi2GetDirectionalDerivative at the point set the same way, the
drivetrain's from monolithic.drivetrain_partials, tau_M's partials entering the main shaft's
acceleration by the chain rule; the implicit solvers then form no Jacobian by differences of
the right-hand side.

The solver is one of scipy's (LSODA by default: Adams in flight, BDF where the contact makes
it stiff), stepped by hand so that the FMI 2.0 sequence is the importer's:
- after each accepted step the event indicators are compared with the step's start (an
  event where one leaves its domain z > 0 or enters it); the earliest crossing is located on
  the step's dense output and the step cut there;
- fmi2CompletedIntegratorStep at the end of every accepted (or cut) step;
- at a state, time or step event: fmi2EnterEventMode, fmi2NewDiscreteStates until no new
  discrete states are needed, fmi2EnterContinuousTimeMode, the states read back, and the
  solver restarted from there (its history is not valid across an event).
"""

from __future__ import annotations

import ctypes
import math
import shutil
import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate import BDF, LSODA, Radau
from scipy.optimize import brentq

from . import masters as MS
from . import monolithic as M

SOLVERS = {"LSODA": LSODA, "BDF": BDF, "Radau": Radau}
# Nominal sizes of theta_M, omega_M, phi, omega_E (rad, rad/s), the reference's own scale.
SHAFT_NOMINALS = (1.0, 100.0, 1e-2, 100.0)
# Width of the bracket an event is located to, relative to the step that straddles it.
EVENT_XTOL = 1e-12


class Drivetrain:
    """GearRattle as Model Exchange inside the drivetrain: the FMU instantiated and
    initialised (both shafts at idle speed, the loose gear at rest in the backlash, as the
    reference starts), the right-hand side, the event indicators and the event iteration on
    the whole state vector. Counts every call into the FMU's equations."""

    def __init__(self, fmu=MS.GEAR_FMU, gear_params: dict | None = None, pf: dict | None = None):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Model

        md = read_model_description(str(fmu))
        vr = {v.name: v.valueReference for v in md.modelVariables}
        self.nx, self.nz = md.numberOfContinuousStates, md.numberOfEventIndicators
        self.i_xi = next(i for i, d in enumerate(md.derivatives) if d.variable.derivative.name == "xi")
        pf = dict(M.FLYWHEEL) if pf is None else pf
        self.accelerations = M.drivetrain(pf)
        self.partials = M.drivetrain_partials(pf)
        self._unzipdir = extract(str(fmu))
        self.fmu = FMU2Model(guid=md.guid, unzipDirectory=self._unzipdir,
                             modelIdentifier=md.modelExchange.modelIdentifier, instanceName="gear")
        self.n_rhs = self.n_indicators = self.n_jacobians = 0
        nx = self.nx
        self.nominals = np.concatenate((np.ones(nx), SHAFT_NOMINALS))  # the FMU's read at each event
        self._x, self._dx, self._z = np.zeros(nx), np.zeros(nx), np.zeros(self.nz)
        ptr = lambda a: a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))  # noqa: E731
        self._px, self._pdx, self._pz = ptr(self._x), ptr(self._dx), ptr(self._z)
        self._vr_shaft = (ctypes.c_uint * 2)(vr["theta_M"], vr["omega_M"])
        self._vr_tau = (ctypes.c_uint * 1)(vr["tau_M"])
        self._vr_counts = (ctypes.c_uint * 2)(vr["impacts_Fplus"], vr["impacts_Fminus"])
        self._shaft, self._tau, self._counts = (ctypes.c_double * 2)(), (ctypes.c_double * 1)(), (ctypes.c_int * 2)()
        # fmi2GetDirectionalDerivative's arguments: unknowns der(x) and tau_M; one call per
        # known (the states, then theta_M, omega_M) with a unit seed, its column written into
        # a row of _columns.
        self._vr_unknowns = (ctypes.c_uint * (nx + 1))(*(d.variable.valueReference for d in md.derivatives), vr["tau_M"])
        knowns = [d.variable.derivative.valueReference for d in md.derivatives] + [vr["theta_M"], vr["omega_M"]]
        self._vr_knowns = [(ctypes.c_uint * 1)(k) for k in knowns]
        self._seed = (ctypes.c_double * 1)(1.0)
        self._columns = np.zeros((nx + 2, nx + 1))
        self._pcolumns = [ptr(row) for row in self._columns]
        f = self.fmu
        f.instantiate()
        try:
            f.setupExperiment(startTime=0.0)
            f.enterInitializationMode()
            gear = {**M.GEAR, **(gear_params or {})}
            f.setReal([vr[k] for k in gear], list(gear.values()))
            # omega_M at idle before initialisation ends: the loose gear starts at rest
            # relative to the shaft turning at that speed (masters.py explains why).
            f.setReal([vr["theta_M"], vr["omega_M"]], [0.0, pf["omega_idle"]])
            f.exitInitializationMode()
            self.next_time_event = self._iterate_events()
            f.getContinuousStates(self._px, nx)
            self.y0 = np.concatenate((self._x, (0.0, pf["omega_idle"], 0.0, pf["omega_idle"])))
        except BaseException:
            self.close()
            raise

    def close(self):
        self.fmu.freeInstance()
        shutil.rmtree(self._unzipdir, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _set(self, t: float, y: np.ndarray):
        """Time, inputs, then states: the states are then taken with the shaft's speed they
        belong to, also by an FMU that derives internal quantities (here ξ' from ω_L and
        ω_M) when the states are set."""
        f = self.fmu
        f.setTime(t)
        self._shaft[0], self._shaft[1] = y[self.nx], y[self.nx + 1]
        f.fmi2SetReal(f.component, self._vr_shaft, 2, self._shaft)
        self._x[:] = y[: self.nx]
        f.setContinuousStates(self._px, self.nx)

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        f, nx = self.fmu, self.nx
        self._set(t, y)
        f.getDerivatives(self._pdx, nx)
        f.fmi2GetReal(f.component, self._vr_tau, 1, self._tau)
        self.n_rhs += 1
        theta_m, om_m, phi, om_e = y[nx:]
        a_m, a_e = self.accelerations(theta_m, phi, om_m, om_e, self._tau[0])
        out = np.empty(nx + 4)
        out[:nx] = self._dx
        out[nx:] = (om_m, a_m, om_e - om_m, a_e)
        return out

    def jac(self, t: float, y: np.ndarray) -> np.ndarray:
        """d rhs / d y at (t, y). Rows nx.. are theta_M' = omega_M, omega_M' = a_M,
        phi' = omega_E - omega_M, omega_E' = a_E; a_M depends on x, theta_M and omega_M also
        through tau_M."""
        f, nx = self.fmu, self.nx
        self._set(t, y)
        for known, column in zip(self._vr_knowns, self._pcolumns):
            f.fmi2GetDirectionalDerivative(f.component, self._vr_unknowns, nx + 1, known, 1, self._seed, column)
        self.n_jacobians += 1
        d_fmu = self._columns.T  # rows der(x), tau_M; columns x, theta_M, omega_M
        d_shaft = self.partials(y[nx], y[nx + 2])  # rows a_M, a_E; columns theta_M, omega_M, phi, omega_E, tau_M
        out = np.zeros((nx + 4, nx + 4))
        out[:nx, : nx + 2] = d_fmu[:nx]
        out[nx, nx + 1] = 1.0
        out[nx + 2, nx + 1], out[nx + 2, nx + 3] = -1.0, 1.0
        accelerations = [nx + 1, nx + 3]
        out[accelerations, nx:] = d_shaft[:, :4]
        out[accelerations, : nx + 2] += np.outer(d_shaft[:, 4], d_fmu[nx])
        return out

    def indicators(self, t: float, y: np.ndarray) -> np.ndarray:
        self._set(t, y)
        self.fmu.getEventIndicators(self._pz, self.nz)
        self.n_indicators += 1
        return self._z.copy()

    def completed_step(self, t: float, y: np.ndarray) -> bool:
        """fmi2CompletedIntegratorStep at (t, y): whether the FMU asks for an event."""
        self._set(t, y)
        enter_event_mode, terminate = self.fmu.completedIntegratorStep()
        if terminate:
            raise RuntimeError(f"GearRattle asked to terminate at t = {t}")
        return enter_event_mode

    def event(self, t: float, y: np.ndarray) -> np.ndarray:
        """The event iteration at (t, y); the state vector after it."""
        self._set(t, y)
        self.fmu.enterEventMode()
        self.next_time_event = self._iterate_events()
        self.fmu.getContinuousStates(self._px, self.nx)
        out = y.copy()
        out[: self.nx] = self._x
        return out

    def _iterate_events(self) -> float:
        """fmi2NewDiscreteStates until no new discrete states are needed, then continuous-time
        mode, and the FMU's nominals read; the next time event (inf: none)."""
        f = self.fmu
        while True:
            needed, terminate, _, _, defined, t_next = f.newDiscreteStates()
            if terminate:
                raise RuntimeError("GearRattle asked to terminate in event mode")
            if not needed:
                break
        f.enterContinuousTimeMode()
        f.getNominalsOfContinuousStates(self.nominals.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), self.nx)
        return t_next if defined else math.inf

    def impact_counts(self) -> tuple[int, int]:
        f = self.fmu
        f.fmi2GetInteger(f.component, self._vr_counts, 2, self._counts)
        return self._counts[0], self._counts[1]


@dataclass
class Cost:
    wall: float  # s
    rhs: int  # right-hand sides: fmi2GetDerivatives calls
    indicators: int  # fmi2GetEventIndicators calls (step ends and event location)
    steps: int  # accepted steps (cut at events included)
    events: int  # event iterations (state, time and step events)
    # The solver's Jacobian evaluations: Drivetrain.jac's (nx + 2 fmi2GetDirectionalDerivative
    # calls each) with the Jacobian, else the solver's differences (at least nx + 4
    # right-hand sides each, counted in rhs too).
    jacobians: int


def simulate(t_end: float, dt: float, rtol: float, method: str = "LSODA", gear_params: dict | None = None,
             pf: dict | None = None, fmu=MS.GEAR_FMU, jacobian: bool = True) -> tuple[dict, Cost]:
    """The drivetrain from its initial state to t_end, sampled at t_n = n dt on the solver's
    dense output: a record with the fields time, theta_M, omega_M, xi, impacts_Fplus,
    impacts_Fminus (those of masters.py's records that Model Exchange has), and the cost.
    Absolute tolerances rtol times the nominal of each state. With `jacobian` the solver gets
    Drivetrain.jac; without, it forms its Jacobians by differences of the right-hand side."""
    started = time.perf_counter()
    n = MS._steps(t_end, dt)
    rec = {k: np.zeros(n + 1) for k in ("time", "theta_M", "omega_M", "xi")}
    rec.update({k: np.zeros(n + 1, dtype=np.int64) for k in MS.GEAR_COUNTS})
    rec["time"] = np.arange(n + 1) * dt
    solver_class = SOLVERS[method]
    steps = events = solver_njev = 0
    with Drivetrain(fmu, gear_params, pf) as dt_:
        nx = dt_.nx

        def sample(k, y, counts):
            rec["xi"][k], rec["theta_M"][k], rec["omega_M"][k] = y[dt_.i_xi], y[nx], y[nx + 1]
            rec["impacts_Fplus"][k], rec["impacts_Fminus"][k] = counts

        t, y = 0.0, dt_.y0
        counts = dt_.impact_counts()
        sample(0, y, counts)
        k = 1
        z = dt_.indicators(t, y)
        while t < t_end:
            solver = solver_class(dt_.rhs, t, y, min(t_end, dt_.next_time_event), rtol=rtol, atol=rtol * dt_.nominals,
                                  jac=dt_.jac if jacobian else None)
            while True:
                t0 = solver.t
                if solver.step() is not None or solver.status == "failed":
                    raise RuntimeError(f"{method} failed at t = {solver.t}")
                steps += 1
                t1, y1 = solver.t, solver.y
                z1 = dt_.indicators(t1, y1)
                dense = None
                state_event = bool(np.any((z > 0) != (z1 > 0)))
                if state_event:
                    dense = solver.dense_output()
                    t1, y1, z1 = _first_crossing(dt_, dense, z, t0, t1, z1)
                while k <= n and rec["time"][k] <= t1:
                    dense = dense or solver.dense_output()
                    sample(k, dense(rec["time"][k]), counts)
                    k += 1
                step_event = dt_.completed_step(t1, y1)
                event = state_event or step_event or t1 >= dt_.next_time_event
                z = z1
                if event or solver.status == "finished":
                    break
            solver_njev += getattr(solver, "njev", 0)
            t, y = t1, y1
            if event and t < t_end:
                y = dt_.event(t, y)
                events += 1
                counts = dt_.impact_counts()
                z = dt_.indicators(t, y)
        jacobians = dt_.n_jacobians if jacobian else int(solver_njev)
        cost = Cost(time.perf_counter() - started, dt_.n_rhs, dt_.n_indicators, steps, events, jacobians)
    return rec, cost


def _first_crossing(dt_: Drivetrain, dense, z0, t0, t1, z1):
    """The earliest domain change of an event indicator within (t0, t1] on the step's dense
    output: (t, y, z) just past it. The indicator whose linear interpolation crosses first is
    located by Brent's method to EVENT_XTOL of the step (or the rounding of t); if another
    one has changed domain before that crossing already, the search goes on before it."""
    domain0 = z0 > 0
    b, zb = t1, z1
    for _ in range(4 * len(z0)):
        changed = np.nonzero(domain0 != (zb > 0))[0]
        i = changed[np.argmin(z0[changed] / (z0[changed] - zb[changed]))]
        ends = {t0: z0[i], b: zb[i]}
        xtol = EVENT_XTOL * (t1 - t0)
        root = brentq(lambda s: ends[s] if s in ends else dt_.indicators(s, dense(s))[i], t0, b, xtol=xtol)
        tol = 2.0 * (xtol + 4.0 * np.finfo(float).eps * abs(root))
        after = min(b, root + tol)
        z_after = dt_.indicators(after, dense(after)) if after < b else zb
        if domain0[i] == (z_after[i] > 0):
            after, z_after = b, zb
        before = root - tol
        if before <= t0:
            break
        z_before = dt_.indicators(before, dense(before))
        if not np.any(domain0 != (z_before > 0)):
            break
        b, zb = before, z_before
    return after, dense(after), z_after
