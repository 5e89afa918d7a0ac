"""The Python side of the work-precision benchmark (`make bench`, mk/bench.mk): the Python
peers' runs (`peers`), the reference solutions they and the Rust suites are measured
against (`reference`) and the report of the run (`report`). Outside the installed package:
the scripts run with benches/ on the import path (`PYTHONPATH=benches`, as the Makefile's
recipes set it)."""
