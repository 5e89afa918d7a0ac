"""`gearrattle-study listen` on GearboxRattle.fmu: one stem per gear, the stems summing to the
mix, and each stem's bursts starting at that gear's impacts, read independently through fmpy's
simulate_fmu from the gear's counters gear[i].impacts_Fplus / impacts_Fminus.

A gear bounces on its flank within a tenth of a millisecond, before its last burst has died
out, so a burst's start is read from the stem as where it stops being a free oscillation of
the one damped mode: during a free flight p[n] = 2 Re(λ) p[n−1] − |λ|² p[n−2] with
λ = e^{s₁/FS} (s₁ the mode's pole), and the residual of that recursion is the force heard."""

import numpy as np
from fmpy import read_model_description

from gearrattle.sound.metrics import read_wav
from gearrattle.sound.modal import Mode
from sound_support import FS, GEARBOX_FMU, fmu, impact_samples, listen
from test_listen import DAMPED

DURATION = 0.1  # the start-up strikes every gear in its first tens of milliseconds
MODE = Mode(5000.0, 0.7, (0.05,))  # DAMPED's mode
FLOOR = 1e-6  # of the stem's peak: above the float32 WAV's rounding in the residual
FREE = 2  # samples of free flight before a burst


def onsets(p):
    """The samples where p starts departing from MODE's free oscillation after FREE samples of
    it."""
    lam = np.exp(MODE.poles()[0] / FS)
    r = np.abs(p[2:] - 2 * lam.real * p[1:-1] + abs(lam) ** 2 * p[:-2]) / np.abs(p).max()
    forced = r > FLOOR
    return np.array([n + 2 for n in range(FREE, len(r))
                     if forced[n] and not forced[n - FREE:n].any()], dtype=int)


def n_gears():
    md = read_model_description(fmu(GEARBOX_FMU))
    return int(next(v.start for v in md.modelVariables if v.name == "n_gears"))


def test_stems_sum_to_the_mix_and_start_at_their_gears_impacts(tmp_path):
    modes = tmp_path / "damped.toml"
    modes.write_text(DAMPED)
    listen("--duration", DURATION, "--transfer", modes, "--out", tmp_path / "d",
           fmu_path=GEARBOX_FMU)
    n = n_gears()
    mix, fs = read_wav(tmp_path / "d" / "rattle.wav")
    stems = [read_wav(tmp_path / "d" / f"gear_{i}.wav")[0] for i in range(1, n + 1)]
    assert fs == FS and len(mix) == round(DURATION * FS) + 1
    assert not (tmp_path / "d" / f"gear_{n + 1}.wav").exists()
    # each file holds float32 samples: the sum agrees within their rounding
    np.testing.assert_allclose(np.sum(stems, axis=0), mix, rtol=0,
                               atol=n * 2.0 ** -23 * np.abs(mix).max())
    want = impact_samples(DURATION, {}, fmu_path=GEARBOX_FMU,
                          prefixes=[f"gear[{i}]." for i in range(1, n + 1)])
    heard = 0
    for i, (stem, w) in enumerate(zip(stems, want), start=1):
        got = onsets(stem)
        assert len(got) == len(w), f"gear {i}: {len(got)} bursts in its stem, {len(w)} impacts"
        late = got - w
        assert np.all((late >= 0) & (late <= 1)), f"gear {i}: onset - impact in samples: {late}"
        heard += len(w)
    assert heard >= 2 * n, f"only {heard} impacts: the test sees too few"
