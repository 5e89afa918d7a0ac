# GearRattle: the two commands a newcomer needs are `make demo` and `make test`.
# Each target installs what it needs on a fresh Debian machine with Rust and Python 3:
# libclang (for fmi-sys's bindgen) through apt-get when missing, and a .venv with the
# pinned Python packages of requirements.txt.

SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
FMU := target/fmu/GearRattle.fmu
LIB := target/release/libgear_rattle.so
# Fragments in mk/ (one per capability: windows, benchmarks, rattle map) add to these.
FMU_DEPS :=
PACKAGE_FLAGS :=
TEST_TARGETS := test-rust test-python

.PHONY: all fmu demo test test-rust test-python setup clean

all: fmu

# Included before the rules so that the fragments' prerequisites are seen.
include $(wildcard mk/*.mk)

## fmu: build target/fmu/GearRattle.fmu (linux64)
fmu: $(FMU)

$(FMU): $(LIB) $(FMU_DEPS) src/bin/package.rs
	cargo run --release --quiet --bin package -- --lib $(LIB) $(PACKAGE_FLAGS) --out $(FMU)

# cargo decides what to rebuild; this rule always asks it.
$(LIB): FORCE | libclang
	cargo build --release --lib

FORCE:

## demo: the paper's bench scenes through fmpy: a summary and plots in target/demo
demo: fmu $(VENV)/.installed
	$(PY) scripts/demo.py --fmu $(FMU) --out target/demo

## test: every test: Rust (cargo test) and the FMU as a user runs it (pytest + fmpy)
test: $(TEST_TARGETS)

# The C-API tests load the cdylib, which `cargo test` alone does not produce.
test-rust: $(LIB) | libclang
	cargo test --release

test-python: fmu $(VENV)/.installed
	$(PY) -m pytest -q

setup: libclang $(VENV)/.installed

$(VENV)/.installed: requirements.txt
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -r requirements.txt
	touch $@

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
