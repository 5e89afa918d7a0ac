"""Merges the work-precision CSVs of `make bench` into docs/work_precision.png and
docs/BENCHMARKS.md. The report holds only what the run measured (tables, verdicts computed
from the CSVs, the machine, the commands); the decisions behind the integrator and the levers
measured and dropped are in docs/DECISIONS.md, which the report links to.

    PYTHONPATH=benches .venv/bin/python scripts/bench_report.py [--started EPOCH_SECONDS]

Reads target/bench/rust.csv (cargo bench -p gear_rattle_bench --bench work_precision), target/bench/python.csv
(scripts/bench_python.py), target/bench/reference/scenes.csv (scripts/bench_reference.py)
and, when present, target/bench/profile.txt, calls.txt and machine.txt (written by
mk/bench.mk). Ratios, not absolute times, carry the claims. The report is written by
benches/precision/report (`document.write`).
"""

import argparse
import pathlib

from precision.report.document import write
from precision.report.names import BENCH, ROOT


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--started", type=float, default=None, help="epoch seconds at which `make bench` started")
    ap.add_argument("--wall", type=float, default=None, help="wall time of `make bench` [s] (else from --started)")
    ap.add_argument("--out", default=str(ROOT / "docs" / "BENCHMARKS.md"))
    ap.add_argument("--png", default=str(ROOT / "docs" / "work_precision.png"))
    ap.add_argument("--bench", default=None, help="directory of the CSVs (default target/bench)")
    args = ap.parse_args()
    bench = pathlib.Path(args.bench) if args.bench else BENCH
    write(bench, pathlib.Path(args.out), pathlib.Path(args.png), args.started, args.wall)


if __name__ == "__main__":
    main()
