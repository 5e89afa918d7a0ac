"""The stress suite: one test per case of gearrattle.stress.CASES, run on the built FMU.

Each test runs its case through fmpy (stress.Driver) and judges it (stress.evaluate): no
NaN/Inf in any output; the error against the independent reference (reference.py) within
10 × the requested tolerance over the case's window, or the invariant (energy balance, no
drift over an hour). Each case is "solved" or "gave up" (a refused fmi2DoStep): giving up
fails every case but the one whose right answer is a refusal (it says why), and there the
refusal must be clean (fmi2Discard/fmi2Error, a log line saying what happened and when,
fmi2GetReal still giving the last good state).

Steps, RHS evaluations, CPU and wall time in fmi2DoStep, and the error of every case are
attached to the test (record_property, for --junitxml) and written to
target/stress/test_stress.csv. scripts/stability_report.py runs the same cases into
docs/STABILITY.md."""

import csv
import math

import pytest

from gearrattle import stress as S


@pytest.fixture(scope="session")
def driver(unzipdir, model_description):
    return S.Driver(unzipdir, model_description)


@pytest.fixture(scope="session")
def results():
    rows = []
    yield rows
    if rows:
        out = S.ROOT / "target" / "stress" / "test_stress.csv"
        out.parent.mkdir(parents=True, exist_ok=True)
        with open(out, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)


@pytest.mark.parametrize("case", S.CASES, ids=[c.name for c in S.CASES])
def test_stress(case, driver, results, record_property):
    v = S.evaluate(case, driver)
    r = v.run
    row = {
        "case": case.name,
        "outcome": v.outcome,
        "passed": v.passed,
        "steps": r.steps if r else math.nan,
        "rejected": r.rejected if r else math.nan,
        "rhs": r.rhs if r else math.nan,
        "cpu_s": r.cpu if r else math.nan,
        "wall_s": r.wall if r else math.nan,
        "methods": " ".join(map(str, r.methods)) if r else "",
        "measure": v.measure,
        "error": v.error,
        "bound": v.bound,
    }
    results.append(row)
    for k, x in row.items():
        record_property(k, x)
    print(v.message())
    if not v.passed:
        pytest.fail(v.message(), pytrace=False)
