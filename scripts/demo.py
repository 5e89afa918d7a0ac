"""GearRattle demo: the paper's bench scenes run through fmpy, with rattle statistics and
figures in the style of Dion et al. 2009, Figs. 14-24 (gearrattle.demo).

    .venv/bin/python scripts/demo.py [--fmu PATH] [--out DIR] [--duration S] [--box-fmu PATH]

Scenes (docs/MODEL.md section 5): S1 = 30 Hz / 300 rad/s^2 RMS, S2 = 60 Hz / 300, S3 = 30 Hz / 500,
all in sine mode (excitation = 1) with the paper's parameters (the FMU's start values).
Statistics are taken from 0.2 s (start-up transient left out) to the end of the run.
"""

import argparse
import sys

from gearrattle import demo


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fmu", default=demo.FMU)
    ap.add_argument("--out", default=demo.OUT)
    ap.add_argument("--duration", type=float, default=1.0, help="simulated time per scene [s]")
    ap.add_argument("--interval", type=float, default=1e-5,
                    help="output (communication) interval [s]; impacts are read from the "
                         "integer counters, exact while at most one impact per interval")
    ap.add_argument("--scenes", default="S1,S2,S3",
                    help="comma-separated subset of S1,S2,S3; empty: the gearbox demo alone")
    ap.add_argument("--box-fmu", default=None,
                    help="GearboxRattle.fmu: run the gearbox demo too (idle and run-down at "
                         "40, -10 and 80 °C, docs/GEARBOX.md)")
    args = ap.parse_args(argv)
    if args.duration <= 0:
        ap.error("--duration must be > 0")
    if not args.scenes.strip():
        if args.box_fmu is None:
            ap.error("--scenes is empty: give --box-fmu for the gearbox demo")
        return demo.run_gearbox(args.box_fmu, args.out)
    return demo.run(args.fmu, args.out, args.duration, args.interval, args.scenes, args.box_fmu)


if __name__ == "__main__":
    sys.exit(main())
