"""Many instances per process, from Python threads through fmpy's low-level API (FMU2Slave):
eight instances, each its own scene, stepped at once on eight threads (ctypes lets go of the
GIL inside each fmi2 call, so the FMU really runs on several threads), each giving the same
bits at every communication point and the same log lines as that scene run alone, and every
log line arriving with its own instance's componentEnvironment.

The logger is a plain ctypes callback (not fmpy's process-wide logger proxy): it receives the
componentEnvironment the FMU hands back, which is what is checked here."""

import threading

import numpy as np
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

from support.fmu import OUTPUTS

INSTANCES = 8
H = 1e-4
STEPS = 1000

# componentEnvironment value -> the lines logged to it: (instance name, status, category, message)
_LINES: dict = {}


def _record(env, instance, status, category, message):
    _LINES.setdefault(env, []).append(
        ((instance or b"").decode("utf-8", "replace"), int(status), (category or b"").decode(), (message or b"").decode())
    )


_LOGGER = fmi2CallbackLoggerTYPE(_record)


def run(unzipdir, md, k: int, env: int, ready: threading.Barrier | None = None):
    """Scene k (S1 in sine mode with its own frequency and start) on a fresh instance whose
    componentEnvironment is `env`, every log category on: every output after every step."""
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    reals = [vrs[n] for n in OUTPUTS if next(v for v in md.modelVariables if v.name == n).type == "Real"]
    callbacks = fmi2CallbackFunctions()
    callbacks.logger = _LOGGER
    callbacks.componentEnvironment = env
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier, instanceName=f"scene{k}")
    fmu.instantiate(callbacks=callbacks, loggingOn=True)
    try:
        fmu.setupExperiment(tolerance=1e-6, startTime=0.0)
        fmu.enterInitializationMode()
        fmu.setInteger([vrs["excitation"]], [1])
        fmu.setReal([vrs["f_exc"], vrs["A_rms"], vrs["gap_start"]], [30.0 + 5.0 * k, 300.0, 0.5 + 0.04 * k])
        fmu.exitInitializationMode()
        if ready is not None:
            ready.wait()
        out = np.empty((STEPS, len(reals)))
        for i in range(STEPS):
            fmu.doStep(currentCommunicationPoint=i * H, communicationStepSize=H)
            out[i] = fmu.getReal(reals)
        fmu.terminate()
    finally:
        fmu.freeInstance()
    return out.view(np.uint64)


def test_eight_instances_on_eight_threads_match_each_run_alone(unzipdir, model_description):
    md = model_description
    alone = [run(unzipdir, md, k, env=1000 + k) for k in range(INSTANCES)]
    together: list = [None] * INSTANCES
    errors = []
    barrier = threading.Barrier(INSTANCES)

    def worker(k):
        try:
            together[k] = run(unzipdir, md, k, env=2000 + k, ready=barrier)
        except Exception as e:  # noqa: BLE001  (reported below, with the scene)
            errors.append((k, e))
            barrier.abort()

    threads = [threading.Thread(target=worker, args=(k,)) for k in range(INSTANCES)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors

    for k in range(INSTANCES):
        diff = np.nonzero(np.any(alone[k] != together[k], axis=1))[0]
        assert diff.size == 0, f"scene {k}: outputs differ from step {diff[:1]} on"
        lines_alone, lines_together = _LINES.get(1000 + k, []), _LINES.get(2000 + k, [])
        assert lines_together, f"scene {k}: no log line with every category on"
        foreign = [line for line in lines_together if line[0] != f"scene{k}"]
        assert not foreign, f"scene {k}'s componentEnvironment got lines of other instances: {foreign[:1]}"
        assert lines_alone == lines_together, f"scene {k}: log lines differ from the run alone"
    # The scenes differ, so a mix-up between instances could not go unseen.
    assert all(not np.array_equal(alone[0][-1], alone[k][-1]) for k in range(1, INSTANCES))
