"""What the test suites share (pytest.ini puts tests/ on the import path, so a test imports
`from support.fmu import ...`): the FMUs' paths, the check that one is built and the session
fixtures of one (support.fmu), GearRattle's contract outputs (support.fmu), the gearbox's
runs against its reference (support.gearbox), the study runner run as a user runs it and a
Dask cluster on localhost (support.study). Each suite's conftest.py binds its fixtures."""
