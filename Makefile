# GearRattle: the two commands a newcomer needs are `make demo` and `make test`.
# Each target installs what it needs on a fresh Debian machine with Rust and Python 3:
# libclang (for fmi-sys's bindgen) through apt-get when missing, and a .venv with the
# pinned Python packages of requirements-demo.txt and requirements.txt.

SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
FMU := target/fmu/GearRattle.fmu
GEARBOX_FMU := target/fmu/GearboxRattle.fmu
# The models whose FMU comes in FMI 3.0 too, in target/fmu/fmi3/ (the same binaries, fmi3-shell's exports).
FMU3_MODELS := GearRattle GearboxRattle
# The host build of GearRattle's library (the benchmarks step it from C).
LIB := target/release/libgear_rattle.so
# The FMUs `make fmu` builds, by model identifier, and the crate of each one's binary.
MODELS := GearRattle GearboxRattle
crate_GearRattle := gear_rattle_fmu
crate_GearboxRattle := gearbox_rattle_fmu
CRATES := $(foreach m,$(MODELS),$(crate_$(m)))
# The FMU's binaries as built (with line tables, for debugging) and as packaged (stripped).
FMU_DEBUG := target/fmu/debug
FMU_STRIPPED := target/fmu/stripped
# The tests and packaging build in cargo's `quick` profile (Cargo.toml): release's optimization
# without its LTO, which is for the FMUs' binaries alone. cargo and rustdoc are not told of
# make's jobserver: under make test's -j2 the recipe cannot reach it (mk/hardening.mk's fuzz).
CARGO_TEST := MAKEFLAGS= cargo test --profile quick
PACKAGE := cargo run --profile quick --quiet -p packaging --bin package --
# Fragments in mk/ (one per capability: windows, benchmarks, rattle map) add to these;
# FMU_PLATFORMS: the platforms of the FMUs' binaries as PLATFORM:EXTENSION (linux64:so...).
FMU_PLATFORMS :=
# pytest runs in two parts, so that make test's -j2 keeps both cores busy to its end: the FMUs'
# own suites (every testpath of pytest.ini but the two below), and the studies' and the
# masters' (docs/DEVELOPING.md). `make test-python` runs both.
PYTEST_LAST := tests/study tests/masters
PYTEST_PARTS := test-python-fmus test-python-tools
TEST_TARGETS := test-rust

.PHONY: all fmu demo test test-rust test-python $(PYTEST_PARTS) setup clean

all: fmu

