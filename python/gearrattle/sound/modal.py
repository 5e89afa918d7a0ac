"""The modal housing: the path from a mesh force F(t) [N] to the sound pressure p(t) [Pa] at the
listening point as a sum of damped modes (docs/SOUND.md, "The modal housing").

Mode k of mesh i is the band-pass

    H_ik(s) = g_ik · 2 ζ_k ω_k s / (s² + 2 ζ_k ω_k s + ω_k²),    ω_k = 2π f_k,

whose magnitude peaks at f_k with the value g_ik [Pa/N] (the gain is the transfer at the mode's
frequency), with no static pressure (H(0) = 0) and a 1/f roll-off above the mode: the shape of
a lightly damped housing mode seen through its surface velocity. p is the sum over meshes and
modes of each H_ik applied to F_i.

Each mode is discretised exactly for a force that is linear between its samples (first-order
hold, FOH), as one complex first-order recursion (the mode's pole), run at the WAV's rate on
the force samples of each WAV interval: it reproduces the continuous response to the
piecewise-linear force at every kept sample, so the only error is the force's deviation from
its linear interpolant,
|F − F_lin| ≤ h²/8 · max|F''|, filtered by the mode (docs/SOUND.md, "Error")."""

from dataclasses import dataclass

import numpy as np
from scipy.signal import lfilter, lfiltic


@dataclass(frozen=True)
class Mode:
    f: float  # natural frequency [Hz]
    zeta: float  # damping ratio
    gains: tuple  # gain at f [Pa/N], one per mesh (a single value: every mesh)

    def gain(self, mesh):
        return self.gains[0] if len(self.gains) == 1 else self.gains[mesh]

    def poles(self):
        """The continuous poles s = −ζω ± iω√(1−ζ²) [1/s], the one with positive imaginary part
        first."""
        w = 2 * np.pi * self.f
        wd = w * np.sqrt(1 - self.zeta ** 2)
        return np.array([complex(-self.zeta * w, wd), complex(-self.zeta * w, -wd)])


# A cast-aluminium automotive gearbox housing, heard at about 1 m: four modes in the band where
# Dion et al. (2009, §5.3) measured the rattle's impact spectrum (500 Hz to beyond 5 kHz), at
# frequencies in the range computed for a transmission casing's first twenty modes (1.2 to
# 3.6 kHz for a truck transmission casing by Kumar, Jaiswal and Patil) and one above, with the 1-2 % damping ratios of cast
# housings (Lim and Singh, NASA report 1989). The gains set the absolute level and are illustrative (docs/SOUND.md).
DEFAULT_MODES = (
    Mode(1250.0, 0.020, (0.030,)),
    Mode(2050.0, 0.015, (0.050,)),
    Mode(2900.0, 0.012, (0.040,)),
    Mode(4300.0, 0.010, (0.025,)),
)


def foh_recursion(mode, h, decimate=1):
    """The FOH recursion of a mode with unit gain at the sample interval h [s], kept at every
    `decimate`-th sample: the mode's complex state x (x' = s1 x + F, p = 2 Re(r x)) obeys

        x[n + D] = lam x[n] + sum_j c[j] F[n + j],   j = 0 .. D,   lam = exp(s1 h D)

    exactly for a force linear between its samples. Returns (lam, c, r, s1)."""
    s1 = mode.poles()[0]
    w = 2 * np.pi * mode.f
    r = 2 * mode.zeta * w * s1 / (s1 - np.conj(s1))
    e = np.exp(s1 * h)
    # one interval: x[n+1] = e x[n] + b0 F[n] + b1 F[n+1] (F linear in between)
    b0 = e / s1 - (e - 1) / (s1 * s1 * h)
    b1 = -1 / s1 + (e - 1) / (s1 * s1 * h)
    D = decimate
    c = np.zeros(D + 1, dtype=complex)
    for j in range(D):
        c[j] += e ** (D - 1 - j) * b0
        c[j + 1] += e ** (D - 1 - j) * b1
    return e ** D, c, r, s1


# Multiply-adds of one matrix product in _inputs: a product this small runs on one thread of
# the BLAS (OpenBLAS shares out those above 2^18); a shared one leaves its threads spinning
# after it, CPU that costs several times the product's and lands on whatever runs next.
PRODUCT = 1 << 17


