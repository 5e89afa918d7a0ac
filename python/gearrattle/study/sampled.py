"""The sampled engine: fmpy's simulate_fmu records the outputs every `interval` (50 us) and the
statistics are computed from those samples (gearrattle.rattle_stats), not read from stat_*.
The benchmark's baseline, and what `make rattle-map --trajectory-stats` uses for the statistics
that need the trajectory itself (free flights, impact speeds along a run, gaps between
impacts), which no stat_* output carries."""

import time

import numpy as np

from .. import rattle_stats as rs

OUTPUTS = ["impacts_Fplus", "impacts_Fminus", "impact_speed", "E_contact", "E_lubricant",
           "a_pitch_L"]
TRAJECTORY = ["omega_L", "contact"]
FLIGHTS = (("free_flight_mean_duration", lambda before, after: True),
           ("crossing_flight_mean_duration", lambda before, after: before != after),
           ("bounce_flight_mean_duration", lambda before, after: before == after))


def point(fmu_dir, md, values, duration, t_from, interval=5e-5, trajectory=False):
    """One point sampled through fmpy: (statistics dict, CPU seconds). trajectory adds the
    free flights' decay rate (median) and mean durations (all, across the gap, bounces)."""
    from fmpy import simulate_fmu

    t0 = time.process_time()
    res = simulate_fmu(fmu_dir, model_description=md, fmi_type="CoSimulation",
                       start_time=0.0, stop_time=duration, output_interval=interval,
                       start_values=values, output=OUTPUTS + (TRAJECTORY if trajectory else []))
    t = res["time"]
    st = rs.rattle_summary(t, res["impacts_Fplus"], res["impacts_Fminus"],
                           values.get("f_exc", 30.0), t_from, impact_speed=res["impact_speed"],
                           energies=(("contact", res["E_contact"]),
                                     ("lubricant", res["E_lubricant"])),
                           accel=res["a_pitch_L"])
    if trajectory:
        c = res["contact"]
        dec = rs.free_flight_decay(t, res["omega_L"], c, t_from)
        st["free_flight_decay"] = float(np.median(dec)) if len(dec) else float("nan")
        flights = rs.free_flights(t, c, t_from)
        for name, keep in FLIGHTS:
            d = [t[e] - t[s] for s, e in flights if keep(c[s - 1], c[e])]
            st[name] = float(np.mean(d)) if d else float("nan")
    return st, time.process_time() - t0


_W = {}  # per pool process: the extracted FMU, its model description and the run's settings


def _init(fmu_dir, settings):
    from fmpy import read_model_description

    _W.update(dir=fmu_dir, md=read_model_description(fmu_dir), settings=settings)


def _point(values):
    return point(_W["dir"], _W["md"], values, **_W["settings"])


def run(fmu_dir, points, workers, duration, t_from, trajectory=False):
    """The points ({name: value}) on `workers` processes, as rattle_map.py ran its grid:
    ([statistics], [CPU s]) in the points' order."""
    import multiprocessing as mp

    settings = dict(duration=duration, t_from=t_from, trajectory=trajectory)
    # forkserver: the pool's processes start clean, not as forks of a process that ran Dask
    with mp.get_context("forkserver").Pool(workers, initializer=_init,
                                     initargs=(fmu_dir, settings)) as pool:
        res = pool.map(_point, points, chunksize=4)
    return [r[0] for r in res], [r[1] for r in res]
