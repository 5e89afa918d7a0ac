"""Runs the stress cases (tests/python/stress_cases.py, the same cases and checks
as tests/python/test_stress.py) on the built FMU and writes docs/STABILITY.md: one row per
case with its parameters, the method the FMU chose, steps, RHS evaluations, CPU time and its
ratio to S1's (per simulated second, measured in the same run), the error and pass/fail.

    make stability
    .venv/bin/python scripts/stability_report.py [--fmu target/fmu/GearRattle.fmu]
        [--out docs/STABILITY.md] [--cases "S1,eps 0"]

CPU time is the process time spent inside fmi2DoStep (reading the outputs is not counted).
Runs shorter than MIN_CPU seconds are repeated and the median taken; S1 is timed before and
after the other cases and the median of all its repeats is the reference of the ratios.
"""

from __future__ import annotations

import argparse
import datetime
import math
import os
import pathlib
import platform
import statistics
import subprocess
import sys
import tempfile
import time

from bench_report import lscpu  # the machine, read the same way as the benchmark

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "python"))

import stress_cases as S  # noqa: E402

MIN_CPU = 0.2  # s of CPU per timing sample group
MAX_REPEATS = 25
COMMAND = "make stability"
BASE = "S1"


def git_state() -> str:
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "src"], cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + (" with uncommitted changes in src/" if dirty else "")


def cpu_samples(case: S.Case, driver: S.Driver, first: S.Run | None) -> list[float]:
    """CPU seconds in fmi2DoStep of the case's run, repeated while short."""
    samples = [first.cpu] if first is not None else []
    if first is not None and (first.status != "ok" or first.cpu >= MIN_CPU):
        return samples
    while len(samples) < MAX_REPEATS and sum(samples) < MIN_CPU:
        samples.append(S.main_run(case, driver).cpu)
    return samples


def method_label(run: S.Run | None) -> str:
    if run is None or not run.methods:
        return "-"
    names = {1: "explicit", 2: "Radau IIA"}
    return " + ".join(names.get(m, str(m)) for m in run.methods)


def fmt(x, spec=".3g") -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return format(x, spec).replace("e-0", "e-").replace("e+0", "e+")


def fmt_count(x) -> str:
    if x is None or not math.isfinite(x):
        return "-"
    return f"{x:,.0f}".replace(",", " ")


def fmt_s(x: float) -> str:
    if x >= 1e4:
        return f"{x / 3600:.3g} h"
    if x >= 1:
        return f"{x:.3g} s"
    if x >= 1e-3:
        return f"{x * 1e3:.3g} ms"
    return f"{x * 1e6:.3g} µs"


