"""Coupling-error study: GearRattle + Flywheel co-simulated at communication steps from 1 ms to
10 us and integrated through Model Exchange, against the monolithic reference; writes
docs/COUPLING.md and docs/coupling_error.png (gearrattle.coupling).

    make coupling-study                       (builds both FMUs first)
    .venv/bin/python scripts/coupling_study.py --out docs [--t-end 0.5] [--steps 1e-3,1e-4]
                                              [--me-rtols 1e-6,1e-8] [--me-solvers LSODA]
"""

import argparse

from gearrattle import coupling, model_exchange


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="docs", help="folder of COUPLING.md and coupling_error.png")
    ap.add_argument("--t-end", type=float, default=0.5)
    ap.add_argument("--steps", default=coupling.STEPS, help="communication steps, comma-separated")
    ap.add_argument("--me-rtols", default=coupling.ME_RTOLS, help="Model Exchange relative tolerances")
    ap.add_argument("--me-solvers", default=coupling.ME_SOLVERS,
                    help=f"Model Exchange solvers, of {', '.join(model_exchange.SOLVERS)}")
    args = ap.parse_args(argv)
    coupling.write_study(args.out, args.t_end, args.steps, args.me_rtols, args.me_solvers)


if __name__ == "__main__":
    main()