def _inputs(recursions, force, D):
    """For each mode's recursion (lam, c, r, s1), Re(r u[m]) and Re(r conj(lam) u[m]) for
    m = 0 .. M − 1, u[m] = sum_j c[j] F[m D + j] (j = 0 .. D, M = (len(F) − 1) // D), as the
    columns of one matrix product: the force's windows of D + 1 samples, a view of it with
    rows D samples apart, times the real coefficients Re(r c[j]) and Re(r conj(lam) c[j]), in
    blocks of rows of PRODUCT multiply-adds. Returns (M, 2 K) for K modes, the first K columns
    the former."""
    M = (len(force) - 1) // D
    step = force.strides[0]
    windows = np.lib.stride_tricks.as_strided(force, (M, D + 1), (D * step, step),
                                              writeable=False)
    coefficients = np.array([(r * c).real for lam, c, r, _ in recursions]
                            + [(r * np.conj(lam) * c).real for lam, c, r, _ in recursions]).T
    u = np.empty((M, coefficients.shape[1]))
    rows = max(1, PRODUCT // coefficients.size)
    for i in range(0, M, rows):
        np.matmul(windows[i:i + rows], coefficients, out=u[i:i + rows])
    return u


def _real_part(recursion, forced, delayed, F0):
    """Re(r x[m]) for m = 0 .. M of a mode's recursion (lam, c, r, s1) driven by the force,
    x[0] = −F0/s1 (the state under the constant force F0), as one real second-order
    recursion: Re(r x) has the poles lam and conj(lam), so it is
    A(z) = 1 − 2 Re(lam) z⁻¹ + |lam|² z⁻² applied to Re(r (1 − conj(lam) z⁻¹) u), u[m] the
    complex input sum_j c[j] F[m D + j] entering at m + 1 (`forced` its Re(r u), `delayed`
    its Re(r conj(lam) u), from _inputs), plus the free response of x[0] (as initial
    conditions)."""
    lam, _, r, s1 = recursion
    v = np.zeros(len(forced) + 1)
    v[1:] = forced
    v[2:] -= delayed[:-1]
    a = [1.0, -2 * lam.real, abs(lam) ** 2]
    w = r * (-F0 / s1)  # Re(w lam^m), m = -1, -2: the free response before the start
    return lfilter([1.0], a, v, zi=lfiltic([1.0], a, [(w / lam).real, (w / lam ** 2).real]))[0]


class ModalTransfer:
    """Modes shared by every mesh, each mesh with its own gains."""

    kind = "modal"

    def __init__(self, modes=DEFAULT_MODES):
        self.modes = tuple(modes)

    def check_meshes(self, n_meshes):
        """Refuse gains given per mesh for another number of meshes."""
        for m in self.modes:
            if len(m.gains) not in (1, n_meshes):
                raise ValueError(f"the mode at {m.f:g} Hz has {len(m.gains)} gains for "
                                 f"{n_meshes} meshes: give one gain (all meshes) or one per mesh")

    def pressure(self, force, mesh, h, decimate=1):
        """The pressure [Pa] of one mesh's force samples F[n] = F(n h), the force before F[0]
        held at F[0]: the housing starts deflected by it and silent (H(0) = 0), as when a
        recording starts while a gear rests on its flank. Kept at every `decimate`-th sample
        (F[0], F[D], ...), each mode run at that rate on the D + 1 force samples of each of its
        intervals: one recursion over the kept samples instead of D."""
        force = np.asarray(force, dtype=float)
        D = decimate
        p = np.zeros((len(force) - 1) // D + 1)  # one more than the intervals of D samples
        heard = [(m.gain(mesh), foh_recursion(m, h, D)) for m in self.modes if m.gain(mesh)]
        if not heard:
            return p
        u = _inputs([rec for _, rec in heard], force, D)
        K = len(heard)
        for k, (g, rec) in enumerate(heard):
            p += 2 * g * _real_part(rec, u[:, k], u[:, K + k], force[0])
        return p

    def render(self, force, mesh, subsample):
        """The pressure at the WAV's instants (every subsample-th force sample)."""
        from .metrics import FS

        return self.pressure(force, mesh, 1.0 / (FS * subsample), subsample)

    def describe(self):
        return "modal housing: " + ", ".join(
            f"{m.f:g} Hz (zeta {m.zeta:g}, {'/'.join(f'{g:g}' for g in m.gains)} Pa/N)"
            for m in self.modes)


def read_modes(path):
    """Modes from a TOML file: [[mode]] tables with f [Hz], zeta and gain [Pa/N] (a number, or
    a list with one gain per mesh). Raises ValueError naming the fix."""
    import tomllib

    try:
        with open(path, "rb") as fh:
            doc = tomllib.load(fh)
    except OSError as e:
        raise ValueError(f"{path}: cannot read the modes ({e.strerror})") from None
    except tomllib.TOMLDecodeError as e:
        raise ValueError(f"{path}: malformed TOML ({e}): write [[mode]] tables with "
                         f"f = 1250.0, zeta = 0.02, gain = 0.03") from None
    modes = []
    for k, t in enumerate(doc.get("mode", [])):
        gain = t.get("gain")
        gains = tuple(gain) if isinstance(gain, list) else (gain,)
        f, zeta = t.get("f"), t.get("zeta")
        ok = all(isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x)
                 for x in (f, zeta, *gains))
        if not ok or not gains or not f > 0 or not 0 < zeta < 1:
            raise ValueError(f"{path}: mode {k + 1}: give f > 0 [Hz], 0 < zeta < 1 and gain "
                             f"[Pa/N] (a number or a list, one per mesh), e.g. f = 1250.0, "
                             f"zeta = 0.02, gain = 0.03")
        modes.append(Mode(float(f), float(zeta), tuple(float(g) for g in gains)))
    if not modes:
        raise ValueError(f"{path}: no [[mode]] table: add one per mode with f, zeta and gain")
    return ModalTransfer(modes)
