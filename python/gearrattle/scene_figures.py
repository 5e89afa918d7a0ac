"""The demo's figures in the style of Dion et al. 2009, Figs. 14-24: per scene the loose gear's
acceleration, speed, angle and ξ over a few excitation periods with the impacts marked, the
periodogram and the spectrum of the acceleration; and S1's overview."""

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from . import rattle_stats as rs  # noqa: E402

C_PLUS, C_MINUS = "tab:red", "tab:blue"


def spectrum(t, a):
    """Single-sided amplitude spectrum (Hann window, amplitude-corrected)."""
    a = a - np.mean(a)
    w = np.hanning(len(a))
    X = np.fft.rfft(a * w)
    f = np.fft.rfftfreq(len(a), d=t[1] - t[0])
    return f, 2.0 * np.abs(X) / np.sum(w)


def mark_impacts(ax, t, y, ev, sel_t=None):
    for fl, col, mk, lab in ((rs.FPLUS, C_PLUS, "v", "impact on F+"),
                             (rs.FMINUS, C_MINUS, "^", "impact on F-")):
        i = ev["index"][ev["flank"] == fl]
        if sel_t is not None:
            i = i[(t[i] >= sel_t[0]) & (t[i] <= sel_t[1])]
        ax.plot(t[i], y[i], mk, color=col, ms=4, ls="none", label=lab)


def xi_panel(ax, t, xi, ev, G, win):
    sel = (t >= win[0]) & (t <= win[1])
    ax.plot(t[sel], 1e6 * xi[sel], color="k", lw=0.8, label=r"$\xi$")
    ax.axhline(0.0, color=C_PLUS, ls="-.", lw=1.0, label=r"flank F+: $\xi = 0$")
    ax.axhline(1e6 * G, color=C_MINUS, ls="-.", lw=1.0,
               label=rf"flank F-: $\xi = G$ = {1e6 * G:g} µm")
    mark_impacts(ax, t, 1e6 * xi, ev, win)
    ax.set_ylabel(r"$\xi$ [µm]")
    ax.legend(loc="upper right", fontsize=7, ncol=5)


def headroom(ax, frac=0.25):
    """Room above the curves for the legend."""
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + frac * (hi - lo))


def time_panels(axes, res, ev, p, win, which):
    t = res["time"]
    sel = (t >= win[0]) & (t <= win[1])
    ts = t[sel]
    rL, rM = p["r_L"], p["r_M"]
    for ax, key in zip(axes, which):
        if key == "a":
            ax.plot(ts, res["a_pitch_L"][sel], color="k", lw=0.7, label=r"loose gear $r_L \dot\omega_L$")
            ax.plot(ts, rM * res["alpha_M_out"][sel], color="0.5", ls="--", lw=0.9,
                    label=r"main shaft $r_M \dot\omega_M$")
            ax.set_ylabel(r"$a_{pitch,L}$ [m/s²]")
            ax.legend(loc="upper right", fontsize=7, ncol=2)
        elif key == "w":
            ax.plot(ts, res["omega_L"][sel], color="k", lw=0.8, label=r"$\omega_L$")
            ax.plot(ts, rM / rL * res["omega_M_out"][sel], color="0.5", ls="--", lw=0.9,
                    label=r"rigid meshing $r_M\omega_M/r_L$")
            ax.set_ylabel(r"$\omega_L$ [rad/s]")
            sec = ax.secondary_yaxis("right", functions=(lambda w: 1e3 * rL * w,
                                                         lambda v: v / (1e3 * rL)))
            sec.set_ylabel("pitch line [mm/s]", fontsize=8)
            ax.legend(loc="upper right", fontsize=7, ncol=2)
        elif key == "th":
            ax.plot(ts, 1e3 * res["theta_L"][sel], color="k", lw=0.8, label=r"$\theta_L$")
            ax.plot(ts, 1e3 * rM / rL * res["theta_M_out"][sel], color="0.5", ls="--", lw=0.9,
                    label=r"rigid meshing $r_M\theta_M/r_L$")
            ax.set_ylabel(r"$\theta_L$ [mrad]")
            sec = ax.secondary_yaxis("right", functions=(lambda th: rL * th * 1e3,
                                                         lambda v: v / (rL * 1e3)))
            sec.set_ylabel("pitch line [µm]", fontsize=8)
            ax.legend(loc="upper right", fontsize=7, ncol=2)
        elif key == "xi":
            xi_panel(ax, t, res["xi"], ev, p["G"], win)
        ax.grid(alpha=0.3)
        ax.set_xlim(*win)
        headroom(ax)
    axes[-1].set_xlabel("time [s]")


