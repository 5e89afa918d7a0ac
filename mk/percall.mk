# Per-call benchmark: `make bench-percall` prints what one fmi2DoStep + fmi2GetReal at 10 µs
# communication steps costs GearRattle on S1, against the Reference FMU Dahlquist
# (modelica/Reference-FMUs) stepped by the same C harness. Not part of `make test`: it makes no
# timed assertion.
#
#   make bench-percall                          the Reference FMUs' sources of release v0.0.39, downloaded
#   make bench-percall REFERENCE_FMUS=PATH      a source tree of them, or its zip
#
# Dahlquist (FMI 2.0) is built from those sources with CMake twice: optimized
# (CMAKE_BUILD_TYPE=Release, -O3) and with CMake's default flags, as the release's linux64
# binary is built (no optimization). docs/DECISIONS.md D56.

REFERENCE_FMUS ?=
REFERENCE_FMUS_VERSION := 0.0.39
REFERENCE_FMUS_URL := https://github.com/modelica/Reference-FMUs/archive/refs/tags/v$(REFERENCE_FMUS_VERSION).zip
PERCALL_DIR := target/bench/percall

.PHONY: bench-percall cmake

## bench-percall: a 10 µs call's cost against the Reference FMU Dahlquist's, from C (prints; REFERENCE_FMUS=PATH)
# GearRattle.fmu with the host's binary alone (the Makefile's HOST_FMU, defined after this file).
bench-percall: target/fmu/host/GearRattle.fmu | cmake valgrind
	@set -e; mkdir -p $(PERCALL_DIR); src='$(REFERENCE_FMUS)'; \
	if [ -z "$$src" ]; then \
		src=$(PERCALL_DIR)/Reference-FMUs-$(REFERENCE_FMUS_VERSION).zip; \
		test -f $$src || $(PYTHON) -c 'import sys, urllib.request; urllib.request.urlretrieve(*sys.argv[1:])' \
			$(REFERENCE_FMUS_URL) $$src \
			|| { echo "$(REFERENCE_FMUS_URL) not downloaded: give REFERENCE_FMUS=PATH"; exit 1; }; \
	fi; \
	if [ -f "$$src" ]; then \
		rm -rf $(PERCALL_DIR)/sources; $(PYTHON) -m zipfile -e $$src $(PERCALL_DIR)/sources; \
		src=$$(dirname $$(ls $(PERCALL_DIR)/sources/CMakeLists.txt $(PERCALL_DIR)/sources/*/CMakeLists.txt 2>/dev/null | head -n 1)); \
	fi; \
	test -f "$$src/Dahlquist/model.c" || { echo "$$src: no Reference FMUs sources (Dahlquist/model.c)"; exit 1; }; \
	for build in optimized:Release default:; do \
		dir=$(PERCALL_DIR)/$${build%%:*}; \
		rm -rf $$dir; cmake -S "$$src" -B $$dir -DFMI_VERSION=2 -DCMAKE_BUILD_TYPE=$${build#*:} >/dev/null; \
		cmake --build $$dir --target Dahlquist >/dev/null; \
	done
	$(CC) -O2 -I benches/study -o $(BENCH_DIR)/overhead benches/overhead/overhead.c -ldl
	$(PYTHON) scripts/bench_percall.py --fmu $< --harness $(BENCH_DIR)/overhead --instructions \
		--reference Dahlquist=$(PERCALL_DIR)/optimized/fmus/Dahlquist.fmu \
		--reference Dahlquist-default=$(PERCALL_DIR)/default/fmus/Dahlquist.fmu

cmake:
	$(call apt_install,cmake,command -v cmake >/dev/null)
