"""The paper's bench scenes (docs/MODEL.md section 5: S1 = 30 Hz / 300 rad/s^2 RMS, S2 = 60 Hz / 300,
S3 = 30 Hz / 500) run through fmpy in sine mode (excitation = 1) with the FMU's start values
(the paper's parameters), and the rattle statistics of a run: impacts per flank and per
period, runs on one flank, impact speeds, energies, and consistency checks on the outputs.
Used by the demo (gearrattle.demo) and the rattle map (gearrattle.rattle_map)."""

import time

import numpy as np

from . import rattle_stats as rs
from . import reference as R

OUTPUTS = [
    "a_pitch_L", "omega_L", "theta_L", "xi", "xi_dot", "contact", "impacts_Fplus",
    "impacts_Fminus", "impact_speed", "E_contact", "E_lubricant", "F_contact",
    "theta_M_out", "omega_M_out", "alpha_M_out",
]


def _scene(name, **facts):
    """A scene of reference.SCENES (f [Hz], A_rms [rad/s^2 RMS]) with what is known of it."""
    return dict(name=name, f=R.SCENES[name]["f_exc"], A_rms=R.SCENES[name]["A_rms"], **facts)


# What the paper measured (section 8) and what an independent high-accuracy solution of
# the model gives (docs/MODEL.md section 5), per scene.
SCENES = [
    _scene("S1", figs="Figs. 14-17",
         paper="4 or 5 consecutive impacts on one flank before crossing the gap",
         paper_runs=(4, 5),
         model_ref="150/150 impacts/s (F+/F-), runs always 5 (the very first: 4)"),
    _scene("S2", figs="Figs. 18-20",
         paper="2 or 3 consecutive impacts on one flank; shorter free flights",
         paper_runs=(2, 3),
         model_ref="~125/~126 impacts/s, runs of 2 with a 3 about one run in ten "
                   "(chaotic: pointwise predictable for ~80 ms only; compare rates)"),
    _scene("S3", figs="Figs. 21-24",
         paper="more impacts than S1, and stronger",
         paper_runs=None,
         model_ref="90/90 impacts/s, runs always 3; RMS pitch-line acceleration ~22 m/s^2 "
                   "(S1: ~15)"),
]


def read_params(fmu):
    """Start values of the FMU's parameters (the paper's values), as floats."""
    from fmpy import read_model_description

    md = read_model_description(fmu)
    p = {}
    for v in md.modelVariables:
        if v.causality == "parameter" and v.start is not None:
            try:
                p[v.name] = float(v.start)
            except ValueError:
                pass
    return md, p


def simulate(fmu, md, f_exc, A_rms, duration, interval):
    """Run one scene; returns (structured result array, wall-clock seconds of simulate_fmu)."""
    from fmpy import simulate_fmu

    t0 = time.perf_counter()
    res = simulate_fmu(
        fmu,
        model_description=md,
        fmi_type="CoSimulation",
        start_time=0.0,
        stop_time=duration,
        output_interval=interval,
        start_values={"excitation": 1, "f_exc": f_exc, "A_rms": A_rms},
        output=OUTPUTS,
    )
    return res, time.perf_counter() - t0


def analyse(res, scene, p, t_from):
    t = res["time"]
    t_end = float(t[-1])
    ev = rs.impact_events(t, res["impacts_Fplus"], res["impacts_Fminus"])
    win = (ev["time"] > t_from) & (ev["time"] <= t_end)
    speeds = rs.values_at_impacts(ev, res["impact_speed"])
    all_runs = rs.runs(ev["flank"])
    runs = rs.complete_runs(ev, t_from)
    k, per_period = rs.per_period_counts(ev, scene["f"], t_from, t_end)
    sel = t >= t_from - 1e-12
    a = res["a_pitch_L"][sel]

    st = dict(t_end=t_end, events=ev, ambiguous=ev["ambiguous"])
    st["per_flank"] = rs.impacts_per_flank(ev, t_from, t_end)
    st["periods"] = len(k)
    st["per_period"] = per_period
    st["runs"] = runs
    st["first_run"] = all_runs[0] if all_runs else None
    st["speed"] = {}
    st["runs_by_flank"] = {}
    for fl in (rs.FPLUS, rs.FMINUS):
        v = speeds[win & (ev["flank"] == fl)]
        st["speed"][fl] = (float(np.mean(v)) if len(v) else float("nan"),
                           float(np.max(v)) if len(v) else float("nan"))
        st["runs_by_flank"][fl] = [n for f_, n, _ in runs if f_ == fl]
    st["E_contact"] = float(res["E_contact"][-1])
    st["E_lubricant"] = float(res["E_lubricant"][-1])
    st["rms_a"] = float(np.sqrt(np.mean(a ** 2)))
    st["peak_a"] = float(np.max(np.abs(a)))

    # Consistency checks on the FMU's outputs (reported under "odd" when they fail).
    odd = []
    if ev["ambiguous"]:
        odd.append(f"{ev['ambiguous']} output intervals with more than one impact: order unknown")
    c = res["contact"]
    onsets = int(np.count_nonzero((c[:-1] == 0) & (c[1:] != 0)))
    n_imp = len(ev["flank"])
    if onsets != n_imp:
        odd.append(f"counters give {n_imp} impacts, the sampled `contact` output {onsets} "
                   f"gap->contact transitions (contacts shorter than one output interval, "
                   f"or contact flips without a gap sample)")
    if n_imp:
        # Every impact sets impact_speed: it must change at each counter increment.
        prev = res["impact_speed"][ev["index"] - 1]
        same = int(np.count_nonzero(speeds == prev))
        if same:
            odd.append(f"impact_speed unchanged at {same} of {n_imp} impacts")
        if np.any(speeds <= 0) or np.any(~np.isfinite(speeds)):
            odd.append("impact_speed <= 0 or not finite at some impacts")
    # Energy balance (docs/MODEL.md section 3), at the last sample in the gap (no elastic energy):
    # 1/2 I_L (w_L^2 - w_L0^2) = int(-tau_M w_M) dt - E_contact - E_lubricant (B = 0, w_S = 0).
    gap = np.nonzero(c == 0)[0]
    if len(gap) and p.get("B", 0.0) == 0.0 and p.get("omega_S", 0.0) == 0.0:
        j = gap[-1]
        w_in = -p["r_M"] * res["F_contact"][: j + 1] * res["omega_M_out"][: j + 1]
        W_in = float(np.trapezoid(w_in, t[: j + 1]))
        dK = 0.5 * p["I_L"] * (res["omega_L"][j] ** 2 - res["omega_L"][0] ** 2)
        diss = float(res["E_contact"][j] + res["E_lubricant"][j])
        st["energy_residual"] = (W_in - diss - dK) / max(diss, 1e-30)
        if abs(st["energy_residual"]) > 1e-2:
            odd.append(f"energy balance off by {100 * st['energy_residual']:.2f} % of the "
                       f"dissipated energy (sampled at the output interval)")
    else:
        st["energy_residual"] = float("nan")
    xi = res["xi"]
    G = p["G"]
    pen = float(max(-xi.min(), xi.max() - G, 0.0))
    st["max_penetration"] = pen
    if not np.all(np.isfinite(a)):
        odd.append("non-finite a_pitch_L")
    st["odd"] = odd
    return st


def dist_str(d):
    """{value: occurrences} as 'value:occurrences ...', e.g. '2:44 3:4'."""
    return " ".join(f"{n}:{m}" for n, m in sorted(d.items())) or "-"
