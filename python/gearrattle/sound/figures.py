"""The figures of `listen`: the spectrogram of the mix with the impact instants marked (and the
pressure over the first excitation periods beneath), and the loudness against time."""

import numpy as np

from .metrics import FS, P_REF
from .render import times

WAVE_WINDOW = 0.1  # seconds of pressure drawn beneath the spectrogram


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def spectrogram(path, sound, run, title):
    """Spectrogram (dB re 20 µPa) with a tick per impact at the top, coloured by mesh."""
    from scipy.signal import spectrogram as stft

    plt = _plt()
    fig, (ax, aw) = plt.subplots(2, 1, figsize=(10, 6.5), height_ratios=(2.2, 1))
    seg = min(512, len(sound.mix))  # 10.7 ms windows, 3/4 overlapping
    f, t, S = stft(sound.mix, FS, nperseg=seg, noverlap=3 * seg // 4, scaling="spectrum")
    S_db = 10 * np.log10(np.maximum(S, 1e-30) / P_REF ** 2)
    top = float(S_db.max()) if np.isfinite(S_db).any() else 0.0
    mesh = ax.pcolormesh(sound.t0 + t, f / 1e3, S_db, shading="auto", cmap="magma",
                         vmin=top - 70, vmax=top)
    fig.colorbar(mesh, ax=ax, label="dB re 20 µPa")
    ax.set_ylabel("frequency [kHz]")
    ax.set_ylim(0, 12)
    t_end = sound.t0 + len(sound.mix) / FS
    ax.set_xlim(sound.t0, t_end)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, (m, imp) in enumerate(zip(run.meshes, run.impacts)):
        c = colours[(i + 2) % len(colours)]
        ax.vlines(imp[:, 1], 11.0, 12.0, colors=c, linewidth=0.7,
                  label=f"{m.label} impacts ({len(imp)})")
        win = imp[imp[:, 1] <= sound.t0 + WAVE_WINDOW]
        aw.vlines(win[:, 1] * 1e3, 0, 1, transform=aw.get_xaxis_transform(), colors=c, linewidth=0.7,
                  alpha=0.6)
    ax.legend(loc="upper right", fontsize=7)
    ax.set_title(title, fontsize=9)
    n = min(len(sound.mix), int(WAVE_WINDOW * FS))
    aw.plot(times(n, sound.t0) * 1e3, sound.mix[:n], lw=0.6, color="k")
    aw.set_xlabel("time [ms] (lines: impacts)")
    aw.set_ylabel("p [Pa]")
    aw.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def loudness(path, results, title):
    """Loudness against time: results = [(label, Metrics)]."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(9, 3.6))
    for label, m in results:
        line, = ax.plot(m.t, m.N, lw=0.9, label=f"{label}: N5 {m.N5:.2f} sone, "
                                                 f"mean {m.N_mean:.2f} sone")
        ax.axhline(m.N5, color=line.get_color(), ls="--", lw=0.7)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("loudness [sone] (ISO 532-1)")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
