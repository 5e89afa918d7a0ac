"""GearRattle's inputs mode driven through fmpy, in either interface and edition, on a
main-shaft motion of two harmonics sampled every dt, against the independent reference
(docs/MODEL_EXCHANGE.md, "Inputs"; docs/DECISIONS.md D48).

Model Exchange is run three ways: fmpy's Input (it sets the inputs in CVode's root function
only), and the inputs set at every fmi2SetTime (fmi3SetTime) from the samples interpolated
linearly, from a cubic Hermite interpolant of the samples of ω_M and α_M, or from the exact
functions. `python -m gearrattle.me_inputs FMU [t_end]` prints max |Δξ| / G of each within
the first 2 ms and over t_end.
"""

from __future__ import annotations

import math
import sys

import numpy as np

from . import reference as R

G = R.DEFAULTS["G"]
# The fundamental (rad/s), the two harmonics' speed amplitudes (rad/s), the second's phase.
W, OMEGA_1, OMEGA_2, PHASE_2 = 2 * math.pi * 40.0, 3.0, 1.5, 0.7


def shaft(t):
    """θ_M, ω_M, α_M of the two harmonics at t (θ_M(0) = 0)."""
    t = np.asarray(t, dtype=float)
    w2 = 2 * W * t + PHASE_2
    theta = -OMEGA_1 / W * np.sin(W * t) - OMEGA_2 / (2 * W) * (np.sin(w2) - math.sin(PHASE_2))
    omega = -OMEGA_1 * np.cos(W * t) - OMEGA_2 * np.cos(w2)
    alpha = OMEGA_1 * W * np.sin(W * t) + 2 * W * OMEGA_2 * np.sin(w2)
    return theta, omega, alpha


def grid(t_end: float, dt: float) -> np.ndarray:
    return np.arange(int(round(t_end / dt)) + 1) * dt


def exact(t):
    return shaft(t)[:2]


def linear(t_end: float, dt: float):
    """θ_M and ω_M each interpolated linearly between the samples, as fmpy's Input does."""
    t = grid(t_end, dt)
    theta, omega, _ = shaft(t)
    return lambda s: (np.interp(s, t, theta), np.interp(s, t, omega))


def hermite(t_end: float, dt: float):
    """ω_M by cubic Hermite interpolation of the samples of ω_M and α_M (a continuous
    derivative), θ_M its integral."""
    from scipy.interpolate import CubicHermiteSpline

    t = grid(t_end, dt)
    _, omega, alpha = shaft(t)
    w = CubicHermiteSpline(t, omega, alpha)
    theta = w.antiderivative()
    return lambda s: (theta(s), w(s))


def signals(t_end: float, dt: float, fields=("theta_M", "omega_M")):
    """fmpy's structured input array of the samples."""
    t = grid(t_end, dt)
    values = dict(zip(("theta_M", "omega_M", "alpha_M"), shaft(t)))
    sig = np.zeros(t.size, dtype=[("time", float)] + [(f, float) for f in fields])
    sig["time"] = t
    for f in fields:
        sig[f] = values[f]
    return sig


def reference(t_end: float, dt: float) -> np.ndarray:
    """ξ of the independent reference on the grid, the shaft's motion as exact functions."""
    res = R.simulate(R.params(), t_end, t_eval=grid(t_end, dt), shaft=lambda t: tuple(float(v) for v in shaft(t)[1:]))
    return res.xi


def driven(base):
    """An fmpy Model Exchange class (FMU2Model or FMU3Model) that sets θ_M and ω_M from
    `inputs(t)` at every setTime, so in CVode's right-hand side too, and in initialisation."""

    class Driven(base):
        def __init__(self, inputs, vrs, **kw):
            super().__init__(**kw)
            self.inputs, self.vrs = inputs, vrs
            self.set_inputs = self.setReal if base.__name__ == "FMU2Model" else self.setFloat64

        def apply(self, t):
            self.set_inputs(self.vrs, [float(v) for v in self.inputs(t)])

        def setTime(self, time):
            super().setTime(time)
            self.apply(time)

        def enterInitializationMode(self, **kw):
            super().enterInitializationMode(**kw)
            self.apply(0.0)

    Driven.__name__ = base.__name__ + "Driven"  # fmpy loads the C functions by the class's prefix
    return Driven


def me_driven(unzipdir, md, inputs, t_end: float, dt: float, rtol: float) -> np.ndarray:
    """ξ on the grid, Model Exchange by fmpy's CVode, the inputs set at every setTime."""
    from fmpy.fmi2 import FMU2Model
    from fmpy.fmi3 import FMU3Model
    from fmpy.simulation import simulateME

    base = FMU2Model if md.fmiVersion == "2.0" else FMU3Model
    vrs = [next(v.valueReference for v in md.modelVariables if v.name == n) for n in ("theta_M", "omega_M")]
    fmu = driven(base)(inputs, vrs, guid=md.guid, unzipDirectory=unzipdir,
                       modelIdentifier=md.modelExchange.modelIdentifier, instanceName="driven")
    fmu.instantiate()
    try:
        return simulateME(md, fmu, 0.0, t_end, "CVode", None, rtol, {}, False, None, ["xi"], dt,
                          False, None, None, True, True)["xi"]
    finally:
        fmu.freeInstance()


def fmpy_input(unzipdir, md, sig, t_end: float, dt: float, rtol: float | None, fmi_type: str) -> np.ndarray:
    """ξ on the grid with fmpy's Input (Model Exchange: CVode at rtol; Co-Simulation: steps
    of dt, the FMU's default tolerance)."""
    from fmpy import simulate_fmu

    return simulate_fmu(unzipdir, model_description=md, fmi_type=fmi_type, solver="CVode", stop_time=t_end,
                        step_size=dt, output_interval=dt, relative_tolerance=rtol, input=sig, output=["xi"],
                        record_events=False)["xi"]


def main(fmu: str, t_end: float = 0.1, dt: float = 1e-5):
    from fmpy import extract, read_model_description

    md, unzipdir = read_model_description(fmu), extract(fmu)
    xi_ref, early = reference(t_end, dt), grid(t_end, dt) <= 2e-3
    runs = [("co-simulation, theta_M, omega_M, alpha_M", lambda: fmpy_input(
                unzipdir, md, signals(t_end, dt, ("theta_M", "omega_M", "alpha_M")), t_end, dt, None, "CoSimulation")),
            ("co-simulation, theta_M, omega_M", lambda: fmpy_input(
                unzipdir, md, signals(t_end, dt), t_end, dt, None, "CoSimulation"))]
    for rtol in (1e-8, 1e-9):
        runs.append((f"fmpy's Input, rtol {rtol:g}", lambda rtol=rtol: fmpy_input(
            unzipdir, md, signals(t_end, dt), t_end, dt, rtol, "ModelExchange")))
        for name, inputs in (("linear", linear(t_end, dt)), ("Hermite", hermite(t_end, dt)), ("exact", exact)):
            runs.append((f"{name} at every setTime, rtol {rtol:g}", lambda rtol=rtol, inputs=inputs: me_driven(
                unzipdir, md, inputs, t_end, dt, rtol)))
    for name, run in runs:
        try:
            err = np.abs(run() - xi_ref) / G
            print(f"{name:45s} first 2 ms {err[early].max():.1e} G, {t_end:g} s {err.max():.1e} G", flush=True)
        except Exception as ex:  # CVode's failures (mxstep) are a result too
            print(f"{name:45s} failed: {ex}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1], *(float(a) for a in sys.argv[2:3]))
