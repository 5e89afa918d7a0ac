"""The Python peers of the work-precision benchmark (`sweep`): scipy's solve_ivp on the
reference's equations and the GearRattle FMU through fmpy, each swept over the tolerances on
the scenes of the reference, written to a CSV with the columns of the Rust suites'. What
each peer runs and how it is timed: scripts/bench_python.py."""

from __future__ import annotations

import csv
import math
import pathlib
import statistics
import time

import numpy as np
from scipy.integrate import solve_ivp

from gearrattle import reference as R

TOLS = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10]
COMM_STEPS = [1e-2, 1e-3, 1e-4, 1e-5]
GRID = 1e-3
METHODS = ["RK45", "DOP853", "Radau", "LSODA"]
RUN_LIMIT = 60.0  # s: a run longer than this stops the sweep of its method and scene
SWEEP_BUDGET = 60.0  # s: CPU of one method's sweep on one scene, past which it stops
REPEAT_BELOW = 2.0  # s: runs shorter than this are repeated (3 in all)
# Default scenes: the targets are on S1; S2 (chaotic: window + rates) and the stiff case at
# 0.2 s keep the Python part within ~15 minutes.
DEFAULT_SCENES = ["S1-0.2s", "S1-1s", "S2-0.2s", "S3-0.2s", "S1-IL-0.2s"]
HEADER = (
    "suite,solver,scene,t_end,window,rtol,comm_step,err_max_xi,err_rms_xi_dot,points,"
    "cpu_median,cpu_min,cpu_max,repeats,rhs_evals,steps,edges,impacts_plus,impacts_minus,"
    "rate_plus,rate_minus,status"
).split(",")


# ------------------------------------------------------------------------------ scenes


def load_scenes(ref_dir: pathlib.Path):
    with open(ref_dir / "scenes.csv") as f:
        scenes = list(csv.DictReader(f))
    refs = {}
    for s in scenes:
        if s["base"] not in refs:
            with open(ref_dir / f"{s['base']}.csv") as f:
                rows = list(csv.DictReader(f))
            refs[s["base"]] = {k: np.array([float(r[k]) for r in rows]) for k in ("t", "xi", "xi_dot")}
    return scenes, refs


def scene_params(s: dict) -> dict:
    return R.params(f_exc=float(s["f_exc"]), A_rms=float(s["A_rms"]), I_L=float(s["I_L"]), C_LM=float(s["C_LM"]))


def grid(t_end: float) -> np.ndarray:
    n = int(round(t_end / GRID))
    return np.minimum(np.arange(n + 1) * GRID, t_end)


# ------------------------------------------------------------------------------ scipy


def run_scipy(p: dict, t_end: float, method: str, rtol: float):
    """Piecewise solve_ivp with terminal events on the current region's edges. Returns the
    samples on the grid (xi, xi_dot, counts) and the work counters."""
    G = p["G"]
    wc = p["r_L"] * math.sqrt(p["K_star"] / p["I_L"])
    atol = np.array([rtol * G, rtol * G * wc, 1e30, 1e30])
    g = grid(t_end)
    n = g.size
    xi = np.full(n, np.nan)
    xd = np.full(n, np.nan)
    counts = np.zeros((n, 2), dtype=np.int64)
    regions = R._regions(p)
    rhs_cache = {}
    y = np.array([p["gap_start"] * G, p["xi_dot_start"], 0.0, 0.0])
    idx = next(i for i, (_, lo, hi) in enumerate(regions) if lo <= y[0] <= hi)
    t, k = 0.0, 0
    nfev = nsteps = edges = 0
    impacts = [0, 0]
    stalls = 0
    t_mark, near = 0.0, 0
    while t < t_end:
        code, lo, hi = regions[idx]
        rhs = rhs_cache.get(code)
        if rhs is None:
            rhs = rhs_cache[code] = R._make_rhs(p, code)
        # The event levels lie 1e-13 G outside the edges: the piece starts exactly on the edge
        # it entered through, and an event function that is 0 at the start would make
        # solve_ivp stop there again when xi turns back within the first step (a graze).
        events = []
        if math.isfinite(lo):
            def ev_lo(_t, yy, lo=lo - 1e-13 * G):
                return yy[0] - lo
            ev_lo.terminal, ev_lo.direction = True, -1
            events.append((ev_lo, -1))
        if math.isfinite(hi):
            def ev_hi(_t, yy, hi=hi + 1e-13 * G):
                return yy[0] - hi
            ev_hi.terminal, ev_hi.direction = True, 1
            events.append((ev_hi, 1))
        sol = solve_ivp(
            rhs, (t, t_end), y, method=method, t_eval=g[k:], events=[e for e, _ in events],
            rtol=rtol, atol=atol,
        )
        if sol.status < 0:
            raise RuntimeError(f"{method} failed at t = {t}: {sol.message}")
        nfev += sol.nfev
        m = np.asarray(sol.t).size  # a list when no t_eval point was reached
        if m:
            xi[k:k + m] = sol.y[0]
            xd[k:k + m] = sol.y[1]
        counts[k:k + m] = impacts
        k += m
        if sol.status != 1:
            y = sol.y[:, -1] if m else y
            t = t_end
            break
        i_ev = next(i for i, te in enumerate(sol.t_events) if te.size)
        side = events[i_ev][1]
        t_c = float(sol.t_events[i_ev][0])
        y = np.array(sol.y_events[i_ev][0], dtype=float)
        y[0] = lo if side < 0 else hi
        stalls = stalls + 1 if t_c <= t else 0
        if stalls > 20:
            raise RuntimeError(f"no progress at t = {t}")
        # Chattering across an edge (Zeno-like tiny pieces) is a failure, not a result.
        if t_c - t_mark > 1e-6:
            t_mark, near = t_c, 0
        near += 1
        if near > 500:
            raise RuntimeError(f"chattering: 500 edge crossings within 1 us at t = {t_c:.9f}")
        if code == 2:  # leaving the gap: an impact (docs/MODEL.md §1)
            impacts[0 if side < 0 else 1] += 1
        idx += side
        edges += 1
        t = t_c
    counts[k:] = impacts
    return dict(xi=xi, xi_dot=xd, counts=counts, stride=1, rhs=nfev, steps=nsteps, edges=edges)


