# GearboxRattle (docs/GEARBOX.md), built by `make fmu`: its tests' prerequisites, and
# `make bench-gearbox`, a benchmark that prints its figures and writes them into
# docs/GEARBOX.md's benchmark section and docs/gearbox_cost.png (no timed assertion; about
# 4 min on the 2-core machine, most of it the 1 000-point rattle map).

.PHONY: bench-gearbox

# tests/gearbox is in pytest's testpaths: `make test-python` runs it on this FMU (and on the
# Flywheel partner's, coupled by libcosim and Ecos).
test-python: $(GEARBOX_FMU)

## bench-gearbox: the gearbox's cost against its gears one by one, scipy, a map, n_gears
bench-gearbox: fmu $(VENV)/.installed
	$(BENCH_PY) scripts/bench_gearbox.py
