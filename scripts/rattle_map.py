"""GearRattle rattle map: the paper's sweep (Dion et al. 2009, section 8: 30-60 Hz in 2 Hz steps
x 100-700 rad/s^2 RMS) through the FMU, as heat maps, plus the no-impact threshold vs frequency
(gearrattle.rattle_map.sweep says how).

    .venv/bin/python scripts/rattle_map.py [--fmu PATH] [--out DIR] [--workers N] ...
"""

import argparse
import sys

from gearrattle.rattle_map import sweep


def main(argv=None):
    d = sweep.Options()
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fmu", default=d.fmu)
    ap.add_argument("--out", default=d.out)
    ap.add_argument("--workers", type=int, default=d.workers,
                    help="Dask worker processes (default: one per core; 0: serial)")
    ap.add_argument("--scheduler", default=d.scheduler, help="an existing Dask cluster's address")
    ap.add_argument("--f", default=d.f, help="frequencies lo:hi:step [Hz]")
    ap.add_argument("--A", default=d.A, help="levels lo:hi:step [rad/s^2 RMS]")
    ap.add_argument("--duration", type=float, default=d.duration,
                    help="simulated time per point [s]")
    ap.add_argument("--t-from", type=float, default=d.t_from, help="statistics from here [s]")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="override a parameter's start value (repeatable), e.g. --set G=80e-6; "
                         "the default is the paper's parameters")
    ap.add_argument("--no-threshold", action="store_true", help="skip the threshold search")
    ap.add_argument("--trajectory-stats", action="store_true",
                    help="also sample every grid point every 50 us through fmpy (the sampled "
                         "engine: about 30 s more on 2 cores) for the statistics that need "
                         "the trajectory: free flights, impact speeds along a run, the shortest "
                         "gap between two impacts on one flank")
    ap.add_argument("--threshold-duration", type=float, default=d.threshold_duration)
    ap.add_argument("--threshold-window", type=float, default=d.threshold_window)
    ap.add_argument("--threshold-tol", type=float, default=d.threshold_tol,
                    help="relative width of the bisection's final bracket")
    args = ap.parse_args(argv)
    if not 0 < args.threshold_window < args.threshold_duration:
        ap.error("need 0 < --threshold-window < --threshold-duration")
    return sweep.run(sweep.Options(**vars(args)))


if __name__ == "__main__":
    sys.exit(main())
