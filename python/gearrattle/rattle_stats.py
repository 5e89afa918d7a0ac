"""Rattle statistics from GearRattle's integer impact counters (shared by the demo and tests).

The FMU counts contact onsets exactly (impacts_Fplus, impacts_Fminus: cumulative integers),
so the impact sequence can be read from the sampled counters at any output interval, provided
each flank has at most one impact per interval (1e-5 s is safe: crossing the 25 um backlash
in 10 us would take 2.5 m/s). Flanks are coded as the FMU's `contact` output: 1 = F+
(xi <= 0), 2 = F- (xi >= G).

Pure numpy; no fmpy, no plotting.
"""

from collections import Counter

import numpy as np

FPLUS, FMINUS = 1, 2
FLANK_NAMES = {FPLUS: "F+", FMINUS: "F-"}


def impact_events(t, n_plus, n_minus):
    """Impacts in time order from the sampled cumulative counters.

    Returns a dict of arrays, one entry per impact:
      time   the sample time at which the counter shows the impact (the end of the
             output interval in which it happened),
      index  that sample's index (read impact_speed etc. there),
      flank  FPLUS or FMINUS,
    and `ambiguous`: the number of intervals where the order is unknown (a counter rising by
    more than one, or both counters rising in the same interval); 0 when the interval is
    fine enough.
    """
    t = np.asarray(t, dtype=float)
    dp = np.diff(np.asarray(n_plus, dtype=np.int64))
    dm = np.diff(np.asarray(n_minus, dtype=np.int64))
    if np.any(dp < 0) or np.any(dm < 0):
        raise ValueError("impact counters decrease: not cumulative counts")
    ambiguous = int(np.count_nonzero((dp > 1) | (dm > 1) | ((dp > 0) & (dm > 0))))
    idx, flank = [], []
    for i in np.nonzero((dp > 0) | (dm > 0))[0]:
        # Same interval on both flanks: the order is unknown; put F+ first, flagged above.
        idx += [i + 1] * int(dp[i]) + [i + 1] * int(dm[i])
        flank += [FPLUS] * int(dp[i]) + [FMINUS] * int(dm[i])
    idx = np.asarray(idx, dtype=np.int64)
    return {
        "index": idx,
        "time": t[idx] if len(idx) else np.zeros(0),
        "flank": np.asarray(flank, dtype=np.int64),
        "ambiguous": ambiguous,
    }


def impacts_per_flank(events, t_from, t_to):
    """Impact counts and rates per flank over t_from < time <= t_to.

    Returns {FPLUS: (count, per_second), FMINUS: (count, per_second)}.
    """
    span = t_to - t_from
    sel = (events["time"] > t_from) & (events["time"] <= t_to)
    out = {}
    for fl in (FPLUS, FMINUS):
        n = int(np.count_nonzero(sel & (events["flank"] == fl)))
        out[fl] = (n, n / span if span > 0 else float("nan"))
    return out


def runs(flank):
    """Runs of consecutive impacts on one flank.

    flank: the impact sequence (FPLUS/FMINUS codes) in time order.
    Returns a list of (flank, length, first_impact_position) tuples. The last run may still
    be going on when the record ends: see complete_runs.
    """
    flank = np.asarray(flank)
    out = []
    if len(flank) == 0:
        return out
    change = np.nonzero(np.diff(flank) != 0)[0] + 1
    starts = np.concatenate(([0], change))
    ends = np.concatenate((change, [len(flank)]))
    for s, e in zip(starts, ends):
        out.append((int(flank[s]), int(e - s), int(s)))
    return out


def complete_runs(events, t_from=0.0):
    """Runs that start at or after t_from and are known to be complete (followed by an
    impact on the other flank). Runs cut by the window start or the record's end are left out.

    Returns a list of (flank, length, start_time).
    """
    r = runs(events["flank"])
    out = []
    for k, (fl, n, s) in enumerate(r):
        if k == len(r) - 1:
            break  # the last run may continue beyond the record
        if events["time"][s] >= t_from:
            out.append((fl, n, float(events["time"][s])))
    return out


def run_length_distribution(run_list):
    """{length: how many runs} from a list as returned by complete_runs (or runs)."""
    return dict(sorted(Counter(n for _, n, *_ in run_list).items()))


