"""A measured transfer: the impulse response from a mesh force [N] to the pressure [Pa] at the
listening point, read from a WAV file (docs/SOUND.md, "A measured transfer").

The file holds the discrete impulse response at 48 kHz in Pa/N as float samples: sample k is
the pressure k/48000 s after a unit force sample, so p[n] = Σ_k h[k] F[n − k] and the DFT of h is
the frequency response in Pa/N. One channel serves every mesh; a gearbox may give one channel
per mesh (channel i for gear[i]). The force is brought to 48 kHz with an anti-aliasing
polyphase filter (the measured response is band-limited the same way) and convolved."""

import numpy as np

from .metrics import FS


class ImpulseResponse:
    kind = "impulse response"

    def __init__(self, path, channels):
        self.path = path
        self.h = channels  # array (samples, channels)

    def check_meshes(self, n_meshes):
        c = self.h.shape[1]
        if c not in (1, n_meshes):
            expected = ("one channel is expected" if n_meshes == 1 else
                        f"give one channel (every mesh) or {n_meshes} (channel i for gear[i])")
            raise ValueError(f"{self.path}: {c} channels for {n_meshes} mesh"
                             f"{'es' if n_meshes > 1 else ''}: {expected}; keep the channel "
                             f"of the listening point, e.g. sox {self.path} ir_mono.wav remix 1")

    def render(self, force, mesh, subsample):
        """The pressure at the WAV's instants of one mesh's force sampled subsample times finer,
        the force before its first sample held at that sample's value (the housing at rest
        under it, as in ModalTransfer.pressure)."""
        from scipy.signal import oaconvolve, resample_poly

        force = np.asarray(force, dtype=float)
        f48 = resample_poly(force, 1, subsample, padtype="edge")[:len(force[::subsample])]
        h = self.h[:, 0 if self.h.shape[1] == 1 else mesh]
        p = oaconvolve(f48, h)[:len(f48)]
        # Σ_{k>n} h[k] F[0]: the held force's share of p[n]
        tail = (h.sum() - np.cumsum(h))[:len(p)]
        p[:len(tail)] += force[0] * tail
        return p

    def describe(self):
        return (f"impulse response {self.path} ({self.h.shape[0]} samples at {FS} Hz, "
                f"{self.h.shape[1]} channel{'s' if self.h.shape[1] > 1 else ''}, "
                f"peak |H| {np.abs(np.fft.rfft(self.h, axis=0)).max():.3g} Pa/N)")


def read_impulse(path):
    """The impulse response in a WAV file, refused with a message that names the fix when it
    cannot be one."""
    import soundfile as sf

    try:
        info = sf.info(path)
    except (RuntimeError, sf.LibsndfileError) as e:
        raise ValueError(f"{path}: not a readable sound file ({e}): give a WAV file of the "
                         f"impulse response in Pa/N at {FS} Hz") from None
    if info.samplerate != FS:
        raise ValueError(f"{path}: sample rate {info.samplerate} Hz, {FS} Hz expected: resample "
                         f"it, e.g. sox {path} -r {FS} ir_{FS // 1000}k.wav")
    if info.subtype not in ("FLOAT", "DOUBLE"):
        raise ValueError(f"{path}: {info.subtype_info} samples cannot hold Pa/N: write it as "
                         f"32-bit float, e.g. soundfile.write(path, h, {FS}, subtype='FLOAT')")
    h, _ = sf.read(path, dtype="float64", always_2d=True)
    if h.shape[0] == 0:
        raise ValueError(f"{path}: no samples: export the measured impulse response "
                         f"(h[k] in Pa/N, k = 0, 1, ...) into it")
    bad = ~np.isfinite(h)
    if bad.any():
        k, c = np.argwhere(bad)[0]
        raise ValueError(f"{path}: {int(bad.sum())} samples are NaN or infinite (the first at "
                         f"sample {k}, channel {c + 1}): replace them (e.g. by 0) or export the "
                         f"measurement again")
    return ImpulseResponse(path, h)
