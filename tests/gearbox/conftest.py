"""Shared fixtures of the GearboxRattle FMU tests.

The tests need target/fmu/GearboxRattle.fmu: when it is missing they FAIL (never skip) with
how to build it, so that a missing build cannot pass silently."""

import pytest

from support.fmu import session_fixtures
from support.gearbox import BUILD_GEARBOX_FMU, GEARBOX_FMU_PATH, gearbox_run


gearbox_fmu, box_md, box_unzipdir, box_vrs = session_fixtures(
    GEARBOX_FMU_PATH, BUILD_GEARBOX_FMU, ("gearbox_fmu", "box_md", "box_unzipdir", "box_vrs"))


@pytest.fixture(scope="session")
def box_run(box_unzipdir, box_md):
    """run(t_end, dt, fmi_type="CoSimulation", tol=None, inputs=None, **start) -> fmpy's
    result, cached per session (see support.gearbox.gearbox_run)."""
    cache = {}

    def run(t_end, dt=1e-4, fmi_type="CoSimulation", tol=None, inputs=None, **start):
        key = (t_end, dt, fmi_type, tol, None if inputs is None else id(inputs), tuple(sorted(start.items())))
        if key not in cache:
            cache[key] = gearbox_run(box_unzipdir, box_md, t_end, dt, fmi_type, tol, inputs, **start)
        return cache[key]

    return run
