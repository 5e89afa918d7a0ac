"""gearrattle-study: rattle studies of the GearRattle FMU (docs/STUDIES.md).

    gearrattle-study map --fmu FMU --x f_exc=30:60:16 --y A_rms=100:700:13 --out DIR
    gearrattle-study doe --fmu FMU --param NAME=LO:HI [...] --design lhs|full --n N --out DIR
    gearrattle-study mc  --fmu FMU --dist NAME=normal:MEAN:SD [...] --n N --seed S --out DIR
    gearrattle-study run STUDY.toml
    gearrattle-study pack BOX.toml --out MyBox.fmu   (GearboxRattle.fmu with a gearbox's values)
    gearrattle-study listen --fmu FMU --duration S --out DIR   (the rattle as sound: docs/SOUND.md)

Results: DIR/points.parquet and DIR/points.csv (one row per point), a summary and figures."""

import argparse
import os
import sys
import time

from . import gearbox, pack, spec
from .errors import StudyError
from ..sound import listen

DEFAULT_FMU = os.path.join("target", "fmu", "GearRattle.fmu")


def _common(p, toml=False):
    p.add_argument("--fmu", default=None if toml else DEFAULT_FMU,
                   help=f"the FMU (default {DEFAULT_FMU})")
    p.add_argument("--out", default=None, required=not toml, help="results directory")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a fixed start value, e.g. --set excitation=1 (repeatable)")
    p.add_argument("--duration", type=float, default=None if toml else spec.DEFAULT_DURATION,
                   help="simulated time per point [s] (default 1)")
    p.add_argument("--stats-from", type=float, default=None,
                   help="start of the statistics window [s] (default 0.2)")
    p.add_argument("--workers", type=int, default=None,
                   help="Dask worker processes of the local cluster (default: one per core; "
                        "0: serial, in this process)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on an existing Dask cluster, e.g. tcp://HOST:8786")
    p.add_argument("--gearbox", default=None, metavar="BOX.toml",
                   help="GearboxRattle: the gearbox's start values (examples/gearboxes/)")
    p.add_argument("--record", action="append", default=[], metavar="OUTPUT",
                   help="also record this output at the end of each point (repeatable)")
    p.add_argument("--quiet", action="store_true", help="no progress bar, no summary")
    p.add_argument("--sound", action="store_true",
                   help="also the sound of each point: sound_N5, sound_sharpness, sound_LA "
                        "(docs/SOUND.md; about 2 s of CPU per simulated second)")


def parser():
    ap = argparse.ArgumentParser(prog="gearrattle-study", description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="See docs/STUDIES.md.")
    sub = ap.add_subparsers(dest="kind", required=True)
    m = sub.add_parser("map", help="a grid over two parameters (heat maps)")
    _common(m)
    m.add_argument("--x", default="f_exc=30:60:16", help="NAME=LO:HI:COUNT (default "
                   "f_exc=30:60:16)")
    m.add_argument("--y", default="A_rms=100:700:13", help="NAME=LO:HI:COUNT (default "
                   "A_rms=100:700:13)")
    d = sub.add_parser("doe", help="full factorial or Latin hypercube over parameter ranges")
    _common(d)
    d.add_argument("--param", action="append", default=[], metavar="NAME=LO:HI", required=True)
    d.add_argument("--design", choices=spec.DESIGNS, default="lhs")
    d.add_argument("--n", type=int, required=True,
                   help="lhs: number of points; full: levels per parameter")
    d.add_argument("--seed", type=int, default=0)
    c = sub.add_parser("mc", help="Monte Carlo over tolerances given as distributions")
    _common(c)
    c.add_argument("--dist", action="append", default=[], required=True,
                   metavar="NAME=KIND:ARGS",
                   help="normal:MEAN:SD, uniform:LO:HI, lognormal:MEAN:SD or "
                        "truncnormal:MEAN:SD:LO:HI (repeatable)")
    c.add_argument("--n", type=int, required=True,
                   help="samples (sobol: base sample, a power of 2; morris: trajectories)")
    c.add_argument("--seed", type=int, default=0)
    c.add_argument("--at", action="append", default=[], metavar="NAME=V,NAME=V",
                   help="an operating point (repeatable): every sample runs at each")
    c.add_argument("--exceed", action="append", default=[], metavar="METRIC>VALUE",
                   help="report the probability of METRIC > VALUE (also >=, <, <=)")
    c.add_argument("--sensitivity", choices=spec.SENSITIVITY, default="none",
                   help="global sensitivity: Sobol' indices (Saltelli's sampling) or Morris")
    r = sub.add_parser("run", help="a study described by a TOML file (docs/STUDIES.md)")
    r.add_argument("study", help="STUDY.toml")
    _common(r, toml=True)
    listen.add_parser(sub)
    pack.add_parser(sub)
    return ap