def sci(x: float) -> str:
    """1e-08 -> 1e-8."""
    return f"{x:g}".replace("e-0", "e-").replace("e+0", "e+")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fmu", default=str(S.FMU_PATH))
    ap.add_argument("--out", default=str(ROOT / "docs" / "STABILITY.md"))
    ap.add_argument("--cases", default="", help="comma-separated case names (default: all)")
    args = ap.parse_args()

    from fmpy import extract, read_model_description

    fmu = pathlib.Path(args.fmu)
    if not fmu.is_file():
        print(f"{fmu} does not exist: build it with `make fmu`", file=sys.stderr)
        return 2
    md = read_model_description(str(fmu))
    tmp = tempfile.TemporaryDirectory(prefix="stability_")
    driver = S.Driver(extract(str(fmu), unzipdir=tmp.name), md)
    cases = S.CASES
    if args.cases:
        wanted = [c.strip() for c in args.cases.split(",") if c.strip()]
        unknown = [w for w in wanted if w not in S.BY_NAME]
        if unknown:
            print(f"unknown case(s): {unknown}; known: {list(S.BY_NAME)}", file=sys.stderr)
            return 2
        cases = [S.BY_NAME[w] for w in wanted]
    base = S.BY_NAME[BASE]

    started = time.time()
    load0 = os.getloadavg()
    base_cpu = cpu_samples(base, driver, None)
    rows = []
    for c in cases:
        w0 = time.perf_counter()
        v = S.evaluate(c, driver)
        wall = time.perf_counter() - w0
        samples = cpu_samples(c, driver, v.run)
        if c.name == BASE:
            base_cpu += samples
        rows.append((c, v, samples, wall))
        print(f"[{'pass' if v.passed else 'FAIL'}] {wall:7.2f} s  {v.message()}", flush=True)
    base_cpu += cpu_samples(base, driver, None)
    load1 = os.getloadavg()
    base_rate = statistics.median(base_cpu) / base.duration
    elapsed = time.time() - started

    # ---- the document
    cpu = lscpu()
    out = []
    w = out.append
    w("# Stability: the stress suite")
    w("")
    w(f"Generated by `{COMMAND}` (scripts/stability_report.py) on "
      f"{datetime.datetime.now(datetime.timezone.utc).strftime('%Y-%m-%d %H:%M UTC')}, in {elapsed:.0f} s. "
      "The same cases and checks run in `make test` as tests/python/test_stress.py "
      "(case table and checks: tests/python/stress_cases.py).")
    w("")
    n_pass = sum(1 for _, v, _, _ in rows if v.passed)
    w(f"**{n_pass} of {len(rows)} cases pass.** FMU: `{fmu.relative_to(ROOT) if fmu.is_relative_to(ROOT) else fmu}`, "
      f"GUID {md.guid}, built from commit {git_state()}.")
    failing = [(c, v) for c, v, _, _ in rows if not v.passed]
    if failing:
        w("")
        w("Failing: " + "; ".join(f"**{c.name}** ({v.outcome}{', ' + v.measure + ' = ' + fmt(v.error, '.2g') + ' > ' + sci(v.bound) if math.isfinite(v.error) else ''})" for c, v in failing) + ".")
    w("")
    w("## How each case is judged")
    w("")
    w("Every case runs the FMU in sine mode (`excitation = 1`, S1 = 30 Hz, 300 rad/s² RMS unless the "
      "parameters say otherwise) through fmpy's FMU2Slave, reading every output at every "
      "communication point. A case passes when no output is ever NaN/Inf and")
    w("")
    w("- **ref**: max |Δξ| against the independent reference (tests/python/reference.py, DOP853 at "
      "rtol 1e-12, Radau at 1e-10 where marked) over the window, divided by max(G, max |ξ_ref|) "
      "(the tolerance is relative: where the teeth go deeper than G, |ξ| is the scale), is at most "
      "10 × rtol, rtol being the tolerance given to the FMU; and the impact counts per flank agree;")
    w("- **energy** (C = C_LM = 0): the balance of MODEL.md §3 from the FMU's outputs alone, "
      "within 10 × rtol (forced: ½ I_L ω_L² + V(ξ) − ∫ −τ_M ω_M dt, the work integrated every 2 µs "
      "with the output derivatives, relative to the largest kinetic energy; shaft at rest: "
      "½ I_L ω_L² + V(ξ) relative to its initial value);")
    w("- **hour**: 1 h at ω_mean = 84 rad/s; the last second is compared with (a) the last second "
      "of a 2 s run from the default start (no drift: the same periodic motion), (b) a run started "
      "at t = 0 from the hour's ξ, ξ' at 3599 s (same sine phase), (c) the reference from that "
      "state over 0.1 s; each within 10 × rtol;")
    w("- **refuse**: where refusing is the right answer (the case says why, below), the FMU must "
      "refuse: fmi2Discard/fmi2Error, a log line saying what happened and at what time, fmi2GetReal "
      "still giving the last good state.")
    w("")
    w("Every other case must be solved: a refused step (\"gave up\") fails it. The windows "
      "are short (12 ms: S1's first two impacts) because the integrator bounds the error per step "
      "(a quarter of rtol each, `LOCAL_SHARE` in src/rattle.rs) and those errors add up: with the "
      "whole rtol per step, S1's error grew by 2-5 rtol per impact, while the model itself does not "
      "amplify it (a change of ξ(0) comes out ×1.5 after 50 ms); so 10 × rtol is a claim about a "
      "few impacts.")
    w("")
    w("CPU is the process time inside fmi2DoStep (median of repeats for runs under "
      f"{MIN_CPU:g} s); **CPU ratio** = (CPU per simulated second) / (S1's CPU per simulated second), "
      f"S1 measured {len(base_cpu)} times before, among and after the cases: "
      f"{statistics.median(base_cpu) * 1e3:.3g} ms for its {fmt_s(base.duration)}.")
    w("")
    w("## Results")
    w("")
    w("| case | parameters (vs S1) | rtol | comm. step | window | method | steps | RHS | CPU | CPU ratio | check | error | allowed | result |")
    w("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for c, v, samples, _ in rows:
        r = v.run
        cpu_med = statistics.median(samples) if samples else math.nan
        ratio = cpu_med / c.duration / base_rate if r is not None and r.status == "ok" else math.nan
        if v.passed:
            result = "pass" if v.outcome == "solved" else f"pass ({v.outcome})"
        else:
            result = f"**FAIL**: {v.outcome}"
        window = f"{fmt_s(c.duration)}" + (f" from t = {sci(c.t0)} s" if c.t0 else "")
        comm = fmt_s(c.h)
        if c.check == "hour":
            window = "1 h (last 1 s compared)"
            comm = f"1 s, the last second {fmt_s(c.h)}"
        w(
            f"| {c.name} | {c.describe()} | {sci(c.rtol)} | {comm} | {window} | {method_label(r)} "
            f"| {fmt_count(r.steps if r else math.nan)} | {fmt_count(r.rhs if r else math.nan)} "
            f"| {fmt_s(cpu_med) if math.isfinite(cpu_med) else '-'} | {fmt(ratio, '.2g')} | {'refuse' if c.refuse else c.check} "
            f"| {fmt(v.error, '.2g')} | {sci(v.bound) if math.isfinite(v.bound) else '-'} | {result} |"
        )
    w("")
    w("Error measures: ref: max|Δξ| / max(G, max|ξ_ref|); energy: drift / scale as above; "
      "hour: the largest of (a), (b), (c).")
    w("")
    w("## Per case")
    w("")
    for c, v, _, wall in rows:
        w(f"- **{c.name}**: {c.about}. {v.outcome}; {wall:.2f} s wall for the case (FMU and reference, "
          f"reference {v.ref_seconds:.2f} s).")
        for p in v.problems:
            w(f"  - problem: {p}")
        for n in v.notes:
            w(f"  - {n}")
    w("")
    w("## Machine")
    w("")
    w(f"- CPU: {cpu.get('Model name', platform.processor() or '?')}, {cpu.get('CPU(s)', os.cpu_count())} logical CPU(s), "
      f"hypervisor {cpu.get('Hypervisor vendor', 'none')}; {platform.system()} {platform.release()}.")
    w(f"- Load average at the start {load0[0]:.2f} / {load0[1]:.2f} / {load0[2]:.2f}, at the end "
      f"{load1[0]:.2f} / {load1[1]:.2f} / {load1[2]:.2f} (1, 5, 15 min): CPU times are process times, "
      "the ratios are the figures to read.")
    w(f"- Python {platform.python_version()}, fmpy {_version('fmpy')}, numpy {_version('numpy')}, scipy {_version('scipy')}.")
    w("")
    w("## Regenerate")
    w("")
    w("```")
    w(COMMAND)
    w("```")
    w("")
    w("(builds the FMU if needed, then runs `.venv/bin/python scripts/stability_report.py`; "
      "`--cases \"S1,eps 0\"` runs a subset, `--out` writes elsewhere). The pass/fail verdicts are "
      "those of `.venv/bin/python -m pytest tests/python/test_stress.py`, part of `make test`.")
    text = "\n".join(out) + "\n"
    dest = pathlib.Path(args.out)
    dest.parent.mkdir(parents=True, exist_ok=True)
    dest.write_text(text)
    print(f"wrote {dest} ({n_pass}/{len(rows)} pass) in {elapsed:.0f} s")
    return 0


def _version(mod: str) -> str:
    try:
        from importlib.metadata import version

        return version(mod)
    except Exception:
        return "?"


if __name__ == "__main__":
    sys.exit(main())
