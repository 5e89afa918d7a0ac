"""Runs the stress cases on the built FMU and writes docs/STABILITY.md (gearrattle.stability).

    make stability
    .venv/bin/python scripts/stability_report.py [--fmu target/fmu/GearRattle.fmu]
        [--out docs/STABILITY.md] [--cases "S1,eps 0"]
"""

import argparse
import sys

from gearrattle import stability, stress


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fmu", default=str(stress.FMU_PATH))
    ap.add_argument("--out", default=str(stability.OUT))
    ap.add_argument("--cases", default="", help="comma-separated case names (default: all)")
    args = ap.parse_args()
    return stability.write_report(args.fmu, args.out, args.cases)


if __name__ == "__main__":
    sys.exit(main())
