"""The WAV files' calibration and the metrics of a sound (docs/SOUND.md, "Metrics").

A WAV sample of 1.0 is `full_scale` pascals, written into the file's comment: a power of two
chosen per run so that the loudest sample of the run's files is within 6 dB of 1.0 (audible as
it is, never clipped), the same for every file of a run (mix, stems, A/B). The metrics read the
pressure back from the WAV through `read_wav`, the way a user's tool would, so that the file
and the reported figures cannot disagree.

- Loudness: Zwicker's method for time-varying sounds (ISO 532-1:2017, free field), from
  MoSQITo: N(t) every 2 ms; N5 is the loudness exceeded 5 % of the time, N_mean its mean.
- Sharpness: DIN 45692 weighting of the same specific loudness (MoSQITo), averaged over the
  instants where N ≥ 0.1 sone (the standard leaves sharpness undefined near silence).
- LAeq: the A-weighted equivalent level over the file, dB re 20 µPa; the weighting is
  IEC 61672-1's closed form applied to the signal's spectrum (MoSQITo has only a table for
  spectra; Parseval makes the level exact for the whole file)."""

from dataclasses import dataclass

import numpy as np
from mosqito.sq_metrics import loudness_zwtv, sharpness_din_from_loudness

FS = 48000  # the WAVs' sample rate [Hz]
CALIBRATION = "sound pressure: 1.0 = {:.17g} Pa"  # the WAV comment
P_REF = 20e-6  # reference pressure [Pa]
SHARPNESS_FROM = 0.1  # loudness [sone] above which sharpness is averaged


def full_scale(*signals):
    """The smallest power of two [Pa] at or above the signals' largest |p| (1 Pa for silence)."""
    peak = max((float(np.max(np.abs(s))) for s in signals if len(s)), default=0.0)
    return 2.0 ** np.ceil(np.log2(peak)) if peak > 0 else 1.0


def write_wav(path, p, scale, fs=FS):
    """p [Pa] as a 32-bit float WAV whose sample 1.0 is `scale` pascals."""
    import soundfile as sf

    with sf.SoundFile(path, "w", samplerate=fs, channels=1, subtype="FLOAT") as f:
        f.comment = CALIBRATION.format(scale)
        f.write((np.asarray(p, dtype=float) / scale).astype(np.float32))
    return path


def read_wav(path):
    """(p [Pa], fs) of a WAV written by write_wav (its comment gives the calibration)."""
    import re

    import soundfile as sf

    with sf.SoundFile(path) as f:
        m = re.fullmatch(CALIBRATION.replace("{:.17g}", r"(\S+)"), f.comment or "")
        if not m:
            raise ValueError(f"{path}: no calibration in the WAV's comment (expected "
                             f"'{CALIBRATION.format(1.0)}'): not a file of gearrattle-study listen")
        x = f.read(dtype="float64")
    return x * float(m[1]), f.samplerate


@dataclass
class Metrics:
    N5: float  # sone
    N_mean: float  # sone
    sharpness: float  # acum (nan when N < SHARPNESS_FROM throughout)
    LAeq: float  # dB(A) re 20 µPa (-inf for silence)
    t: np.ndarray  # the loudness's instants [s]
    N: np.ndarray  # loudness against time [sone]
    cpu_s: float  # CPU time of the metrics


def a_weighting(f):
    """IEC 61672-1 A-weighting as a gain (not dB) at the frequencies f [Hz]."""
    f2 = np.asarray(f, dtype=float) ** 2
    ra = (12194.0 ** 2 * f2 ** 2) / ((f2 + 20.6 ** 2) * np.sqrt((f2 + 107.7 ** 2)
                                     * (f2 + 737.9 ** 2)) * (f2 + 12194.0 ** 2))
    return ra * 10 ** (2.0 / 20)  # +2.00 dB: 0 dB at 1 kHz


def laeq(p, fs):
    """A-weighted equivalent level [dB re 20 µPa] of p [Pa] over its duration."""
    spec = np.fft.rfft(p)
    w = a_weighting(np.fft.rfftfreq(len(p), 1 / fs))
    power = np.abs(spec * w) ** 2
    power[1:(len(p) + 1) // 2] *= 2  # the negative frequencies (not DC, not Nyquist)
    mean_sq = power.sum() / len(p) ** 2
    return 10 * np.log10(mean_sq / P_REF ** 2) if mean_sq > 0 else -np.inf


def metrics(p, fs=FS):
    """The metrics of p [Pa] sampled at fs."""
    import time

    t0 = time.process_time()
    p = np.asarray(p, dtype=float)
    N, N_spec, _, t = loudness_zwtv(p, fs, field_type="free")
    loud = N >= SHARPNESS_FROM
    if loud.any():
        S = np.atleast_1d(sharpness_din_from_loudness(N[loud], N_spec[:, loud], "din"))
        sharp = float(np.mean(S))
    else:
        sharp = float("nan")
    return Metrics(N5=float(np.percentile(N, 95)), N_mean=float(np.mean(N)), sharpness=sharp,
                   LAeq=float(laeq(p, fs)), t=np.asarray(t), N=np.asarray(N),
                   cpu_s=time.process_time() - t0)
