"""The gearbox benchmark (`make bench-gearbox`): prints its figures and writes them into
docs/GEARBOX.md's benchmark section (between its two bench-gearbox markers) and the plots
docs/gearbox_cost.png and docs/gearbox_work_precision.png (benches/gearbox).

    PYTHONPATH=benches .venv/bin/python scripts/bench_gearbox.py [--map-x rpm=600:1000:40] [--map-y T_oil=-10:90:25] [--no-write] [--no-map]
"""

import argparse
import sys

from gearbox.report import run


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--map-x", default="rpm=600:1000:40")
    ap.add_argument("--map-y", default="T_oil=-10:90:25")
    ap.add_argument("--no-write", action="store_true", help="print only")
    ap.add_argument("--no-map", action="store_true", help="leave the rattle map out")
    a = ap.parse_args(argv)
    return run(a.map_x, a.map_y, write=not a.no_write, with_map=not a.no_map)


if __name__ == "__main__":
    sys.exit(main())
