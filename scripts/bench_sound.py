"""The sound's cost and error against the force's sampling (`make bench-sound`, docs/SOUND.md's
Cost section; benches/sound). With --cost, only the WAV's cost against the simulation alone,
side by side, and the metrics'.

    PYTHONPATH=benches .venv/bin/python scripts/bench_sound.py --fmu FMU [--duration 1] [--set NAME=VALUE ...] [--cost]
"""

import argparse
import os
import sys

from sound.cost import report


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fmu", default=os.path.join("target", "fmu", "GearRattle.fmu"))
    ap.add_argument("--duration", type=float, default=1.0)
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    ap.add_argument("--cost", action="store_true",
                    help="only the WAV's cost against the simulation alone, and the metrics'")
    a = ap.parse_args(argv)
    return report(a.fmu, a.duration, a.set, cost_only=a.cost)


if __name__ == "__main__":
    sys.exit(main())