def per_period_counts(events, f_exc, t_from, t_to, t_start=0.0):
    """Impacts per excitation period and per flank, over the whole periods inside
    [t_from, t_to] (periods counted from t_start: period k is [t_start + k/f, t_start + (k+1)/f)).

    Returns (k, counts): k the period numbers (int array), counts an int array of shape
    (len(k), 2), column 0 for F+, column 1 for F-.
    """
    T = 1.0 / f_exc
    eps = 1e-9 * T  # rounding of t_from/t_to onto whole periods
    k0 = int(np.ceil((t_from - t_start) / T - 1e-9))
    k1 = int(np.floor((t_to - t_start) / T + 1e-9))  # periods k0 .. k1-1
    k = np.arange(k0, k1)
    counts = np.zeros((len(k), 2), dtype=np.int64)
    if len(k) == 0:
        return k, counts
    # An impact seen at sample time t happened in the interval ending at t: attribute it
    # to the period of t minus a hair (exact when sample times fall on period boundaries).
    kk = np.floor((events["time"] - t_start - eps) / T).astype(np.int64)
    for col, fl in enumerate((FPLUS, FMINUS)):
        sel = (events["flank"] == fl) & (kk >= k0) & (kk < k1)
        counts[:, col] = np.bincount(kk[sel] - k0, minlength=len(k))[: len(k)]
    return k, counts


def values_at_impacts(events, values):
    """A sampled output (e.g. impact_speed) read at the sample right after each impact."""
    return np.asarray(values)[events["index"]]


# --------------------------------------------------------------------------- window summaries
# (what the sampled engine, gearrattle.study.sampled, reports over its window)

