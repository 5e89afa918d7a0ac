"""From a run's mesh forces to the sound pressure at the WAV's instants: one stem per mesh and
their sum, the mix (the transfer is linear, so the stems add up to the mix exactly)."""

from dataclasses import dataclass

import numpy as np

from .metrics import FS


@dataclass
class Sound:
    stems: list  # p [Pa] of each mesh at t0 + n / FS
    mix: np.ndarray  # their sum [Pa]
    t0: float
    cpu_s: float  # CPU time of the filtering

    def shares(self):
        """Each mesh's share of the sum of the stems' energies (the mix's energy differs from
        that sum by the stems' cross terms)."""
        e = np.array([float(np.sum(s * s)) for s in self.stems])
        return e / e.sum() if e.sum() > 0 else np.full(len(e), np.nan)


def load_transfer(spec):
    """The transfer named on the command line: `modal` (the default modes), a TOML file of
    modes, or a WAV file of an impulse response. Raises ValueError naming the fix."""
    from .impulse import read_impulse
    from .modal import ModalTransfer, read_modes

    if spec == "modal":
        return ModalTransfer()
    low = spec.lower()
    if low.endswith(".toml"):
        return read_modes(spec)
    if low.endswith(".wav"):
        return read_impulse(spec)
    raise ValueError(f"--transfer {spec}: give modal (the default modes), a modes file "
                     f"MODES.toml or an impulse response IR.wav")


def render(run, transfer, subsample):
    """The Sound of a meshes.Run through the transfer."""
    import time

    t0 = time.process_time()
    transfer.check_meshes(len(run.forces))
    stems = [transfer.render(f, i, subsample) for i, f in enumerate(run.forces)]
    mix = np.sum(stems, axis=0)
    return Sound(stems, mix, run.t0, time.process_time() - t0)


def times(n, t0=0.0):
    """The instants [s] of n WAV samples from t0."""
    return t0 + np.arange(n) / FS
