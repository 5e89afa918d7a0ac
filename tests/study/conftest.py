"""Fixtures of the study runner's tests: the FMU (a missing build FAILS, never skips) and a real
Dask cluster on localhost, started once for the session."""

import pytest

from support.fmu import FMU_PATH
from support.study import LocalhostCluster


@pytest.fixture(scope="session")
def fmu():
    if not FMU_PATH.is_file():
        pytest.fail(f"{FMU_PATH} is missing: build it with `make fmu`")
    return str(FMU_PATH)


@pytest.fixture(scope="session")
def cluster(tmp_path_factory):
    c = LocalhostCluster(tmp_path_factory.mktemp("cluster"))
    yield c
    c.close()


@pytest.fixture(scope="session")
def gearbox_fmu():
    from support.gearbox import GEARBOX_FMU_PATH

    if not GEARBOX_FMU_PATH.is_file():
        pytest.fail(f"{GEARBOX_FMU_PATH} is missing: build it as tests/gearbox/conftest.py says")
    return str(GEARBOX_FMU_PATH)
