"""The sampling entry gearRattleDoStepSampled (docs/SOUND.md, "The force") on both FMUs: its
samples and the state it leaves are those of fmi2DoStep and fmi2GetReal called at every point
of the same grid, to the bit; a bad argument is refused with fmi2Error and a log line and
changes nothing; meshes.record takes the same forces through it as through the plain calls."""

import ctypes

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import fmi2Error, fmi2OK

from gearrattle.sound import meshes as M
from sound_support import FMU, GEARBOX_FMU, fmu
from support.slave import Slave

H = 1.0 / (48000 * 4)
CHUNKS = (960, 1, 2880)  # points per call: the run's first 20 ms, with impacts in both FMUs


@pytest.fixture(scope="module", params=[FMU, GEARBOX_FMU], ids=["GearRattle", "GearboxRattle"])
def unzipped(request):
    path = fmu(request.param)
    return extract(path), read_model_description(path)


def started(unzipped):
    unzipdir, md = unzipped
    s = Slave(unzipdir, md, "sampled")
    s.init(integers={"excitation": 1})
    return s


def forces(md):
    return [v.valueReference for v in md.modelVariables
            if v.name.endswith("F_contact") and v.causality == "output"]


def outputs(md):
    return [v.valueReference for v in md.modelVariables
            if v.type == "Real" and v.causality == "output"]


def sampled(s, t, dt, n, vrs, values=None):
    """gearRattleDoStepSampled on the Slave's instance; values None passes NULL."""
    call = M.sampled_call(s.fmu)
    vr = (ctypes.c_uint * len(vrs))(*vrs)
    at = None if values is None else values.ctypes.data
    return call(s.fmu.component, t, dt, n, ctypes.addressof(vr), len(vrs), at)


def test_the_samples_and_the_state_are_fine_grid_do_steps_to_the_bit(unzipped):
    _, md = unzipped
    vrs = forces(md)
    a, b = started(unzipped), started(unzipped)
    t, got, want = 0.0, [], []
    for n in CHUNKS:
        out = np.full((n, len(vrs)), np.nan)
        assert sampled(a, t, H, n, vrs, out) == fmi2OK, a.logs[-3:]
        got.append(out)
        for j in range(n):
            assert b.do_step(H, t + j * H) == fmi2OK
            st, v = b.get_real(vrs)
            assert st == fmi2OK
            want.append(v)
        t += n * H
    got, want = np.vstack(got), np.array(want)
    assert np.count_nonzero(want) > 100, "no contact in the run: the test would see no force"
    assert np.array_equal(got, want)
    assert a.get_real(outputs(md)) == b.get_real(outputs(md))
    # both continue alike from there
    assert a.do_step(1e-3, t) == b.do_step(1e-3, t) == fmi2OK
    assert a.get_real(outputs(md)) == b.get_real(outputs(md))
    a.free(), b.free()


def test_a_bad_argument_is_refused_with_its_reason_and_changes_nothing(unzipped):
    _, md = unzipped
    vrs = forces(md)
    s, ref = started(unzipped), started(unzipped)
    out = np.zeros((4, len(vrs)))
    bad = {
        "nSamples = 0": lambda: sampled(s, 0.0, H, 0, vrs, out),
        "is NULL": lambda: sampled(s, 0.0, H, 4, vrs, None),
        "unknown": lambda: sampled(s, 0.0, H, 4, [*vrs, 999999], np.zeros((4, len(vrs) + 1))),
        "does not match": lambda: sampled(s, 1.0, H, 4, vrs, out),
        "must be finite and > 0": lambda: sampled(s, 0.0, -H, 4, vrs, out),
    }
    for reason, call in bad.items():
        mark = s.mark()
        assert call() == fmi2Error, reason
        s.assert_logged(mark, "gearRattleDoStepSampled", reason)
    assert not out.any()
    assert sampled(s, 0.0, H, 4, vrs, out) == fmi2OK
    want = []
    for j in range(4):
        assert ref.do_step(H, j * H) == fmi2OK
        want.append(ref.get_real(vrs)[1])
    assert np.array_equal(out, want)
    s.free(), ref.free()


def test_record_takes_the_same_forces_through_the_entry_as_through_the_plain_calls(unzipped,
                                                                                   monkeypatch):
    unzipdir, md = unzipped
    values = M.start_values(md, {})
    with_entry = M.simulate(unzipdir, md, values, 0.02)
    monkeypatch.setattr(M, "sampled_call", lambda inst: None)
    plain = M.simulate(unzipdir, md, values, 0.02)
    for f, g in zip(with_entry.forces, plain.forces):
        # the two grids' points differ by rounding (t0 + k h against (t0 + k0 h) + j h)
        assert np.abs(f - g).max() <= 1e-9 * np.abs(g).max()
    for i, j in zip(with_entry.impacts, plain.impacts):
        assert np.array_equal(i, j)
