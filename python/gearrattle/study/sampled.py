"""The rattle map's engine before the study runner, kept as the benchmark's baseline: fmpy's
simulate_fmu records the outputs every `interval` (50 us) and the statistics are computed from
those samples (gearrattle.rattle_stats), as scripts/rattle_map.py did."""

import time

from .. import rattle_stats as rs

OUTPUTS = ["impacts_Fplus", "impacts_Fminus", "impact_speed", "E_contact", "E_lubricant",
           "a_pitch_L"]


def point(fmu_dir, md, values, duration, t_from, interval=5e-5):
    """One point sampled through fmpy: (statistics dict, CPU seconds)."""
    from fmpy import simulate_fmu

    t0 = time.process_time()
    res = simulate_fmu(fmu_dir, model_description=md, fmi_type="CoSimulation",
                       start_time=0.0, stop_time=duration, output_interval=interval,
                       start_values=values, output=OUTPUTS)
    st = rs.rattle_summary(res["time"], res["impacts_Fplus"], res["impacts_Fminus"],
                           values.get("f_exc", 30.0), t_from, impact_speed=res["impact_speed"],
                           energies=(("contact", res["E_contact"]),
                                     ("lubricant", res["E_lubricant"])),
                           accel=res["a_pitch_L"])
    return st, time.process_time() - t0
