"""The rattle threshold of the model at given excitation frequencies, on the study runner:
A_rms scanned geometrically from `lo` upwards (x `ratio`), then both edges refined by bisection
to the relative width `tol`; the scan's levels of all frequencies run as one study, each
bisection round as another. A level is classed
  none       no impact at all in the run (the impact counters from t = 0),
  transient  impacts in the start-up transient only (none in the study's statistics window),
  sustained  impacts still in the window (on one or both flanks).
Two levels per frequency:
  A_first      the lowest level with any impact (the start-up transient reaches a flank),
  A_sustained  the onset of sustained rattle: every scanned level from there up to `confirm`
               times it sustains. Below it, a few isolated levels may sustain too (coexisting
               states near the onset): they are listed with the result.
A level the FMU refuses is reported with the FMU's message and ends that bisection.

`meta` holds the search's settings: thr_lo, thr_hi (the scan's range), thr_ratio, thr_confirm,
thr_tol. The study passed in records COUNTS (the impact counters from t = 0) and takes its
statistics over the window."""

import math
import os

from . import engine

COUNTS = ["impacts_Fplus", "impacts_Fminus"]  # cumulative from t = 0


def classify(r):
    """'none' / 'transient' / 'sustained' of a threshold run (the module docstring), with
    the impacts in the window on F+ and F-; None if the FMU refused the level."""
    if r["status"] != "ok":
        return None, 0, 0
    lp, lm = r["stat_impacts_Fplus"], r["stat_impacts_Fminus"]
    if r["impacts_Fplus"] + r["impacts_Fminus"] == 0:
        return "none", lp, lm
    return ("transient" if lp + lm == 0 else "sustained"), lp, lm


def _run_levels(study, model, data, session, points, out):
    """Classes of the levels {(f, A)} run as one study in out."""
    study.out = out
    table = engine.execute(study, model, data, points=[{"f_exc": f, "A_rms": A}
                                                         for f, A in points], session=session)
    res = {(r["f_exc"], r["A_rms"]): r for r in table.to_pylist()}
    return {k: (classify(res[k]), res[k]["message"]) for k in points}


def scan_one(f, levels, classes, meta):
    """The scan at one frequency up to the level where sustained rattle has held from its onset
    to thr_confirm times it: (scan, streak start or None)."""
    scan, streak = [], None
    for A in levels:
        (c, lp, lm), _ = classes[(f, A)]
        scan.append((A, c, lp, lm))
        if c == "sustained":
            streak = A if streak is None else streak
            if A >= meta["thr_confirm"] * streak:
                break
        elif c is not None:
            streak = None
    return scan, streak


def thresholds(study, model, data, session, fs, meta, base):
    """A_first and A_sustained at each frequency (geometric scan, then rounds of bisection);
    the runner's points in base/scan, base/bisection1, ..."""
    levels, A = [], meta["thr_lo"]
    while A <= meta["thr_hi"]:
        levels.append(A)
        A *= meta["thr_ratio"]
    classes = _run_levels(study, model, data, session, [(f, A) for f in fs for A in levels],
                          os.path.join(base, "scan"))
    out, brackets = {}, {}
    for f in fs:
        scan, streak = scan_one(f, levels, classes, meta)
        lv = [s[0] for s in scan]
        cl = [s[1] for s in scan]
        t = out[f] = {"f_Hz": f, "scan": scan, "errors": [f"{A:.4g}: {classes[(f, A)][1]}"
                                                          for A in lv if classes[(f, A)][0][0]
                                                          is None]}
        first = next((i for i, c in enumerate(cl) if c not in ("none", None)), None)
        t["A_first"] = t["A_first_lo"] = float("nan")
        if first:
            brackets[(f, "first")] = [lv[first - 1], lv[first]]
        t["A_sustained"] = t["A_sustained_lo"] = float("nan")
        t["isolated_sustained"] = []
        if streak is not None and lv[-1] >= meta["thr_confirm"] * streak:
            j = lv.index(streak)
            t["A_sustained"] = streak
            if j:
                brackets[(f, "sustained")] = [lv[j - 1], streak]
            t["isolated_sustained"] = [s[0] for s in scan[:j] if s[1] == "sustained"]
        t["one_sided"] = [(s[0], "F+" if s[3] == 0 else "F-") for s in scan
                          if s[1] == "sustained" and (s[2] == 0 or s[3] == 0)]
        t["sims"] = len(lv)
    active, rnd = dict(brackets), 0
    while active:
        rnd += 1
        mids = {k: math.sqrt(lo * hi) for k, (lo, hi) in active.items()}
        todo = sorted({(f, A) for (f, _), A in mids.items()})
        res = _run_levels(study, model, data, session, todo,
                          os.path.join(base, f"bisection{rnd}"))
        for (f, edge), mid in mids.items():
            (c, _, _), msg = res[(f, mid)]
            out[f]["sims"] += 1
            if c is None:
                out[f]["errors"].append(f"{mid:.4g}: {msg}")
                del active[(f, edge)]
                continue
            lo_hi = active[(f, edge)]
            lo_hi[1 if (c != "none" if edge == "first" else c == "sustained") else 0] = mid
            if lo_hi[1] / lo_hi[0] <= 1 + meta["thr_tol"]:
                del active[(f, edge)]
    for (f, edge), (lo, hi) in brackets.items():
        out[f][f"A_{edge}_lo"], out[f][f"A_{edge}"] = lo, hi
    return [out[f] for f in fs]
