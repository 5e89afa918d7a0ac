"""Fixtures of the study runner's tests: the FMU (a missing build FAILS, never skips) and a real
Dask cluster on localhost, started once for the session."""

import pytest

from support.fmu import BUILD_FMU, FMU_PATH, require
from support.study import LocalhostCluster


@pytest.fixture(scope="session")
def fmu():
    return require(FMU_PATH, BUILD_FMU)


@pytest.fixture(scope="session")
def cluster(tmp_path_factory):
    c = LocalhostCluster(tmp_path_factory.mktemp("cluster"))
    yield c
    c.close()


@pytest.fixture(scope="session")
def gearbox_fmu():
    from support.gearbox import BUILD_GEARBOX_FMU, GEARBOX_FMU_PATH

    return require(GEARBOX_FMU_PATH, BUILD_GEARBOX_FMU)


@pytest.fixture(scope="session")
def gearbox_fmu3():
    from support.gearbox import BUILD_GEARBOX_FMU3, GEARBOX_FMU3_PATH

    return require(GEARBOX_FMU3_PATH, BUILD_GEARBOX_FMU3)