# Included before the rules so that the fragments' prerequisites are seen.
include $(wildcard mk/*.mk)
# The parts start longest first (the FMUs' pytest, the fuzzer's build and run, the studies'
# pytest: docs/DEVELOPING.md has their times), the short ones after them.
LONGEST_PARTS := test-python-fmus fuzz test-python-tools
TEST_TARGETS := $(LONGEST_PARTS) $(filter-out $(LONGEST_PARTS),$(TEST_TARGETS))

## fmu: build target/fmu/GearRattle.fmu and GearboxRattle.fmu (FMI 2.0) and the same in target/fmu/fmi3/ (FMI 3.0), linux64, darwin64, win64
fmu: $(foreach m,$(MODELS),target/fmu/$(m).fmu) $(foreach m,$(FMU3_MODELS),target/fmu/fmi3/$(m).fmu)

# The fragments build the binaries and name their platforms in FMU_PLATFORMS: mk/portable.mk
# linux64 (for glibc 2.17) and darwin64 with zig, mk/windows.mk win64.
# $(call binary,MODEL,PLATFORM:EXTENSION): the stripped binary of MODEL for that platform.
binary = $(FMU_STRIPPED)/$(word 1,$(subst :, ,$(2)))/$(1).$(word 2,$(subst :, ,$(2)))
# $(call binaries,MODEL): all of them; $(call package_flags,MODEL): the packaging binary's
# options naming them (--lib for linux64, --PLATFORM else).
binaries = $(foreach p,$(FMU_PLATFORMS),$(call binary,$(1),$(p)))
package_option = $(if $(filter linux64:%,$(1)),--lib,--$(word 1,$(subst :, ,$(1))))
package_flags = $(foreach p,$(FMU_PLATFORMS),$(call package_option,$(p)) $(call binary,$(1),$(p)))
PACKAGING_SOURCES = $(wildcard packaging/src/*.rs packaging/src/bin/*.rs)

# $(call fmu_rule,MODEL,EDITION,FOLDER): the rule of FOLDER/MODEL.fmu, FMI EDITION (2 or 3).
define fmu_rule
$(3)/$(1).fmu: $(call binaries,$(1)) $(PACKAGING_SOURCES) | libclang
	$(PACKAGE) --model $(1) --fmi $(2) $(call package_flags,$(1)) --out $$@
endef
$(foreach m,$(MODELS),$(eval $(call fmu_rule,$(m),2,target/fmu)))
$(foreach m,$(FMU3_MODELS),$(eval $(call fmu_rule,$(m),3,target/fmu/fmi3)))

# The host's cdylib of a crate (target/release/lib<crate>.so), for the demo's FMUs and the
# benchmarks, built alone like the packaged ones: the crates' own crate type is rlib, so that
# the gearbox, which links gear_rattle, does not build a second cdylib of it. cargo decides
# what to rebuild; this rule always asks it.
target/release/lib%.so: FORCE | libclang
	cargo rustc --release -p $* --lib --crate-type cdylib

FORCE:

# The demo's FMUs: the host's linux64 binary alone (target/release), packaged as `make fmu`
# packages the shipped ones, so that the first result waits for no cross build
# (docs/DEVELOPING.md).
HOST_FMU := target/fmu/host
define host_fmu_rule
$(HOST_FMU)/$(1).fmu: target/release/lib$(crate_$(1)).so
	$$(PACKAGE) --model $(1) --lib $$< --out $$@
endef
$(foreach m,$(MODELS),$(eval $(call host_fmu_rule,$(m))))

## demo: the bench scenes, then the gearbox, through fmpy (summaries, plots, sounds in target/demo), then `make fmu`
demo: $(VENV)/.demo-installed $(HOST_FMU)/GearRattle.fmu
	$(PY) scripts/demo.py --fmu $(HOST_FMU)/GearRattle.fmu --out target/demo
	$(MAKE) --no-print-directory $(HOST_FMU)/GearboxRattle.fmu
	$(PY) scripts/demo.py --scenes "" --box-fmu $(HOST_FMU)/GearboxRattle.fmu --out target/demo
	@echo "demo: done; the FMUs for linux64, darwin64 and win64 are built next (make fmu)"
	$(MAKE) --no-print-directory fmu

## test: every test: Rust (cargo test) and the FMU as a user runs it (pytest + fmpy)
# What the parts install (apt-get, rustup, pip, cargo install) is installed first, one at a
# time (apt-get and rustup take locks); then the builds, on both cores (cargo spreads them);
# then the parts two at a time, since pytest and the fuzzer's run keep one core each. Each
# part's output is printed whole when it ends (docs/DEVELOPING.md).
TEST_TOOLS := libclang $(VENV)/.installed zig-toolchain llvm-tools windows-toolchain windows-wine \
	valgrind libtbb fuzz-tools
# The fuzzer's run ends the parts in a fresh clone: make test gives it 40 s (make fuzz 60).
TEST_FUZZ_SECONDS := 40
test: | $(TEST_TOOLS)
	$(MAKE) --no-print-directory test-builds
	$(MAKE) --no-print-directory -j2 --output-sync=target FUZZ_SECONDS=$(TEST_FUZZ_SECONDS) $(TEST_TARGETS)

.PHONY: test-builds
test-builds: fmu $(FLYWHEEL_FMU)
	$(CARGO_TEST) --no-run -p gear_rattle -p gearbox_rattle -p fmi2-shell -p fmi3-shell -p flywheel

# The C-API tests load the FMU's linux64 binary as cargo-zigbuild builds it (mk/portable.mk):
# the library shipped, and no second release build of it. fmi2-shell's own tests check FMI's
# rules on a model of their own, fmi3-shell's its state table.
CAPI_LIB = $(call linux_so,$(crate_GearRattle))
test-rust: $(CAPI_LIB) | libclang
	GEAR_RATTLE_CDYLIB=$(abspath $(CAPI_LIB)) $(CARGO_TEST) -p gear_rattle -p gearbox_rattle -p fmi2-shell -p fmi3-shell

test-python: $(PYTEST_PARTS)
$(PYTEST_PARTS): fmu $(VENV)/.installed
# Each part keeps its own pytest cache: the two run at the same time.
test-python-fmus:
	$(PY) -m pytest -q -o cache_dir=.pytest_cache/$@ $(foreach d,$(PYTEST_LAST),--ignore-glob='$(d)/*')
test-python-tools:
	$(PY) -m pytest -q -o cache_dir=.pytest_cache/$@ $(PYTEST_LAST)

setup: libclang $(VENV)/.installed

# The demo's packages first (requirements-demo.txt), so that `make demo` starts on them alone;
# everything else on top (requirements.txt includes them).
$(VENV)/.demo-installed: requirements-demo.txt
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -r requirements-demo.txt
	touch $@

$(VENV)/.installed: requirements.txt $(VENV)/.demo-installed
	$(PY) -m pip install --quiet --disable-pip-version-check -r requirements.txt
	touch $@

# $(1): a Debian package, $(2): a shell test that succeeds when it is installed.
# Installs it with apt-get when root, else says how and stops.
define apt_install
	@if $(2); then :; \
	elif [ "$$(id -u)" = 0 ]; then \
		echo "$(1) missing: installing it with apt-get"; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $(1) >/dev/null; \
	else \
		echo "$(1) is missing: run 'sudo apt-get install $(1)', then retry"; \
		exit 1; \
	fi
endef

# fmi-sys generates its bindings with bindgen, which loads libclang at build time.
.PHONY: libclang
libclang:
	@if compgen -G '/usr/lib/llvm-*/lib/libclang.so' >/dev/null || [ -n "$$LIBCLANG_PATH" ]; then :; \
	elif [ "$$(id -u)" = 0 ]; then \
		echo "libclang missing: installing libclang-dev with apt-get"; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libclang-dev >/dev/null; \
	else \
		echo "libclang is missing: run 'sudo apt-get install libclang-dev' (or set LIBCLANG_PATH), then retry"; \
		exit 1; \
	fi

clean:
	cargo clean
	rm -rf $(VENV)
