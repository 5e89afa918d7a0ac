"""The CSVs of `make bench` read, and what the report takes from them: a solver's
work-precision curve, its cost at an error, the side-by-side runs at equal error, the timing
noise; numbers formatted for the tables."""

from __future__ import annotations

import csv
import math
import pathlib
import statistics

from precision.report.names import GR, RUST_PEERS

def read(path: pathlib.Path):
    if not path.is_file():
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def fnum(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return math.nan


def fmt_t(x):
    if not math.isfinite(x):
        return "-"
    if x >= 1:
        return f"{x:.2f} s"
    if x >= 1e-3:
        return f"{x * 1e3:.2f} ms"
    return f"{x * 1e6:.0f} µs"


def fmt_e(x):
    return "-" if not math.isfinite(x) else f"{x:.1e}"


def curve(rows, solver, scene, comm=""):
    """(rtol, error, cpu, rhs) of one solver on one scene, loose to tight tolerance."""
    pts = []
    for r in rows:
        if r["solver"] == solver and r["scene"] == scene and r["comm_step"] == comm and r["status"] == "ok":
            pts.append((fnum(r["rtol"]), fnum(r["err_max_xi"]), fnum(r["cpu_median"]), fnum(r["rhs_evals"])))
    return sorted(pts, key=lambda p: -p[0])


def cost_at(pts, target):
    """CPU time at error `target`: log-log interpolation between the two tolerances that
    bracket it. Returns (cost, kind): 'interp', 'bound' (already below at the loosest
    tolerance: an upper bound), 'above' (never reached: the cost of the most accurate run,
    a lower bound) or None."""
    pts = [p for p in pts if math.isfinite(p[1]) and math.isfinite(p[2])]
    if not pts:
        return None, None
    for i, (_, e, c, _) in enumerate(pts):
        if e <= target:
            if i == 0:
                return c, "bound"
            _, e0, c0, _ = pts[i - 1]
            if e0 <= 0 or e <= 0 or e0 == e:
                return c, "interp"
            w = (math.log(target) - math.log(e0)) / (math.log(e) - math.log(e0))
            return math.exp(math.log(c0) + w * (math.log(c) - math.log(c0))), "interp"
    return max(p[2] for p in pts), "above"


def rhs_at(pts, target):
    """RHS evaluations at error `target`, interpolated like cost_at."""
    return cost_at([(r, e, h, c) for r, e, c, h in pts if math.isfinite(h)], target)


def side_by_side(eq_rows, scene):
    """{solver: (cpu, err, rtol, repeats, rhs)} of the group run side by side at equal error."""
    return {r["solver"]: (fnum(r["cpu_median"]), fnum(r["err_max_xi"]), fnum(r["rtol"]), r["repeats"],
                          fnum(r["rhs_evals"]))
            for r in eq_rows if r["scene"] == scene}


def sbs_ratio(eq, names):
    """The fastest of `names` over GearRattle in a side-by-side group, and its name."""
    cands = [(eq[n][0], n) for n in names if n in eq]
    if GR not in eq or not cands:
        return None, None
    c, n = min(cands)
    return c / eq[GR][0], n


def side_by_side_rows(eq):
    gr = eq[GR][0] if GR in eq else math.nan
    rows = ["| solver | rtol | max \\|Δξ\\| | CPU time (median) | repeats | RHS evaluations | ratio to GearRattle |",
            "|---|---|---|---|---|---|---|"]
    for n in [GR] + RUST_PEERS:
        if n not in eq:
            rows.append(f"| {n} | never within 1e-9 m in the sweep | | | | | |")
            continue
        c, e, rt, reps, h = eq[n]
        rows.append(f"| {n} | {rt:.3g} | {e:.2e} m | {fmt_t(c)} | {reps} | {h:.3g} | {c / gr:.2f} |")
    return "\n".join(rows)


def noise(rows):
    """Spread of the repeats: median and 90th percentile of (max - min) / median."""
    sp = []
    for r in rows:
        c, lo, hi, n = fnum(r["cpu_median"]), fnum(r["cpu_min"]), fnum(r["cpu_max"]), fnum(r["repeats"])
        if n >= 3 and c > 0:
            sp.append((hi - lo) / c)
    if not sp:
        return None
    sp.sort()
    return statistics.median(sp), sp[int(0.9 * (len(sp) - 1))], len(sp)


def curve_any(rows, solver, scene, comm):
    """Like curve(), matching the communication step numerically."""
    pts = []
    for r in rows:
        if r["solver"] != solver or r["scene"] != scene or r["status"] != "ok":
            continue
        if comm:
            if not r["comm_step"] or not math.isclose(fnum(r["comm_step"]), float(comm)):
                continue
        elif r["comm_step"]:
            continue
        pts.append((fnum(r["rtol"]), fnum(r["err_max_xi"]), fnum(r["cpu_median"]), fnum(r["rhs_evals"])))
    return sorted(pts, key=lambda p: -p[0])