# ------------------------------------------------------------------------------ fmpy


def run_fmpy(fmu: str, s: dict, t_end: float, rtol: float, comm: float):
    from fmpy import simulate_fmu

    res = simulate_fmu(
        fmu,
        start_time=0.0,
        stop_time=t_end,
        relative_tolerance=rtol,
        output_interval=comm,
        fmi_type="CoSimulation",
        start_values=dict(excitation=1, A_rms=float(s["A_rms"]), f_exc=float(s["f_exc"]),
                          I_L=float(s["I_L"]), C_LM=float(s["C_LM"])),
        output=["xi", "xi_dot", "impacts_Fplus", "impacts_Fminus"],
    )
    return res


def fmpy_samples(res, t_end: float, comm: float):
    """The rows of an fmpy result that fall on the error grid."""
    t = res["time"]
    stride = max(1, int(round(comm / GRID)))
    step = stride * GRID
    k = np.rint(t / step)
    on = np.nonzero(np.isclose(t, k * step, rtol=0, atol=1e-9))[0]
    _, first = np.unique(k[on], return_index=True)  # one row per grid point (events repeat rows)
    sel = on[first]
    counts = np.stack([res["impacts_Fplus"][sel], res["impacts_Fminus"][sel]], axis=1).astype(np.int64)
    return dict(xi=res["xi"][sel], xi_dot=res["xi_dot"][sel], counts=counts, stride=stride,
                rhs="", steps="", edges="")


# ------------------------------------------------------------------------------ rows


