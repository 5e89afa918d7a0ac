"""The reference solutions of the work-precision benchmark (`write`): each base scene by
python/gearrattle/reference.py at a tight tolerance, checked by a second method, with its
predictable window; what each holds: scripts/bench_reference.py."""

from __future__ import annotations

import csv
import pathlib
import time

import numpy as np

from gearrattle import reference as R

GRID = 1e-3  # the error grid of every solver [s]
PERTURBATION = 1e-4  # of G, for the predictable window
DIVERGED = 1e-2  # of G

# Base scenes: parameter overrides of reference.params, run length, reference and check.
BASES = {
    "S1": dict(scene="S1", over={}, t_end=1.0, ref=("DOP853", 1e-13), check=("Radau", 1e-12)),
    "S2": dict(scene="S2", over={}, t_end=1.0, ref=("DOP853", 1e-13), check=("Radau", 1e-12)),
    "S3": dict(scene="S3", over={}, t_end=1.0, ref=("DOP853", 1e-13), check=("Radau", 1e-12)),
    # The stress suite's stiff cases: a 1e4 times lighter loose gear; 1000 times the contact damping
    "S1-IL": dict(scene="S1", over=dict(I_L=0.32e-7), t_end=0.2, ref=("Radau", 1e-12), check=("DOP853", 1e-12)),
    "S1-CLM": dict(scene="S1", over=dict(C_LM=67000.0), t_end=0.2, ref=("Radau", 1e-12), check=("DOP853", 1e-12)),
}

# Benchmark scenes: (name, base, t_end).
SCENES = [
    ("S1-0.2s", "S1", 0.2),
    ("S1-1s", "S1", 1.0),
    ("S2-0.2s", "S2", 0.2),
    ("S2-1s", "S2", 1.0),
    ("S3-0.2s", "S3", 0.2),
    ("S3-1s", "S3", 1.0),
    ("S1-IL-0.2s", "S1-IL", 0.2),
    ("S1-CLM-0.2s", "S1-CLM", 0.2),
]


def grid(t_end: float) -> np.ndarray:
    n = int(round(t_end / GRID))
    return np.minimum(np.arange(n + 1) * GRID, t_end)


def run(p: dict, t_end: float, method: str, rtol: float):
    t0 = time.process_time()
    r = R.simulate(p, t_end, t_eval=grid(t_end), method=method, rtol=rtol)
    return r, time.process_time() - t0


def write(out: pathlib.Path) -> None:
    """Writes <out>/scenes.csv and <out>/<base>.csv of every base scene."""
    out.mkdir(parents=True, exist_ok=True)

    info = {}
    for base, b in BASES.items():
        p = R.params(b["scene"], **b["over"])
        G = p["G"]
        ref, cpu_ref = run(p, b["t_end"], *b["ref"])
        print(f"{base}: reference {b['ref']} {cpu_ref:.1f} s CPU, {ref.nfev} rhs, {len(ref.impact_t)} impacts", flush=True)
        pert, _ = run(dict(p, gap_start=p["gap_start"] + PERTURBATION), b["t_end"], *b["ref"])
        d = np.abs(pert.xi - ref.xi)
        beyond = np.nonzero(d > DIVERGED * G)[0]
        window = float(ref.t[beyond[0]]) if beyond.size else b["t_end"]
        chk, cpu_chk = run(p, b["t_end"], *b["check"])
        agree = np.abs(chk.xi - ref.xi)
        inside = ref.t <= window + 1e-12
        print(
            f"  window {window:.3f} s (a {PERTURBATION:g} G offset grows to {DIVERGED:g} G); check {b['check']} "
            f"{cpu_chk:.1f} s CPU: max |dxi| {agree[inside].max():.2e} m in the window, {agree.max():.2e} m overall",
            flush=True,
        )
        n_plus, n_minus = ref.impact_counts(ref.t)
        with open(out / f"{base}.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["t", "xi", "xi_dot", "n_plus", "n_minus"])
            for row in zip(ref.t, ref.xi, ref.xi_dot, n_plus, n_minus):
                w.writerow([f"{row[0]:.6f}", repr(float(row[1])), repr(float(row[2])), int(row[3]), int(row[4])])
        info[base] = dict(p=p, ref=ref, window=window, agree=agree, cpu_ref=cpu_ref, cpu_chk=cpu_chk, b=b)

    with open(out / "scenes.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow([
            "scene", "base", "f_exc", "A_rms", "I_L", "C_LM", "t_end", "window", "ref_method", "ref_rtol",
            "check_method", "check_rtol", "agreement_window", "impacts_plus", "impacts_minus",
            "rate_plus", "rate_minus",
        ])
        for name, base, t_end in SCENES:
            i = info[base]
            p, ref = i["p"], i["ref"]
            window = min(i["window"], t_end)
            inside = ref.t <= window + 1e-12
            n_plus, n_minus = ref.impact_counts([t_end])
            if t_end >= 0.5:
                rp, rm = R.rates(ref.impact_t, ref.impact_flank, 0.2, t_end).values()
                rates = [f"{rp:.2f}", f"{rm:.2f}"]
            else:
                rates = ["", ""]
            w.writerow([
                name, base, p["f_exc"], p["A_rms"], p["I_L"], p["C_LM"], t_end, f"{window:.4f}",
                i["b"]["ref"][0], i["b"]["ref"][1], i["b"]["check"][0], i["b"]["check"][1],
                f"{i['agree'][inside].max():.3e}", int(n_plus[0]), int(n_minus[0]), *rates,
            ])
    print(f"wrote {out}/scenes.csv")
