# Reliability checks of the C API (docs/RELIABILITY.md says what each one proves):
#   make fuzz          libFuzzer + AddressSanitizer over random fmi2 call sequences
#                      (fuzz/, cargo-fuzz on the nightly toolchain), FUZZ_SECONDS long
#   make test-memcheck valgrind memcheck over the lifecycle and thread tests (quick profile)
#   make check-memory  test-memcheck, then the same tests under AddressSanitizer (nightly)
#                      and a Python lifecycle through fmpy under valgrind
#   make soak          the soak test's figures (it also runs in `cargo test`)
# `make test` runs `fuzz` for 40 s and `test-memcheck`; the longer runs are separate.
# Installs what is missing: cargo-fuzz (pinned) with cargo, valgrind with apt-get when root.

FUZZ_SECONDS ?= 60
FUZZ_TARGET := fmi2_calls
CARGO_FUZZ_VERSION := 0.13.2
# New inputs go to a scratch directory; the seed corpus in the repo is only read.
FUZZ_SCRATCH := fuzz/target/corpus-$(FUZZ_TARGET)
FUZZ_FLAGS := -max_total_time=$(FUZZ_SECONDS) -timeout=20 -max_len=4096 -print_final_stats=1
MEMCHECK := valgrind --tool=memcheck --leak-check=full --show-leak-kinds=definite \
	--errors-for-leak-kinds=definite --error-exitcode=99
HOST := $(shell rustc -vV | sed -n 's/^host: //p')
# The lifecycle and thread tests: every fmi2 call and its error paths, 8 instances at once.
MEMORY_TESTS := --test lifecycle --test threads

TEST_TARGETS += fuzz test-memcheck

.PHONY: fuzz fuzz-tools nightly test-memcheck check-memory soak valgrind

nightly:
	@rustup toolchain list | grep -q '^nightly' || { \
		echo "the nightly Rust toolchain is missing (cargo-fuzz and -Zsanitizer need it): rustup toolchain install nightly"; \
		rustup toolchain install nightly --profile minimal; }

fuzz-tools: nightly
	@cargo +nightly fuzz --version 2>/dev/null | grep -q ' $(CARGO_FUZZ_VERSION)' || { \
		echo "cargo-fuzz $(CARGO_FUZZ_VERSION) missing: cargo +nightly install cargo-fuzz --locked"; \
		cargo +nightly install cargo-fuzz --version $(CARGO_FUZZ_VERSION) --locked -j 2; }

## fuzz: libFuzzer + ASan over random fmi2 call sequences (FUZZ_SECONDS=60); a crash fails
# Nightly cargo warns when MAKEFLAGS names a jobserver its recipe cannot reach (under make
# test's -j2); a recipe marked + would reach it but lose --output-sync=target's grouping, so
# the fuzzer's cargo is not told of it and keeps its own two jobs.
fuzz: fuzz-tools | libclang
	mkdir -p $(FUZZ_SCRATCH)
	cd fuzz && MAKEFLAGS= CARGO_BUILD_JOBS=2 cargo +nightly fuzz run $(FUZZ_TARGET) \
		../$(FUZZ_SCRATCH) corpus/$(FUZZ_TARGET) -- $(FUZZ_FLAGS) 2>&1 \
		| grep -v -e '^#' -e '^\s*NEW_FUNC' -e '^INFO: ' -e '^"' -e 'callback_log' ; exit $${PIPESTATUS[0]}

valgrind:
	$(call apt_install,valgrind,command -v valgrind >/dev/null)

## test-memcheck: valgrind memcheck over the lifecycle and thread tests: 0 errors, 0 definitely lost
test-memcheck: | libclang valgrind
	$(CARGO_TEST) $(MEMORY_TESTS) \
		--config 'target.$(HOST).runner = "$(MEMCHECK)"' -- --test-threads 1

## check-memory: test-memcheck, the same tests under AddressSanitizer, fmpy's lifecycle under valgrind
check-memory: test-memcheck fmu $(VENV)/.installed | nightly
	RUSTFLAGS=-Zsanitizer=address ASAN_OPTIONS=detect_leaks=1 CARGO_BUILD_JOBS=2 \
		cargo +nightly test --target $(HOST) --target-dir target/asan $(MEMORY_TESTS)
	$(PY) scripts/memcheck_fmpy.py --fmu $(FMU)

## soak: 100 000 instance and 1 000 000 FMU-state cycles, resident memory printed and checked
soak: | libclang
	$(CARGO_TEST) --test soak -- --nocapture
