"""Shared fixtures of the GearboxRattle FMU tests.

The tests need target/fmu/GearboxRattle.fmu: when it is missing they FAIL (never skip) with
how to build it, so that a missing build cannot pass silently."""

import pytest

from support.gearbox import GEARBOX_FMU_PATH, gearbox_run


@pytest.fixture(scope="session")
def gearbox_fmu() -> str:
    if not GEARBOX_FMU_PATH.is_file():
        pytest.fail(
            f"{GEARBOX_FMU_PATH} does not exist: build it first with "
            "`cargo build --release -p gearbox_rattle && cargo run --release -p packaging -- "
            "--model GearboxRattle --lib target/release/libgearbox_rattle.so "
            "--out target/fmu/GearboxRattle.fmu`, then rerun the tests",
            pytrace=False,
        )
    return str(GEARBOX_FMU_PATH)


@pytest.fixture(scope="session")
def box_md(gearbox_fmu):
    from fmpy import read_model_description

    return read_model_description(gearbox_fmu)


@pytest.fixture(scope="session")
def box_unzipdir(gearbox_fmu, tmp_path_factory) -> str:
    from fmpy import extract

    return extract(gearbox_fmu, unzipdir=str(tmp_path_factory.mktemp("GearboxRattle_fmu")))


@pytest.fixture(scope="session")
def box_vrs(box_md) -> dict:
    """name -> value reference."""
    return {v.name: v.valueReference for v in box_md.modelVariables}


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
