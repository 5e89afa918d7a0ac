# Stability report: the stress suite of python/gearrattle/stress.py (the same cases
# and checks as tests/python/test_stress.py, which runs in `make test`) as one table in
# docs/STABILITY.md: parameters, method chosen, steps, RHS evaluations, CPU-time ratio to S1,
# error, pass/fail. About two minutes on the 2-core machine (the 1 h case takes ~20 s of it).
# Not part of `make test`.
#   make stability STABILITY_FLAGS='--cases "S1,eps 0"'

STABILITY_OUT ?= docs/STABILITY.md
STABILITY_FLAGS ?=

.PHONY: stability

## stability: the stress suite as a report -> docs/STABILITY.md
stability: fmu $(VENV)/.installed
	$(PY) scripts/stability_report.py --fmu $(FMU) --out $(STABILITY_OUT) $(STABILITY_FLAGS)
