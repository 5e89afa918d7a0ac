# Rattle studies: the gearrattle package in python/ (the `gearrattle-study` command;
# installed editable into .venv by requirements-demo.txt), its tests (tests/study, run by pytest with
# the others: pytest.ini) and its benchmark.
#   make bench-study          CPU per point and wall times against the sampled engine -> docs/STUDY_BENCH.md

STUDY_BENCH_OUT ?= target/bench-study

.PHONY: bench-study

# A new console script or dependency of the package needs a reinstall.
$(VENV)/.demo-installed: python/pyproject.toml

## bench-study: the study runner against the sampled engine and the FMU stepped from C -> docs/STUDY_BENCH.md
bench-study: fmu $(VENV)/.installed
	$(PY) benches/study/study_bench.py --fmu $(FMU) --out $(STUDY_BENCH_OUT) --report docs/STUDY_BENCH.md

# The benchmark's reference solutions depend on the reference (python/gearrattle/reference.py).
$(BENCH_REF): python/gearrattle/reference.py

STUDY_EXAMPLES := map_paper mc_idle sobol_s1 doe_backlash_drag

.PHONY: study-examples

## study-examples: the worked examples of docs/STUDIES.md (examples/studies) -> their figures in docs/studies
study-examples: fmu $(VENV)/.installed
	@mkdir -p docs/studies
	@set -e; for s in $(STUDY_EXAMPLES); do \
		$(VENV)/bin/gearrattle-study run examples/studies/$$s.toml --quiet; \
		cp target/studies/$$s/summary.txt docs/studies/$$s.txt; \
	done
	cp target/studies/map_paper/map_overview.png docs/studies/map_paper.png
	cp target/studies/mc_idle/mc_distributions.png docs/studies/mc_idle.png
	cp target/studies/sobol_s1/mc_sensitivity.png docs/studies/sobol_s1.png
	cp target/studies/doe_backlash_drag/doe_G.png docs/studies/doe_backlash_drag.png
