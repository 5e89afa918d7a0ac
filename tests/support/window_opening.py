"""A master whose communication points accumulate rounding around the opening of the
statistics window: it steps 1e-3 s from k·1e-3, then from 0.02 + k·1e-3, so that the step from
0.029 ends one ulp past 0.03 (the tests of both FMUs)."""

import numpy as np
import pytest
from fmpy.fmi2 import FMU2Slave

H = 1e-3
# The end of the step from 0.029: the first double past 0.03.
END = 0.029 + H
POINTS = [k * H for k in range(20)] + [0.02 + k * H for k in range(40)]
# Windows asked to open within rounding of END: one ulp before it, and two after.
NEAR_END = [0.03, float(np.nextafter(np.nextafter(END, 1.0), 1.0))]


def stats(unzipdir, md, start, inputs, stats_from):
    """Every stat_* output after the master's steps at POINTS, with the start values `start`
    (an int sets an Integer), stats_from, and `inputs(t)` ({name: value}) set at each point."""
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="window_opening")
    fmu.instantiate()
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        for name, value in {**start, **inputs(0.0), "stats_from": stats_from}.items():
            (fmu.setInteger if isinstance(value, int) else fmu.setReal)([vrs[name]], [value])
        fmu.exitInitializationMode()
        for t in POINTS:
            for name, value in inputs(t).items():
                fmu.setReal([vrs[name]], [value])
            fmu.doStep(t, H)
        out = {}
        for v in md.modelVariables:
            if "stat_" in v.name:
                get = fmu.getReal if v.type == "Real" else fmu.getInteger
                out[v.name] = get([v.valueReference])[0]
        fmu.terminate()
        return out
    finally:
        fmu.freeInstance()


def within_rounding(x):
    return pytest.approx(x, rel=1e-12, abs=0.0)


def assert_opens_on_the_step_end(run):
    """`run(stats_from)` -> stats: a window asked within rounding of END gives the figures
    of the window that opens on END (within rounding), with impacts in it."""
    on_the_point = run(END)
    impacts = sum(v for k, v in on_the_point.items() if "stat_impacts_" in k)
    assert impacts > 0
    # Each window's length (a gearbox's slots past n_gears have none).
    windows = [v for k, v in on_the_point.items() if k.endswith("stat_window") and v != 0.0]
    assert windows and all(w == within_rounding(POINTS[-1] + H - END) for w in windows)
    for stats_from in NEAR_END:
        got = run(stats_from)
        assert got.keys() == on_the_point.keys()
        bad = {k: (got[k], v) for k, v in on_the_point.items() if got[k] != within_rounding(v)}
        assert not bad, (stats_from, bad)
