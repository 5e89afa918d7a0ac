"""The sound's benchmark (`make bench-sound`, mk/sound.mk): its cost and error against the
force's sampling (`cost`). Outside the installed package: scripts/bench_sound.py runs with
benches/ on the import path (`PYTHONPATH=benches`, as the Makefile's recipe sets it)."""
