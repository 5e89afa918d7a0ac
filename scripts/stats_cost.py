"""CPU of one 1-s sine-mode run of S1, S2 and S3 in a single fmi2DoStep, for several FMUs side
by side (interleaved, median of 15): what the statistics window costs (docs/DECISIONS.md, D22).

    .venv/bin/python scripts/stats_cost.py BASE.fmu target/fmu/GearRattle.fmu [--stats-from S]

With --stats-from beyond the run (e.g. 2) the window never opens: the integration alone.
"""

import argparse
import time

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

SCENES = {"S1": (30.0, 300.0), "S2": (60.0, 300.0), "S3": (30.0, 500.0)}


def instance(path):
    md = read_model_description(path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier)
    fmu.instantiate()
    return fmu, vr


def cpu(fmu, vr, f_exc, a_rms, stats_from):
    fmu.reset()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setInteger([vr["excitation"]], [1])
    fmu.setReal([vr["f_exc"], vr["A_rms"]], [f_exc, a_rms])
    if stats_from is not None and "stats_from" in vr:
        fmu.setReal([vr["stats_from"]], [stats_from])
    fmu.exitInitializationMode()
    t = time.process_time()
    fmu.doStep(0.0, 1.0)
    return time.process_time() - t


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("fmus", nargs="+")
    ap.add_argument("--stats-from", type=float, default=None)
    a = ap.parse_args()
    fmus = [instance(p) for p in a.fmus]
    for scene, (f_exc, a_rms) in SCENES.items():
        times = [[] for _ in fmus]
        for _ in range(15):
            for k, (fmu, vr) in enumerate(fmus):
                times[k].append(cpu(fmu, vr, f_exc, a_rms, a.stats_from))
        med = [float(np.median(t)) for t in times]
        cells = "  ".join(f"{p}: {m * 1e3:.2f} ms ({m / med[0]:.2f}x)" for p, m in zip(a.fmus, med))
        print(f"{scene}  {cells}")


if __name__ == "__main__":
    main()
