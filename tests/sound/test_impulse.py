"""A measured transfer against the modal housing: the default modes' impulse response written
as a WAV in Pa/N and read back as a measured transfer gives the modal housing's sound (the
differences: sampling the impulse response and the force's anti-aliasing filter)."""

import numpy as np
import soundfile as sf
from fmpy import read_model_description

from gearrattle.sound import meshes as M
from gearrattle.sound.impulse import read_impulse
from gearrattle.sound.metrics import laeq
from gearrattle.sound.modal import DEFAULT_MODES, ModalTransfer
from gearrattle.sound.render import render
from sound_support import FS, fmu


def sampled_impulse_response(modes, length):
    """h[k] = h(k / FS) / FS of the modes (Pa/N per force sample), halved at k = 0 where h(t)
    jumps (the trapezoidal rule)."""
    t = np.arange(int(length * FS)) / FS
    h = np.zeros(len(t))
    for m in modes:
        s1, s2 = m.poles()
        w = 2 * np.pi * m.f
        h += m.gains[0] * np.real(2 * (2 * m.zeta * w * s1 / (s1 - s2)) * np.exp(s1 * t)) / FS
    h[0] *= 0.5
    return h


def test_the_default_housing_as_an_impulse_response_sounds_the_same(tmp_path):
    path = tmp_path / "housing.wav"
    sf.write(path, sampled_impulse_response(DEFAULT_MODES, 0.05), FS, subtype="FLOAT")
    md = read_model_description(fmu())
    run = M.simulate(fmu(), md, M.start_values(md, {}), 0.1)
    modal = render(run, ModalTransfer(), M.SUBSAMPLE).mix
    measured = render(run, read_impulse(str(path)), M.SUBSAMPLE).mix
    rms = np.sqrt(np.mean((measured - modal) ** 2) / np.mean(modal ** 2))
    assert rms < 0.02, f"RMS difference {100 * rms:.2f} %"
    assert abs(laeq(measured, FS) - laeq(modal, FS)) < 0.1


def test_a_recording_started_under_load_is_the_whole_history_heard_from_then(tmp_path):
    from test_modal import a_history, held_start_error

    path = tmp_path / "housing.wav"
    sf.write(path, sampled_impulse_response(DEFAULT_MODES, 0.05), FS, subtype="FLOAT")
    ir = read_impulse(str(path))
    h = 1.0 / (FS * M.SUBSAMPLE)
    n0 = int(0.5 / h)
    F = a_history(n0 + int(0.05 / h), n0, h)
    err = held_start_error(lambda f: ir.render(f, 0, M.SUBSAMPLE), F, n0, M.SUBSAMPLE)
    # the anti-aliasing filter's start: its edge padding against the history's samples
    assert err < 1e-3, f"held start differs by {err:.1e} of the peak"
