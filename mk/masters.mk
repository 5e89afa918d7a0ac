# Masters: GearRattle coupled with a drivetrain partner FMU, partners/flywheel
# (an engine flywheel with firing acyclism driving the main shaft through a clutch damper),
# in fmpy, libcosim and Ecos, against a monolithic reference (tests/masters, run by pytest
# with the Python tests), and the coupling-error study (`make coupling-study`, not in `make test`).
# Installs what it needs when missing: Debian's libtbb12 for Ecos (apt-get when root); the
# masters' PyPI packages are pinned in requirements.txt.

FLYWHEEL_FMU := target/fmu/Flywheel.fmu
FLYWHEEL_LIB := target/quick/libflywheel.so

TEST_TARGETS += test-flywheel

.PHONY: flywheel-fmu test-flywheel test-masters coupling-study libtbb

## flywheel-fmu: build target/fmu/Flywheel.fmu, the drivetrain partner (linux64)
flywheel-fmu: $(FLYWHEEL_FMU)

# cargo decides what to rebuild; the model description is written from src/model.rs. A test
# partner, built in the tests' `quick` profile (Cargo.toml): no release build of its own.
$(FLYWHEEL_FMU): FORCE
	cargo build --profile quick -p flywheel
	$(PACKAGE) --model Flywheel --lib $(FLYWHEEL_LIB) --out $@

# The master tests live in pytest's testpaths: `make test-python` runs them, so it needs
# the partner FMU and the Ecos runtime library too.
$(PYTEST_PARTS): $(FLYWHEEL_FMU) | libtbb

## test-flywheel: the partner's own Rust tests (cargo test -p flywheel)
test-flywheel:
	$(CARGO_TEST) -p flywheel

## test-masters: only the coupled runs in fmpy, libcosim and Ecos (tests/masters)
test-masters: fmu $(FLYWHEEL_FMU) $(VENV)/.installed | libtbb
	$(PY) -m pytest -q tests/masters

## coupling-study: coupling error vs communication step, and Model Exchange vs tolerance -> docs/COUPLING.md, docs/coupling_error.png
coupling-study: fmu $(FLYWHEEL_FMU) $(VENV)/.installed | libtbb
	$(PY) scripts/coupling_study.py --out docs

# Ecos's libecosc.so links against oneTBB's libtbb.so.12 (Debian: libtbb12).
libtbb:
	@if compgen -G '/usr/lib/*/libtbb.so.12*' >/dev/null || compgen -G '/lib/*/libtbb.so.12*' >/dev/null; then :; \
	elif [ "$$(id -u)" = 0 ]; then \
		echo "libtbb12 missing (Ecos needs it): installing it with apt-get"; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends libtbb12 >/dev/null; \
	else \
		echo "libtbb12 is missing (Ecos needs it): run 'sudo apt-get install libtbb12', then retry"; \
		exit 1; \
	fi
