"""The rattle statistics of a window [t0, t1] (the FMU's stat_* outputs, docs/STUDIES.md,
"Metric definitions") computed independently of the FMU: from the reference solution's
impacts and a dense grid of its states, or from an FMU run's densely sampled outputs.

Both give a dict keyed by the stat_* output names. Integrals are Simpson's rule on the grid;
the time in contact is the time with xi <= 0 or xi >= G, its ends placed between grid points
by linear interpolation.
"""

import numpy as np
from scipy.integrate import simpson

from gearrattle import reference as R


def _flank_stats(times, flanks, speeds, t0, t1, m_eq):
    """Counts, runs and speed statistics of the impacts at t0 <= t <= t1."""
    sel = (times >= t0) & (times <= t1)
    flanks, speeds = np.asarray(flanks)[sel], np.asarray(speeds)[sel]
    runs = R.runs_per_flank(flanks)
    out = {}
    for fl, name in ((R.FPLUS, "Fplus"), (R.FMINUS, "Fminus")):
        v = speeds[flanks == fl]
        n = len(v)
        out[f"stat_impacts_{name}"] = n
        out[f"stat_runs_{name}"] = len(runs[fl])
        out[f"stat_run_max_{name}"] = max(runs[fl], default=0)
        out[f"stat_run_mean_{name}"] = n / len(runs[fl]) if runs[fl] else 0.0
        out[f"stat_v_mean_{name}"] = float(np.mean(v)) if n else 0.0
        out[f"stat_v_rms_{name}"] = float(np.sqrt(np.mean(v * v))) if n else 0.0
        out[f"stat_v_max_{name}"] = float(np.max(v)) if n else 0.0
        out[f"stat_E_impact_{name}"] = float(0.5 * m_eq * np.sum(v * v))
        out[f"stat_impact_rate_{name}"] = n / (t1 - t0)
    out["stat_rattle_power"] = (out["stat_E_impact_Fplus"] + out["stat_E_impact_Fminus"]) / (t1 - t0)
    n_plus, n_minus = out["stat_impacts_Fplus"], out["stat_impacts_Fminus"]
    out["stat_regime"] = (n_plus > 0) + (n_minus > 0)
    out["stat_side"] = 1 if (n_plus and not n_minus) else 2 if (n_minus and not n_plus) else 0
    return out


def _contact_time(t, xi, G):
    """Time with xi <= 0 or xi >= G on the grid, ends interpolated linearly."""
    total = 0.0
    for d in (-xi, xi - G):  # >= 0 in contact on F+, on F-
        inside = d >= 0
        both = inside[1:] & inside[:-1]
        total += np.sum(np.diff(t)[both])
        cross = inside[1:] != inside[:-1]
        i = np.nonzero(cross)[0]
        frac = d[i] / (d[i] - d[i + 1])  # where d crosses 0 in [t_i, t_i+1]
        dt = t[i + 1] - t[i]
        total += np.sum(np.where(inside[i], frac * dt, (1 - frac) * dt))
    return total


def _grid_stats(t, xi, a, F, E_contact, E_lubricant, G):
    """The integral statistics from grid values over the grid's span."""
    T = t[-1] - t[0]
    F_mean = simpson(F, x=t) / T
    return {
        "stat_window": T,
        "stat_a_rms": float(np.sqrt(simpson(a * a, x=t) / T)),
        "stat_a_peak": float(np.max(np.abs(a))),
        "stat_F_std": float(np.sqrt(simpson(F * F, x=t) / T - F_mean**2)),
        "stat_contact_fraction": _contact_time(t, xi, G) / T,
        "stat_P_contact": (E_contact[-1] - E_contact[0]) / T,
        "stat_P_lubricant": (E_lubricant[-1] - E_lubricant[0]) / T,
    }


def from_reference(p, t0, t1, dt=1e-6):
    """The window's statistics from the reference solution (DOP853 at rtol 1e-12)."""
    n = int(round(t1 / dt))
    grid = np.arange(n + 1) * dt
    ref = R.simulate(p, t1, t_eval=grid)
    _, alpha_L, F = ref.loose_gear()
    w = grid >= t0 - 0.5 * dt
    m_eq = p["I_L"] / p["r_L"] ** 2
    out = _flank_stats(ref.impact_t, ref.impact_flank, ref.impact_speed, t0, t1, m_eq)
    out.update(_grid_stats(grid[w], ref.xi[w], p["r_L"] * alpha_L[w], F[w],
                           ref.E_contact[w], ref.E_lubricant[w], p["G"]))
    return out


def from_samples(res, p, t0):
    """The window's statistics from an FMU run's outputs sampled densely (fmpy's result):
    impacts from the counters (their speed read right after), integrals on the samples."""
    t = res["time"]
    n_plus, n_minus = res["impacts_Fplus"], res["impacts_Fminus"]
    rising = np.nonzero((np.diff(n_plus) > 0) | (np.diff(n_minus) > 0))[0] + 1
    assert np.all(np.diff(n_plus)[rising - 1] + np.diff(n_minus)[rising - 1] == 1), \
        "two impacts within one sample interval: sample more densely"
    flanks = np.where(np.diff(n_plus)[rising - 1] > 0, R.FPLUS, R.FMINUS)
    m_eq = p["I_L"] / p["r_L"] ** 2
    out = _flank_stats(t[rising], flanks, res["impact_speed"][rising], t0, t[-1], m_eq)
    w = t >= t0
    out.update(_grid_stats(t[w], res["xi"][w], res["a_pitch_L"][w], res["F_contact"][w],
                           res["E_contact"][w], res["E_lubricant"][w], p["G"]))
    return out