def mean_rate(t, y, t_from, t_to):
    """Mean rate of a cumulative output y (e.g. a dissipated energy) over [t_from, t_to]:
    (y(t_to) - y(t_from)) / (t_to - t_from), y linearly interpolated between samples."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if t_to <= t_from:
        return float("nan")
    return float((np.interp(t_to, t, y) - np.interp(t_from, t, y)) / (t_to - t_from))


def min_gap_same_flank(events, t_from=0.0):
    """Shortest time between two consecutive impacts on the same flank (inside a run) among
    the impacts after t_from; nan when there is no such pair. Resolution: the output interval."""
    tm, fl = events["time"], events["flank"]
    sel = tm > t_from
    tm, fl = tm[sel], fl[sel]
    same = fl[1:] == fl[:-1]
    if not np.any(same):
        return float("nan")
    return float(np.min(np.diff(tm)[same]))


def decreasing_runs(events, speeds, t_from=0.0):
    """Among the complete runs (see complete_runs) of at least 2 impacts starting at or after
    t_from: (number of runs whose impact speeds strictly decrease along the run, number of
    runs). speeds: one value per impact (values_at_impacts)."""
    r = runs(events["flank"])
    speeds = np.asarray(speeds, dtype=float)
    n = dec = 0
    for k, (_, length, s) in enumerate(r[:-1]):  # the last run may be cut by the record's end
        if length < 2 or events["time"][s] < t_from:
            continue
        n += 1
        dec += bool(np.all(np.diff(speeds[s:s + length]) < 0))
    return dec, n


def free_flights(t, contact, t_from=0.0):
    """Free flights (contact == 0) that start after t_from and end before the record does:
    a list of (first, last + 1) sample-index pairs."""
    t = np.asarray(t, dtype=float)
    gap = np.asarray(contact) == 0
    edges = np.diff(np.concatenate(([0], gap.astype(np.int8), [0])))
    starts, ends = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]
    return [(int(s), int(e)) for s, e in zip(starts, ends)
            if s > 0 and e < len(t) and t[s] > t_from]


def free_flight_decay(t, omega, contact, t_from=0.0, min_duration=1e-3):
    """Decay rates of the loose-gear speed during free flights (contact == 0).

    For each free flight (see free_flights) lasting at least min_duration in which omega keeps
    one sign, the least-squares slope of -ln|omega| against time (1/s). With the lubricant drag
    alone (B = 0, omega_S = 0) every rate is C* = C / I_L. Returns an array, one rate per flight.
    """
    t = np.asarray(t, dtype=float)
    omega = np.asarray(omega, dtype=float)
    rates = []
    for s, e in free_flights(t, contact, t_from):
        # leave out the samples next to the contacts (the contact may end inside them)
        s, e = s + 1, e - 1
        if e - s < 3 or t[e - 1] - t[s] < min_duration:
            continue
        w = omega[s:e]
        if np.any(w == 0) or not (np.all(w > 0) or np.all(w < 0)):
            continue
        rates.append(-np.polyfit(t[s:e], np.log(np.abs(w)), 1)[0])
    return np.asarray(rates)


def rattle_summary(t, n_plus, n_minus, f_exc, t_from, t_to=None, impact_speed=None,
                   energies=(), accel=None):
    """The statistics of one steady window [t_from, t_to] (default: to the end of the record),
    as a flat dict of numbers (nan where undefined), for tables and maps:

      periods, impacts_Fplus, impacts_Fminus     whole periods and impacts in the window
      impacts_per_period (+ _Fplus, _Fminus)     mean over the whole periods
      mean_run (+ _Fplus, _Fminus), runs         consecutive impacts on one flank (complete
      run_min, run_max, run_lengths              runs, see complete_runs); run_lengths is
                                                 {length: count}
      mean_impact_speed, max_impact_speed        m/s (if impact_speed is given), and
      mean_impact_speed_Fplus, _Fminus           per flank
      runs_decreasing                            fraction of the complete runs of >= 2 impacts
                                                 whose impact speeds decrease along the run
      min_gap_same_flank                         s, see min_gap_same_flank
      power_<name>                               W: mean_rate of each cumulative energy in
                                                 energies, a sequence of (name, values)
      rms_accel                                  RMS of accel over the window (if given)
      ambiguous                                  see impact_events
    """
    t = np.asarray(t, dtype=float)
    if t_to is None:
        t_to = float(t[-1])
    ev = impact_events(t, n_plus, n_minus)
    out = {"ambiguous": ev["ambiguous"]}
    pf = impacts_per_flank(ev, t_from, t_to)
    out["impacts_Fplus"], out["impacts_Fminus"] = pf[FPLUS][0], pf[FMINUS][0]
    k, pp = per_period_counts(ev, f_exc, t_from, t_to)
    out["periods"] = len(k)
    nan = float("nan")
    if len(k):
        out["impacts_per_period_Fplus"] = float(pp[:, 0].mean())
        out["impacts_per_period_Fminus"] = float(pp[:, 1].mean())
        out["impacts_per_period"] = float(pp.sum(axis=1).mean())
    else:
        out["impacts_per_period_Fplus"] = out["impacts_per_period_Fminus"] = nan
        out["impacts_per_period"] = nan
    cr = [r for r in complete_runs(ev, t_from) if r[2] <= t_to]
    lengths = np.array([n for _, n, _ in cr], dtype=float)
    out["runs"] = len(cr)
    out["mean_run"] = float(lengths.mean()) if len(cr) else nan
    for fl, name in ((FPLUS, "Fplus"), (FMINUS, "Fminus")):
        ln = [n for f_, n, _ in cr if f_ == fl]
        out["mean_run_" + name] = float(np.mean(ln)) if ln else nan
    out["run_min"] = float(lengths.min()) if len(cr) else nan
    out["run_max"] = float(lengths.max()) if len(cr) else nan
    out["run_lengths"] = run_length_distribution(cr)
    win = (ev["time"] > t_from) & (ev["time"] <= t_to)
    if impact_speed is not None:
        v = values_at_impacts(ev, impact_speed)[win]
        out["mean_impact_speed"] = float(v.mean()) if len(v) else nan
        out["max_impact_speed"] = float(v.max()) if len(v) else nan
        vv = values_at_impacts(ev, impact_speed)
        dec, n = decreasing_runs(ev, vv, t_from)
        out["runs_decreasing"] = dec / n if n else nan
        for fl, name in ((FPLUS, "Fplus"), (FMINUS, "Fminus")):
            v = vv[win & (ev["flank"] == fl)]
            out["mean_impact_speed_" + name] = float(v.mean()) if len(v) else nan
    sub = {"time": ev["time"][win], "flank": ev["flank"][win]}
    out["min_gap_same_flank"] = min_gap_same_flank(sub)
    for name, e in energies:
        out["power_" + name] = mean_rate(t, e, t_from, t_to)
    if accel is not None:
        sel = (t >= t_from) & (t <= t_to)
        a = np.asarray(accel, dtype=float)[sel]
        out["rms_accel"] = float(np.sqrt(np.mean(a ** 2))) if len(a) else nan
    return out
