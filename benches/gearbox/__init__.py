"""The gearbox benchmark (`make bench-gearbox`, mk/gearbox.mk): the FMUs stepped and timed
(`runs`), the box against scipy at equal error (`work_precision`) and the run that prints the
figures and writes them into docs/GEARBOX.md (`report`).
Outside the installed package: scripts/bench_gearbox.py runs with benches/ on the import path
(`PYTHONPATH=benches`, as the Makefile's recipe sets it)."""
