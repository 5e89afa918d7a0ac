"""What the hand-over to Radau IIA saves on stiff gear pairs: S1 with a light idler,
0.2 s at rtol 1e-6, with each value of the `solver` parameter; right-hand sides and steps as
the FMU counts them, and the CPU time of the run (process time, fmpy included).

    .venv/bin/python scripts/stiff_cost.py [--fmu target/fmu/GearRattle.fmu]
"""

import argparse
import pathlib
import time

from fmpy import simulate_fmu

from gearrattle import reference as R

ROOT = pathlib.Path(__file__).resolve().parents[1]

SOLVERS = {0: "auto", 1: "DOPRI5", 2: "Radau IIA"}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fmu", default=str(ROOT / "target" / "fmu" / "GearRattle.fmu"))
    args = ap.parse_args()
    sc = R.SCENES["S1"]
    print("| I_L [kg m²] | solver | RHS | steps (by Radau IIA) | CPU [s] |")
    print("|---|---|---|---|---|")
    for I_L in (0.32e-7, 1e-8):
        for solver, name in SOLVERS.items():
            start = time.process_time()
            res = simulate_fmu(
                args.fmu,
                stop_time=0.2,
                step_size=1e-3,
                output_interval=1e-3,
                relative_tolerance=1e-6,
                start_values={"excitation": 1, "f_exc": sc["f_exc"], "A_rms": sc["A_rms"], "I_L": I_L, "solver": solver},
                output=["solver_rhs", "solver_steps", "solver_implicit_steps"],
            )
            cpu = time.process_time() - start
            print(
                f"| {I_L:g} | {solver} ({name}) | {res['solver_rhs'][-1]:.0f} | "
                f"{res['solver_steps'][-1]:.0f} ({res['solver_implicit_steps'][-1]:.0f}) | {cpu:.2f} |"
            )


if __name__ == "__main__":
    main()
