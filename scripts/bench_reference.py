"""Reference solutions of the work-precision benchmark, from the independent Python
implementation of docs/MODEL.md (python/gearrattle/reference.py, reused as it is).

    PYTHONPATH=benches .venv/bin/python scripts/bench_reference.py [--out target/bench/reference]

For each base scene (S1, S2, S3 of docs/MODEL.md §5 and two stiff variants of S1 from the stress
suite) it computes, with the paper's parameters, xi(0) = G/2, xi'(0) = 0:

* the reference: reference.simulate at tight tolerance (DOP853 rtol 1e-13 for S1-S3; Radau
  rtol 1e-12 for the stiff variants, where DOP853 needs millions of steps), sampled on the 1 ms
  error grid, with the impact counts per flank there;
* a check by a second method (Radau 1e-12, resp. DOP853 1e-12): the largest |dxi| between the
  two over the error window is the floor below which errors cannot be told apart;
* the predictable window: the run is repeated from xi(0) = G/2 + 1e-4 G and the window ends
  where the two differ by 1e-2 G (docs/MODEL.md §5's criterion); the whole run when they never do.

Writes <out>/scenes.csv (one row per benchmark scene) and <out>/<base>.csv (t, xi, xi_dot,
n_plus, n_minus on the grid). Takes about 6 minutes (the Radau checks); `make bench` reruns it
only when this script or benches/precision/reference.py changes.
"""

import argparse
import pathlib

from precision.reference import write

ROOT = pathlib.Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=str(ROOT / "target" / "bench" / "reference"))
    args = ap.parse_args()
    write(pathlib.Path(args.out))


if __name__ == "__main__":
    main()
