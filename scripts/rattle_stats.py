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