def errors(out: dict, ref: dict, window: float):
    stride = out["stride"]
    n = min(out["xi"].size, (ref["t"].size - 1) // stride + 1)
    gi = np.arange(n) * stride
    inside = ref["t"][gi] <= window + 1e-9
    gi = gi[inside]
    dx = np.abs(out["xi"][:n][inside] - ref["xi"][gi])
    dv = out["xi_dot"][:n][inside] - ref["xi_dot"][gi]
    max_xi = float(np.max(np.where(np.isnan(dx), np.inf, dx))) if dx.size else float("nan")
    return max_xi, float(np.sqrt(np.mean(dv * dv))) if dv.size else float("nan"), int(gi.size)


def row(solver, s, ref, rtol, comm, out, cpus, status="ok"):
    t_end, window = float(s["t_end"]), float(s["window"])
    r = dict.fromkeys(HEADER, "")
    r.update(suite="python", solver=solver, scene=s["scene"], t_end=t_end, window=window,
             rtol=f"{rtol:e}", comm_step=f"{comm:e}" if comm else "", status=status)
    if out is None:
        return r
    e, v, pts = errors(out, ref, window)
    last = out["counts"][-1]
    r.update(err_max_xi=f"{e:.4e}", err_rms_xi_dot=f"{v:.4e}", points=pts,
             cpu_median=f"{statistics.median(cpus):.6e}", cpu_min=f"{min(cpus):.6e}",
             cpu_max=f"{max(cpus):.6e}", repeats=len(cpus), rhs_evals=out["rhs"], steps=out["steps"],
             edges=out["edges"], impacts_plus=int(last[0]), impacts_minus=int(last[1]))
    if t_end >= 0.5:
        j = int(round(0.2 / GRID)) // out["stride"]
        c = out["counts"][j]
        r.update(rate_plus=f"{(last[0] - c[0]) / (t_end - 0.2):.2f}",
                 rate_minus=f"{(last[1] - c[1]) / (t_end - 0.2):.2f}")
    return r


def timed(fn):
    t0 = time.process_time()
    out = fn()
    return out, time.process_time() - t0


def fmpy_tolerances(rust_csv: pathlib.Path):
    """The FMU's default tolerance and the loosest at which GearRattle reaches 1e-9 m on S1
    (from the Rust run of the same `make bench`), else 1e-9."""
    tols = [1e-6]
    best = None
    if rust_csv.is_file():
        with open(rust_csv) as f:
            for r in csv.DictReader(f):
                if (r["solver"] == "GearRattle (direct)" and r["scene"] == "S1-1s" and r["status"] == "ok"
                        and float(r["err_max_xi"]) <= 1e-9):
                    best = max(best or 0.0, float(r["rtol"]))
    tols.append(best or 1e-9)
    return sorted(set(tols), reverse=True)


def sweep(scenes_wanted: str, quick: bool, fmu: str, ref: pathlib.Path, csv_path: pathlib.Path,
          run_limit: float = RUN_LIMIT) -> None:
    """Runs the peers on the scenes `scenes_wanted` (comma-separated, or 'all') of the reference
    in `ref` and writes their rows to `csv_path`; `quick`: S1-0.2s, three tolerances, one run each."""
    scenes, refs = load_scenes(ref)
    wanted = [s["scene"] for s in scenes] if scenes_wanted == "all" else scenes_wanted.split(",")
    tols = TOLS
    if quick:
        wanted, tols = ["S1-0.2s"], [1e-4, 1e-6, 1e-8]
    scenes = [s for s in scenes if s["scene"] in wanted]
    rows = []
    wall = time.time()

    def log(r):
        rows.append(r)
        print(f"{r['scene']:11} rtol {float(r['rtol']):.0e} {r['solver'] + (' @' + r['comm_step'] if r['comm_step'] else ''):34} "
              f"err {r['err_max_xi'] or '-':>10}  cpu {r['cpu_median'] or '-':>12} (x{r['repeats'] or 0})  "
              f"rhs {r['rhs_evals']}  {r['status'] if r['status'] != 'ok' else ''}", flush=True)

    for s in scenes:
        ref = refs[s["base"]]
        p = scene_params(s)
        t_end = float(s["t_end"])
        stopped = {}  # method -> reason
        spent = {}  # method -> CPU seconds of its first runs
        for rtol in tols:
            # scipy methods at this tolerance, interleaved
            firsts = {}
            for m in METHODS:
                if m in stopped:
                    log(row(f"scipy {m}", s, ref, rtol, None, None, [], status=stopped[m]))
                    continue
                try:
                    out, cpu = timed(lambda: run_scipy(p, t_end, m, rtol))
                except Exception as e:  # noqa: BLE001 - reported in the CSV
                    log(row(f"scipy {m}", s, ref, rtol, None, None, [], status=f"failed: {e}".replace(",", ";")))
                    continue
                firsts[m] = (out, [cpu])
                spent[m] = spent.get(m, 0.0) + cpu
                if cpu > run_limit:
                    stopped[m] = f"skipped: one run at rtol {rtol:g} took {cpu:.0f} s (> {run_limit:.0f} s)"
                elif spent[m] > SWEEP_BUDGET:
                    stopped[m] = (f"skipped: the sweep had used {spent[m]:.0f} s of CPU up to rtol {rtol:g} "
                                  f"(budget {SWEEP_BUDGET:.0f} s per method and scene)")
            for _ in range(0 if quick else 2):
                for m, (out, cpus) in firsts.items():
                    if cpus[0] < REPEAT_BELOW:
                        cpus.append(timed(lambda: run_scipy(p, t_end, m, rtol))[1])
            for m, (out, cpus) in firsts.items():
                log(row(f"scipy {m}", s, ref, rtol, None, out, cpus))
        # the FMU through fmpy
        for rtol in fmpy_tolerances(csv_path.with_name("rust.csv")) if not quick else [1e-6]:
            for comm in COMM_STEPS:
                res, cpu = timed(lambda: run_fmpy(fmu, s, t_end, rtol, comm))
                cpus = [cpu]
                if not quick and cpu < REPEAT_BELOW:
                    cpus += [timed(lambda: run_fmpy(fmu, s, t_end, rtol, comm))[1] for _ in range(2)]
                log(row("GearRattle FMU (fmpy)", s, ref, rtol, comm, fmpy_samples(res, t_end, comm), cpus))

    csv_path.parent.mkdir(parents=True, exist_ok=True)
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=HEADER)
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {csv_path} ({len(rows)} rows) in {time.time() - wall:.0f} s")
