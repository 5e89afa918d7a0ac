"""The metrics through the tool's own path: pressure written to a calibrated WAV, read back,
measured with MoSQITo."""

import numpy as np

from gearrattle.sound.metrics import full_scale, metrics, read_wav, write_wav
from sound_support import FS


def test_a_1_khz_tone_at_40_db_is_1_sone_and_40_db_a(tmp_path):
    t = np.arange(FS) / FS
    p = np.sqrt(2) * 20e-6 * 10 ** (40 / 20) * np.sin(2 * np.pi * 1000 * t)
    path = write_wav(tmp_path / "tone.wav", p, full_scale(p))
    q, fs = read_wav(path)
    m = metrics(q, fs)
    assert abs(m.N5 - 1.0) < 0.05, f"N5 = {m.N5:.4f} sone"  # ISO 532-1's reference point
    assert abs(m.LAeq - 40.0) < 0.05, f"LAeq = {m.LAeq:.3f} dB(A)"
    assert 0.5 < m.sharpness < 2.0


def test_the_calibration_travels_in_the_wav(tmp_path):
    p = np.array([0.0, 0.3, -0.7, 0.05])
    path = write_wav(tmp_path / "x.wav", p, full_scale(p))
    q, _ = read_wav(path)
    np.testing.assert_allclose(q, p, rtol=1e-7)
