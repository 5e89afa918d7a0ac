"""Fixtures of the coupled tests: the two FMUs (a missing build FAILS the test, never skips it,
with how to build it), and the coupled test run (masters.T_TEST at masters.H_TEST) of each
master and the monolithic reference sampled at its communication points, each made once per
session."""

import functools

import numpy as np
import pytest

from gearrattle import masters as MS
from gearrattle import monolithic as M
from support.fmu import BUILD_FMU, require


@pytest.fixture(scope="session")
def fmus():
    """(GearRattle.fmu, Flywheel.fmu)."""
    require(MS.GEAR_FMU, BUILD_FMU)
    require(MS.FLYWHEEL_FMU, "`make flywheel-fmu`")
    return MS.GEAR_FMU, MS.FLYWHEEL_FMU


@pytest.fixture(scope="session")
def coupled_reference() -> M.Result:
    n = int(round(MS.T_TEST / MS.H_TEST))
    return M.simulate(MS.T_TEST, np.arange(n + 1) * MS.H_TEST)


@pytest.fixture(scope="session")
def coupled_run(fmus):
    """run(master, inputs="alpha") -> the master's record; `inputs` for fmpy only."""

    @functools.lru_cache(maxsize=None)
    def run(master: str, inputs: str = "alpha") -> dict:
        if master == "fmpy":
            return MS.run_fmpy(MS.T_TEST, MS.H_TEST, inputs=inputs)
        return MS.MASTERS[master](MS.T_TEST, MS.H_TEST)

    return run
