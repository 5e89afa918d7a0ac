"""Python peers of the work-precision benchmark: scipy's solve_ivp on the same
equations, and the GearRattle FMU through fmpy, the way users script them.

    PYTHONPATH=benches .venv/bin/python scripts/bench_python.py [--scenes S1-1s,...] [--quick] [--out target/bench/python.csv]

Needs target/bench/reference/ (scripts/bench_reference.py) and target/fmu/GearRattle.fmu.

* scipy: solve_ivp with RK45, DOP853, Radau and LSODA, rtol 1e-3 ... 1e-10, atol = rtol times
  (G, G times the contact frequency) as for every solver of the benchmark, the energies
  carried as quadratures outside the error control (atol 1e30). The right-hand side is the
  one of python/gearrattle/reference.py (`_make_rhs`, the region's formula locked), so these are
  the same equations as the reference, written independently of the FMU. Region changes are
  solve_ivp terminal events on the two edges of the current region (xi = lo falling, xi = hi
  rising; the levels 1e-13 G outside the edges, else a piece that starts on its edge and turns
  back at once would stop there again); the integration restarts at the edge with the neighbouring region's right-hand side
  (solve_ivp picks its first step anew each time, as a user's loop does). solve_ivp's events
  only see sign changes at step ends, so a grazing touch inside one step can be missed (the
  reference looks for it; the error column would show it). Outputs: t_eval on the 1 ms grid.
* fmpy: simulate_fmu on the .fmu file (unzipped and validated at each call, as a user calls
  it) at communication steps 10 ms, 1 ms, 0.1 ms, 10 us, recording xi, xi_dot and the impact
  counters at every step.

Cost: time.process_time of the whole call, median of 3 runs when a run takes under 2 s,
else one run. Sweeps go from loose to tight tolerances; once a single run exceeds the per-run
limit (60 s), or one method's sweep on one scene has used 60 s of CPU, the tighter
tolerances of that method and scene are skipped and the CSV says so. Writes target/bench/python.csv with the columns of target/bench/rust.csv.
"""

import argparse
import pathlib

from precision.peers import DEFAULT_SCENES, RUN_LIMIT, sweep

ROOT = pathlib.Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default=",".join(DEFAULT_SCENES), help="comma-separated scene names, or 'all'")
    ap.add_argument("--quick", action="store_true", help="S1-0.2s, three tolerances, one run each")
    ap.add_argument("--fmu", default=str(ROOT / "target" / "fmu" / "GearRattle.fmu"))
    ap.add_argument("--ref", default=str(ROOT / "target" / "bench" / "reference"))
    ap.add_argument("--out", default=str(ROOT / "target" / "bench" / "python.csv"))
    ap.add_argument("--run-limit", type=float, default=RUN_LIMIT)
    args = ap.parse_args()
    sweep(args.scenes, args.quick, args.fmu, pathlib.Path(args.ref), pathlib.Path(args.out), args.run_limit)


if __name__ == "__main__":
    main()
