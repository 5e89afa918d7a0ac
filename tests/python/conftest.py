"""Shared fixtures for the Python tests.

The FMU tests need target/fmu/GearRattle.fmu: when it is missing they FAIL (never skip)
with a message telling how to build it, so that a missing build cannot pass silently."""

import pytest

from gearrattle import fmpy_run
from gearrattle import reference as R
from support.fmu import BUILD_FMU, FMU_PATH, OUTPUTS, main_shaft_input, session_fixtures


fmu_path, model_description, unzipdir, vrs = session_fixtures(
    FMU_PATH, BUILD_FMU, ("fmu_path", "model_description", "unzipdir", "vrs"))


@pytest.fixture
def slave(unzipdir, model_description, vrs):
    """slave(name, start_time=0.0, tolerance=None, **start) -> an fmpy FMU2Slave, instantiated
    and initialised with the start values `start` (an int sets an Integer), freed after the
    test."""
    from fmpy.fmi2 import FMU2Slave

    made = []

    def make(name, start_time=0.0, tolerance=None, **start):
        fmu = FMU2Slave(guid=model_description.guid, unzipDirectory=unzipdir,
                        modelIdentifier=model_description.coSimulation.modelIdentifier, instanceName=name)
        fmu.instantiate()
        made.append(fmu)
        fmu.setupExperiment(tolerance=tolerance, startTime=start_time)
        fmu.enterInitializationMode()
        for n, v in start.items():
            (fmu.setInteger if isinstance(v, int) else fmu.setReal)([vrs[n]], [v])
        fmu.exitInitializationMode()
        return fmu

    yield make
    for fmu in made:
        fmu.freeInstance()


@pytest.fixture(scope="session")
def fmu_run(unzipdir, model_description):
    """run(mode, scene, t_end, dt, fields=..., tol=None, **overrides) -> fmpy result, cached.

    mode 'sine': excitation = 1 with the scene's f_exc / A_rms; mode 'inputs': excitation = 0
    (default) driven by the analytic main-shaft motion given as inputs `fields` at dt.
    The communication step and the output interval are both dt; tol: the relative tolerance
    (None: the model description's default, 1e-6). overrides: other parameters (start
    values; in inputs mode omega_mean, f_exc, A_rms shape the input signal instead)."""
    cache = {}

    def run(mode: str, scene: str, t_end: float, dt: float = 1e-4, fields=("theta_M", "omega_M", "alpha_M"), tol=None, **overrides):
        key = (mode, scene, t_end, dt, tuple(fields), tol, tuple(sorted(overrides.items())))
        if key not in cache:
            sc = R.SCENES[scene]
            if mode == "sine":
                start = {"excitation": 1, "f_exc": sc["f_exc"], "A_rms": sc["A_rms"], **overrides}
                inp = None
            elif mode == "inputs":
                shaft = {k: overrides.pop(k) for k in ("omega_mean", "f_exc", "A_rms") if k in overrides}
                start = dict(overrides)  # excitation = 0 is the default
                inp = main_shaft_input(scene, t_end, dt, fields, **shaft)
            else:
                raise ValueError(mode)
            cache[key] = fmpy_run.simulate(unzipdir, t_end, dt, OUTPUTS, tol=tol, inputs=inp,
                                              model_description=model_description, **start)
        return cache[key]

    return run