def from_args(a):
    if a.kind == "run":
        over = {"fmu": a.fmu, "out": a.out, "duration": a.duration, "workers": a.workers,
                "scheduler": a.scheduler}
        st = spec.from_toml(a.study, over)
        for text in a.set:
            name, value = spec.parse_set(text, f"--set {text}")
            st.fixed[name] = (value, f"--set {text}")
        if a.stats_from is not None:
            st.stats_from = (a.stats_from, f"--stats-from {a.stats_from:g}")
        st.record += a.record
        st.sound = st.sound or a.sound
        return with_gearbox(st, a.gearbox or st.gearbox)
    st = spec.Study(kind=a.kind, fmu=a.fmu, out=a.out, duration=a.duration, workers=a.workers,
                    scheduler=a.scheduler, record=list(a.record), sound=a.sound)
    for text in a.set:
        name, value = spec.parse_set(text, f"--set {text}")
        st.fixed[name] = (value, f"--set {text}")
    if a.stats_from is not None:
        st.stats_from = (a.stats_from, f"--stats-from {a.stats_from:g}")
    if a.kind == "map":
        st.axes = [spec.parse_axis(a.x, f"--x {a.x}"), spec.parse_axis(a.y, f"--y {a.y}")]
    elif a.kind == "doe":
        st.ranges = [spec.parse_range(t, f"--param {t}") for t in a.param]
        st.design, st.n, st.seed = a.design, a.n, a.seed
    else:
        from .distributions import parse_dist

        st.dists = [parse_dist(t, f"--dist {t}") for t in a.dist]
        st.at = [(spec.parse_at(t, f"--at {t}"), f"--at {t}") for t in a.at]
        st.exceed = [spec.parse_exceed(t, f"--exceed {t}") for t in a.exceed]
        st.n, st.seed, st.sensitivity = a.n, a.seed, a.sensitivity
    return with_gearbox(st, a.gearbox)


def with_gearbox(st, path):
    """The study with the gearbox file's values under its own (none without a file)."""
    if path:
        st.gearbox = path
        gearbox.apply(st, path)
    return st


def prepare(st):
    """Read the FMU and validate the study: (Model, FMU bytes). Raises StudyError."""
    from .model import read_model

    if not os.path.isfile(st.fmu):
        raise StudyError(f"no FMU at {st.fmu}: build it first (make fmu) or give --fmu PATH")
    with open(st.fmu, "rb") as f:
        data = f.read()
    model = read_model(st.fmu)
    spec.validate(st, model)
    return model, data


def main(argv=None):
    a = parser().parse_args(argv)
    if a.kind == "listen":
        return listen.main(a)
    try:
        if a.kind == "pack":
            return pack.main(a)
        st = from_args(a)
        model, data = prepare(st)
    except StudyError as e:
        print(f"gearrattle-study: error: {e}", file=sys.stderr)
        return 2
    from . import engine, report

    t0 = time.perf_counter()
    table = engine.execute(st, model, data, quiet=a.quiet)
    wall = time.perf_counter() - t0
    lines, files = report.write(st, model, table, wall)
    if not a.quiet:
        print("\n".join(lines))
        print("files:\n" + "\n".join(f"  {f}" for f in files))
    return 0


if __name__ == "__main__":
    sys.exit(main())
