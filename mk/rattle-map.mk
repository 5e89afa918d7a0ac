# Rattle map: the paper's sweep (section 8: 30-60 Hz in 2 Hz steps x 100-700 rad/s^2 RMS)
# through the FMU on the study runner (gearrattle.study, docs/STUDIES.md), as heat maps, the
# no-impact threshold curve and a CSV in target/rattle_map. About 20 s on 2 cores; not part of
# `make test`. A rerun reuses the points already in target/rattle_map/{grid,threshold}.
#   make rattle-map RATTLE_MAP_FLAGS="--A 100:700:100 --workers 4"
#   make rattle-map RATTLE_MAP_FLAGS="--scheduler tcp://HOST:8786"   (an existing Dask cluster)
#   make rattle-map RATTLE_MAP_FLAGS=--trajectory-stats   (+ free flights, speeds along runs: ~30 s more)
# (options: .venv/bin/python scripts/rattle_map.py --help)

RATTLE_MAP_OUT ?= target/rattle_map
RATTLE_MAP_FLAGS ?=

.PHONY: rattle-map

## rattle-map: heat maps of the paper's sweep and the no-impact threshold in target/rattle_map
rattle-map: fmu $(VENV)/.installed
	$(PY) scripts/rattle_map.py --fmu $(FMU) --out $(RATTLE_MAP_OUT) $(RATTLE_MAP_FLAGS)
