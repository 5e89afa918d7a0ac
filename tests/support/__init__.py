"""What the test suites share (pytest.ini puts tests/ on the import path, so
a test imports `from support.fmu import ...`): the FMU's paths and its contract's outputs
(support.fmu), the study runner run as a user runs it and a Dask cluster on localhost
(support.study). Fixtures live in each suite's conftest.py."""