def scene_figure(path, scene, res, st, p, t_from, n_periods):
    t = res["time"]
    f = scene["f"]
    win = (t_from, min(t_from + n_periods / f, t[-1]))
    fig, axes = plt.subplots(6, 1, figsize=(10, 15), constrained_layout=True)
    for ax in axes[1:4]:
        ax.sharex(axes[0])
    time_panels(axes[:4], res, st["events"], p, win, ("a", "w", "th", "xi"))
    for ax in axes[:3]:
        ax.tick_params(labelbottom=False)
    axes[0].set_xlim(*win)
    axes[3].set_xlabel(f"time [s] ({n_periods} excitation periods)")

    # Periodogram: |a_pitch_L| against the period number N = t f_exc, whole record.
    ax = axes[4]
    ax.plot(t * f, np.abs(res["a_pitch_L"]), color="k", lw=0.4)
    ax.axvline(t_from * f, color="0.5", ls=":", lw=1.0)
    ax.text(t_from * f, 0.97, " statistics from here", transform=ax.get_xaxis_transform(),
            fontsize=7, color="0.4", va="top")
    ax.set_xlim(0, t[-1] * f)
    ax.set_xlabel(r"period number $N = t\,f_{exc}$")
    ax.set_ylabel(r"$|a_{pitch,L}|$ [m/s²]")
    ax.set_title("periodogram", fontsize=9)
    ax.grid(alpha=0.3)

    # Spectrum of a_pitch_L over the analysed window.
    ax = axes[5]
    sel = t >= t_from
    fr, amp = spectrum(t[sel], res["a_pitch_L"][sel])
    m = (fr > 0) & (fr <= 5000)
    ax.semilogy(fr[m], amp[m], color="k", lw=0.6)
    ax.set_xlim(0, 5000)
    lo = max(amp[m].max() * 1e-6, amp[m][amp[m] > 0].min()) if np.any(amp[m] > 0) else 1e-6
    ax.set_ylim(lo, amp[m].max() * 2)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(r"amplitude of $a_{pitch,L}$ [m/s²]")
    ax.set_title(f"spectrum ({t_from:g}-{t[-1]:g} s, Hann window; "
                 f"excitation at {f:g} Hz)", fontsize=9)
    ax.grid(alpha=0.3, which="both")

    mr = np.mean([n for _, n, _ in st["runs"]]) if st["runs"] else float("nan")
    rate = sum(v[1] for v in st["per_flank"].values())
    fig.suptitle(
        f"{scene['name']}: {f:g} Hz, {scene['A_rms']:g} rad/s² RMS - GearRattle FMU, paper's "
        f"parameters (cf. paper {scene['figs']})\n"
        f"{rate:.0f} impacts/s, mean run on one flank {mr:.2f}, "
        f"RMS $a_{{pitch,L}}$ {st['rms_a']:.1f} m/s² (over {t_from:g}-{t[-1]:g} s)",
        fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def overview_figure(path, scene, res, st, p, t_from, n_periods):
    t = res["time"]
    f = scene["f"]
    win = (t_from, min(t_from + n_periods / f, t[-1]))
    fig, axes = plt.subplots(3, 1, figsize=(10, 8), sharex=True, constrained_layout=True)
    time_panels(axes, res, st["events"], p, win, ("a", "w", "xi"))
    axes[-1].set_xlabel(f"time [s] ({n_periods} excitation periods)")
    # mark impacts on the acceleration too
    mark_impacts(axes[0], t, res["a_pitch_L"], st["events"], win)
    axes[0].legend(loc="upper right", fontsize=7, ncol=4)
    mr = np.mean([n for _, n, _ in st["runs"]]) if st["runs"] else float("nan")
    fig.suptitle(f"{scene['name']} overview: {f:g} Hz, {scene['A_rms']:g} rad/s² RMS - "
                 f"loose gear acceleration, speed and transmission error in the backlash band\n"
                 f"mean run of consecutive impacts on one flank: {mr:.2f} (paper measured 4-5)",
                 fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)
