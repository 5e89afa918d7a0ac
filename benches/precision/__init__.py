"""The Python side of the work-precision benchmark (`make bench`, mk/bench.mk): the Python
peers' runs (`peers`) and the report of the run (`report`). Outside the installed package:
the scripts run with benches/ on the import path (`PYTHONPATH=benches`, as the Makefile's
recipes set it)."""
