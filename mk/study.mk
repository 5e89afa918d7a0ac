# Rattle studies (issue 22): the gearrattle package in python/ (the `gearrattle-study` command;
# installed editable into .venv by requirements.txt), its tests (tests/study, run by pytest with
# the others: pytest.ini) and its benchmark.
#   make bench-study          CPU per point and wall times against today's engine -> docs/STUDY_BENCH.md

STUDY_BENCH_OUT ?= target/bench-study

.PHONY: bench-study

# A new console script or dependency of the package needs a reinstall.
$(VENV)/.installed: python/pyproject.toml

## bench-study: the study runner against the sampled engine and the FMU stepped from C -> docs/STUDY_BENCH.md
bench-study: fmu $(VENV)/.installed
	$(PY) -m gearrattle.study.bench --fmu $(FMU) --out $(STUDY_BENCH_OUT) --report docs/STUDY_BENCH.md

# The benchmark's reference solutions depend on the reference, now in the package.
$(BENCH_REF): python/gearrattle/reference.py
