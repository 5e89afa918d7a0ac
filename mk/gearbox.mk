# GearboxRattle (docs/GEARBOX.md), built by `make fmu`: its tests' prerequisites, and
# `make bench-gearbox`, a benchmark that prints its figures and writes them into
# docs/GEARBOX.md's benchmark section, docs/gearbox_cost.png and docs/gearbox_work_precision.png
# (no timed assertion; 5-8 min on the 2-core machine, most of it scipy's work-precision sweep
# and the 1 000-point rattle map). Its Python (benches/gearbox) runs with benches/ on the
# import path (BENCH_PY, mk/bench.mk).

.PHONY: bench-gearbox

# tests/gearbox is in pytest's testpaths: `make test-python` runs it on this FMU (and on the
# Flywheel partner's, coupled by libcosim and Ecos).
$(PYTEST_PARTS): $(GEARBOX_FMU)

## bench-gearbox: the gearbox's cost against its gears one by one, scipy at equal error, a map, n_gears
bench-gearbox: fmu $(VENV)/.installed
	$(BENCH_PY) scripts/bench_gearbox.py
