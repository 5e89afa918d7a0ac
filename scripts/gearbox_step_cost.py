"""The cost of stepping GearboxRattle at fine communication steps (docs/DECISIONS.md D60): CPU
seconds of 1 s simulated in fmi2DoSteps of 1e-4 s through the bare C API (ctypes), against one
fmi2DoStep over the same second, for two FMUs side by side (interleaved rounds, the best of
each): the default gearbox (excitation 1), and the flywheel's (0) and the input side's (2)
inputs set before each step.

    .venv/bin/python scripts/gearbox_step_cost.py BEFORE.fmu AFTER.fmu [ROUNDS]"""
import ctypes
import shutil
import sys
import time

from fmpy import extract, instantiate_fmu, read_model_description

T, H = 1.0, 1e-4
CASES = {
    "excitation 1 (default)": {},
    "excitation 0, inputs set each step": {"excitation": 0},
    "excitation 2, inputs set each step": {"excitation": 2},
}


def run(unzip, md, params, h):
    """CPU seconds of T simulated in steps of h."""
    inst = instantiate_fmu(unzip, md, fmi_type="CoSimulation")
    vrs = {v.name: v for v in md.modelVariables}
    inst.setupExperiment(startTime=0.0)
    for k, v in params.items():
        inst.setInteger([vrs[k].valueReference], [v])
    inst.enterInitializationMode()
    inst.exitInitializationMode()
    do_step = inst.dll.fmi2DoStep
    do_step.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int]
    set_real = inst.dll.fmi2SetReal
    set_real.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p]
    side = "F" if params.get("excitation") == 0 else "I"
    vr = (ctypes.c_uint * 2)(*[vrs[f"{q}_{side}"].valueReference for q in ("theta", "omega")])
    value = (ctypes.c_double * 2)()
    inputs = "excitation" in params
    c = inst.component
    t0 = time.process_time()
    for k in range(int(round(T / h))):
        t = k * h
        if inputs:
            value[0], value[1] = 84.0 * t, 84.0
            set_real(c, vr, 2, value)
        if do_step(c, t, h, 1) != 0:
            raise RuntimeError(f"fmi2DoStep failed at t = {t}")
    cpu = time.process_time() - t0
    inst.terminate()
    inst.freeInstance()
    return cpu


def main(fmus, rounds):
    for name, params in CASES.items():
        best = {}
        for _ in range(rounds):
            for f in fmus:
                md, unzip = read_model_description(f), extract(f)
                for h in (H, T):
                    best[f, h] = min(best.get((f, h), float("inf")), run(unzip, md, params, h))
                shutil.rmtree(unzip, ignore_errors=True)
        print(name)
        for f in fmus:
            print(f"  {f}: steps of {H} s {best[f, H]:.3f} s CPU, one fmi2DoStep "
                  f"{best[f, T]:.3f} s, ratio {best[f, H] / best[f, T]:.2f}")


if __name__ == "__main__":
    main(sys.argv[1:3], int(sys.argv[3]) if len(sys.argv) > 3 else 5)
