"""An fmpy instance's FMI calls as bare ctypes functions, for loops that call them thousands of
times (the sound's fine grid, the benches): no fmpy wrapper and no pointer object a call,
the value arrays passed as addresses (ints). And the FMUs' sampling entry SAMPLED
(fmi2-shell/src/fmu/sampled.rs, outside FMI): a run of fmi2DoSteps of one interval with Real
variables read after each, in one call (docs/SOUND.md, "The force")."""

import ctypes

import numpy as np

SAMPLED = "gearRattleDoStepSampled"

P = ctypes.c_void_p


def raw_calls(inst):
    """fmi2DoStep, fmi2GetReal and fmi2GetInteger of an fmpy instance."""
    return (bare(inst, "fmi2DoStep", P, ctypes.c_double, ctypes.c_double, ctypes.c_int),
            bare(inst, "fmi2GetReal", P, P, ctypes.c_size_t, P),
            bare(inst, "fmi2GetInteger", P, P, ctypes.c_size_t, P))


def sampled_call(inst):
    """SAMPLED (component, t, dt, nSamples, vr, nvr, values), or None where the FMU's binary
    does not export it."""
    if not hasattr(inst.dll, SAMPLED):
        return None
    return bare(inst, SAMPLED, P, ctypes.c_double, ctypes.c_double, ctypes.c_size_t, P,
                ctypes.c_size_t, P)


def bare(inst, name, *args):
    """The instance's library function `name` taking `args`, returning an fmi2Status."""
    return ctypes.CFUNCTYPE(ctypes.c_int, *args)(
        ctypes.cast(getattr(inst.dll, name), ctypes.c_void_p).value)


def sample(inst, vrs, t0: float, h: float, n: int) -> np.ndarray:
    """The Real variables `vrs` at t0 and after each of n steps of h, (n + 1, len(vrs)): one
    SAMPLED call where the FMU has it, else fmi2DoStep and fmi2GetReal at every point."""
    m = len(vrs)
    vr = (ctypes.c_uint * m)(*vrs)
    out = np.empty((n + 1, m))
    comp, v, at = inst.component, ctypes.addressof(vr), out.ctypes.data
    do_step, get_real, _ = raw_calls(inst)
    get_real(comp, v, m, at)
    sampled = sampled_call(inst)
    if sampled is not None:
        check(sampled(comp, t0, h, n, v, m, at + 8 * m), SAMPLED, t0)
        return out
    for k in range(n):
        check(do_step(comp, t0 + k * h, h, 1), "fmi2DoStep", t0 + k * h)
        get_real(comp, v, m, at + 8 * m * (k + 1))
    return out


def check(status, name, t):
    """Raises, naming the call and the time, when an FMI call did not return fmi2OK."""
    if status != 0:
        raise RuntimeError(f"{name} at t = {t:.9g} s returned status {status}")
