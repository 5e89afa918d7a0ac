# Work-precision benchmark: `make bench` measures GearRattle beside its peers and
# regenerates docs/BENCHMARKS.md and docs/work_precision.png. Not part of `make test`: it
# takes 12-16 min on the 2-core machine (about 8 more when the reference is rebuilt) and makes
# no timed assertion.
#
#   make bench            everything (reference only when missing or outdated)
#   make bench-reference  the independent reference alone (scripts/bench_reference.py)
#   make bench-overhead   what the rattle statistics cost a run, against an older FMU library

BENCH_DIR := target/bench
BENCH_REF := $(BENCH_DIR)/reference/scenes.csv
# The benchmark's Python modules (benches/precision) stay out of the installed package: its
# command lines run with benches/ on the import path.
BENCH_PY := PYTHONPATH=benches$${PYTHONPATH:+:$$PYTHONPATH} $(PY)

.PHONY: bench bench-reference bench-profile bench-overhead

## bench: work-precision benchmark -> docs/BENCHMARKS.md, docs/work_precision.png
bench: fmu $(VENV)/.installed $(BENCH_REF) | libclang
	@started=$$(date +%s); \
	mkdir -p $(BENCH_DIR); \
	{ echo "Load average at the start: $$(cut -d' ' -f1-3 /proc/loadavg) (1, 5, 15 min)."; } > $(BENCH_DIR)/machine.txt; \
	set -e; \
	cargo bench -p gear_rattle_bench --bench work_precision; \
	$(BENCH_PY) scripts/bench_python.py; \
	tol=$$($(PY) -c "import csv; r=[x for x in csv.DictReader(open('$(BENCH_DIR)/rust.csv')) if x['solver']=='GearRattle (direct)' and x['scene']=='S1-1s' and x['status']=='ok' and float(x['err_max_xi'])<=1e-9]; print(max((float(x['rtol']) for x in r), default=1e-9))"); \
	$(MAKE) --no-print-directory bench-profile BENCH_PROFILE_RTOL=$$tol; \
	echo "Load average at the end: $$(cut -d' ' -f1-3 /proc/loadavg) (1, 5, 15 min)." >> $(BENCH_DIR)/machine.txt; \
	$(BENCH_PY) scripts/bench_report.py --started $$started

## bench-profile: GearRattle alone on S1 under perf -> target/bench/profile.txt, the cost of a call -> calls.txt (part of bench)
# The bench binary is built first and recorded alone, so that no compiler shows in the profile.
BENCH_PROFILE_RTOL ?= 1e-7
bench-profile: | libclang
	@exe=$$(cargo bench -p gear_rattle_bench --no-run --bench work_precision 2>&1 | grep -o 'target/release/deps/work_precision-[0-9a-f]*' | tail -n 1); \
	test -x "$$exe" || { echo "bench binary not found"; exit 1; }; \
	if command -v perf >/dev/null 2>&1; then \
		BENCH_PROFILE=1 BENCH_PROFILE_RTOL=$(BENCH_PROFILE_RTOL) perf record -q -F 999 -o $(BENCH_DIR)/perf.data -- \
			$$exe --bench > $(BENCH_DIR)/profile.txt; \
		{ echo; echo "perf report (self time, symbols over 1 %):"; \
		  perf report -i $(BENCH_DIR)/perf.data --stdio --no-children --sort symbol --percent-limit 1 2>/dev/null \
			| grep -v '^#' | grep -v '^$$' | sed -E 's/[[:space:]]+-[[:space:]]+-[[:space:]]*$$//; s/[[:space:]]+$$//' | head -25; \
		} >> $(BENCH_DIR)/profile.txt; \
	else \
		BENCH_PROFILE=1 BENCH_PROFILE_RTOL=$(BENCH_PROFILE_RTOL) $$exe --bench > $(BENCH_DIR)/profile.txt; \
	fi; \
	BENCH_PROFILE=calls BENCH_PROFILE_RTOL=$(BENCH_PROFILE_RTOL) BENCH_PROFILE_SECONDS=2 $$exe --bench > $(BENCH_DIR)/calls.txt; \
	cat $(BENCH_DIR)/profile.txt $(BENCH_DIR)/calls.txt

## bench-reference: the independent reference solutions of the benchmark scenes
bench-reference: $(BENCH_REF)

$(BENCH_REF): scripts/bench_reference.py benches/precision/reference.py | $(VENV)/.installed
	$(BENCH_PY) scripts/bench_reference.py --out $(BENCH_DIR)/reference

## bench-overhead: the statistics' cost on S1 against the FMU library of OVERHEAD_BASE, from C (prints)
# The base commit is checked out in a worktree under target/ and built there (its own target/,
# about 8 min the first time); both libraries are stepped alternately by one C harness.
OVERHEAD_BASE ?= dd70606
OVERHEAD_TREE := target/overhead-base
bench-overhead: $(LIB)
	@test -d $(OVERHEAD_TREE) || git worktree add --detach $(OVERHEAD_TREE) $(OVERHEAD_BASE)
	git -C $(OVERHEAD_TREE) checkout --quiet --detach $(OVERHEAD_BASE)
	cd $(OVERHEAD_TREE) && cargo build --release --lib
	@mkdir -p $(BENCH_DIR)
	$(CC) -O2 -I benches/study -o $(BENCH_DIR)/overhead benches/overhead/overhead.c -ldl
	$(PYTHON) scripts/bench_overhead.py --base $(OVERHEAD_TREE) --new . --harness $(BENCH_DIR)/overhead
