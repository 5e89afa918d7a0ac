"""The worker's reuse of one FMU instance: a point run after others on a reset instance gives
the same bits as on a fresh instance; a point the FMU refuses is recorded with the FMU's own
message, and the next point on the same instance is unaffected."""

import math

import pytest

from gearrattle.study import worker
from gearrattle.study.model import read_model

POINT = {"excitation": 1, "f_exc": 42.0, "A_rms": 350.0, "G": 27e-6}
OTHERS = [{"excitation": 1, "f_exc": 60.0, "A_rms": 700.0},
          {"excitation": 1, "f_exc": 30.0, "A_rms": 100.0, "C": 0.05, "G": 40e-6}]
RECORD = ("xi", "xi_dot", "omega_L", "E_contact", "E_lubricant", "impacts_Fplus",
          "impacts_Fminus")


@pytest.fixture(scope="module")
def installed(fmu):
    model = read_model(fmu)
    with open(fmu, "rb") as f:
        path, model = worker.install_fmu(model.guid, f.read())
    return path, model


def _same_bits(a, b):
    return all(a[k] == b[k] or (isinstance(a[k], float) and math.isnan(a[k])
                                and math.isnan(b[k])) for k in a if k != "cpu_s")


def test_reset_instance_gives_the_bits_of_a_fresh_one(installed):
    fresh = worker.Instance(*installed)
    want = fresh.run(POINT, 0.5, RECORD)
    fresh.close()
    reused = worker.Instance(*installed)
    for p in OTHERS:
        assert reused.run(p, 0.5, RECORD)["status"] == "ok"
    got = reused.run(POINT, 0.5, RECORD)
    reused.close()
    assert want["status"] == got["status"] == "ok"
    assert set(want) == set(got) and len(want) > len(RECORD)
    assert _same_bits(want, got), (want, got)


def test_refused_point_is_recorded_with_the_fmu_message(installed):
    inst = worker.Instance(*installed)
    bad = inst.run({**POINT, "G": -1e-6}, 0.5, RECORD)
    after = inst.run(POINT, 0.5, RECORD)
    fresh = worker.Instance(*installed)
    want = fresh.run(POINT, 0.5, RECORD)
    inst.close()
    fresh.close()
    assert bad["status"] == "refused"
    assert "G" in bad["message"] and "error" in bad["message"], bad["message"]
    assert after["status"] == "ok" and _same_bits(after, want)
