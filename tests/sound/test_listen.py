"""`gearrattle-study listen` on GearRattle.fmu as a user runs it: the WAV's time axis against the
FMU's impact events, silence without impacts, the A/B comparison and the refusals."""

import numpy as np
import soundfile as sf

from gearrattle.sound.metrics import read_wav
from sound_support import FS, fmu, impact_samples, listen, sound_json

DURATION = 0.2
# One heavily damped mode: each burst dies out within a free flight, so a burst's onset is the
# first sample above a floor after a quiet stretch, read from the WAV alone.
DAMPED = """[[mode]]
f = 5000.0
zeta = 0.7
gain = 0.05
"""
FLOOR = 1e-5  # of the WAV's peak
QUIET = 5  # samples below the floor before a burst


def onsets(p):
    loud = np.abs(p) > FLOOR * np.abs(p).max()
    out, quiet = [], QUIET
    for n, x in enumerate(loud):
        if x and quiet >= QUIET:
            out.append(n)
        quiet = 0 if x else quiet + 1
    return np.array(out)


def test_burst_onsets_are_the_impacts_within_one_sample(tmp_path):
    modes = tmp_path / "damped.toml"
    modes.write_text(DAMPED)
    listen("--duration", DURATION, "--transfer", modes, "--out", tmp_path / "d", process=True)
    p, fs = read_wav(tmp_path / "d" / "rattle.wav")
    assert fs == FS and len(p) == round(DURATION * FS) + 1
    want = impact_samples(DURATION, {})
    got = onsets(p)
    assert len(want) > 40
    assert len(got) == len(want), f"{len(got)} bursts in the WAV, {len(want)} impacts"
    late = got - want
    assert np.all((late >= 0) & (late <= 1)), f"onset - impact in samples: {late}"


def test_from_hears_the_run_from_then_on_the_same_time_axis(tmp_path):
    # A contact under way at t_from (read through simulate_fmu) is heard from the first sample.
    from fmpy import simulate_fmu

    t_from = 0.1
    modes = tmp_path / "damped.toml"
    modes.write_text(DAMPED)
    listen("--duration", t_from + DURATION, "--from", t_from, "--transfer", modes,
           "--out", tmp_path / "d")
    p, _ = read_wav(tmp_path / "d" / "rattle.wav")
    assert len(p) == round(DURATION * FS) + 1
    whole = impact_samples(t_from + DURATION, {})
    want = whole[whole > round(t_from * FS)] - round(t_from * FS)
    at_from = simulate_fmu(fmu(), start_values={"excitation": 1}, stop_time=t_from,
                           output=["F_contact"])["F_contact"][-1]
    if at_from != 0:
        want = np.r_[1, want]  # p[0] is the housing at rest under the held force
    got = onsets(p)
    assert len(want) > 40 and len(got) == len(want), f"{len(got)} bursts, {len(want)} impacts"
    late = got - want
    assert np.all((late >= 0) & (late <= 1)), f"onset - impact in samples: {late}"
    assert sound_json(tmp_path / "d")["from_s"] == t_from


def test_sound_starts_at_the_first_impact_with_the_default_housing(tmp_path):
    listen("--duration", 0.02, "--out", tmp_path)
    p, _ = read_wav(tmp_path / "rattle.wav")
    first = impact_samples(0.02, {})[0]
    assert np.all(p[:first] == 0) and p[first] != 0


def test_a_scene_without_impacts_is_silent(tmp_path):
    # 1 rad/s^2 RMS is below the level from which the bench rattles (docs/MODEL.md section 5)
    listen("--duration", 0.5, "--set", "A_rms=1", "--out", tmp_path)
    s = sound_json(tmp_path)["scenes"][0]
    assert s["impacts"] == [0]
    assert s["N5"] < 0.01 and s["N_mean"] < 0.01
    p, _ = read_wav(tmp_path / "rattle.wav")
    assert not p.any()


def test_compare_writes_a_then_pause_then_b_and_both_metric_sets(tmp_path):
    listen("--duration", 0.1, "--compare", "--b-set", "A_rms=500", "--out", tmp_path)
    a, _ = read_wav(tmp_path / "A" / "rattle.wav")
    b, _ = read_wav(tmp_path / "B" / "rattle.wav")
    ab, _ = read_wav(tmp_path / "ab.wav")
    pause = np.zeros(FS // 2)
    np.testing.assert_array_equal(ab, np.concatenate([a, pause, b]))
    scenes = sound_json(tmp_path)["scenes"]
    assert [s["values"]["A_rms"] for s in scenes[1:]] == [500.0]
    assert "A_rms" not in scenes[0]["values"]
    text = (tmp_path / "sound.txt").read_text()
    row = next(line for line in text.splitlines() if line.strip().startswith("loudness N5"))
    n5 = [float(x) for x in row.split()[-3:]]
    assert np.allclose(n5, [scenes[0]["N5"], scenes[1]["N5"], scenes[1]["N5"] - scenes[0]["N5"]],
                       atol=1e-3)
    for f in ("loudness.png", "A/spectrogram.png", "B/spectrogram.png", "A/impacts.csv"):
        assert (tmp_path / f).stat().st_size > 0


def _wav(path, data, fs=FS, subtype="FLOAT"):
    sf.write(path, data, fs, subtype=subtype)
    return path


def test_a_bad_impulse_response_is_refused_with_its_fix(tmp_path):
    h = np.zeros(256)
    h[0] = 0.01
    nan = h.copy()
    nan[7] = np.nan
    cases = {
        "wrong sample rate": (_wav(tmp_path / "r.wav", h, fs=44100), "sox"),
        "no samples": (_wav(tmp_path / "e.wav", np.zeros(0)), "no samples"),
        "NaN": (_wav(tmp_path / "n.wav", nan), "replace them"),
        "two channels": (_wav(tmp_path / "c.wav", np.column_stack([h, h])),
                         "one channel is expected"),
        "integer samples": (_wav(tmp_path / "i.wav", h, subtype="PCM_16"), "32-bit float"),
    }
    for what, (path, fix) in cases.items():
        code, err = listen("--duration", 0.01, "--transfer", path, "--out", tmp_path / "x",
                           check=False)
        assert code == 2, f"{what}: accepted"
        assert fix in err, f"{what}: {err}"
    assert not (tmp_path / "x" / "rattle.wav").exists()
