# GearboxRattle (docs/GEARBOX.md): its FMU for this machine, and `make bench-gearbox`, a
# benchmark that prints its figures and writes them into docs/GEARBOX.md's benchmark section
# and docs/gearbox_cost.png (no timed assertion; about 15 min on the 2-core machine, most of
# it the 1 000-point rattle map).

GEARBOX_FMU := target/fmu/GearboxRattle.fmu
GEARBOX_LIB := target/release/libgearbox_rattle.so

.PHONY: gearbox-fmu bench-gearbox

## gearbox-fmu: build target/fmu/GearboxRattle.fmu (this machine's platform)
gearbox-fmu: $(GEARBOX_FMU)

$(GEARBOX_FMU): FORCE | libclang
	cargo build --release -p gearbox_rattle
	cargo run --release --quiet -p packaging --bin package -- --model GearboxRattle --lib $(GEARBOX_LIB) --out $@

# tests/gearbox is in pytest's testpaths: `make test-python` runs it on this FMU (and on the
# Flywheel partner's, coupled by libcosim and Ecos).
test-python: $(GEARBOX_FMU)

## bench-gearbox: the gearbox's cost against its gears one by one, scipy, a map, n_gears
bench-gearbox: $(GEARBOX_FMU) fmu $(VENV)/.installed
	$(PY) scripts/bench_gearbox.py
