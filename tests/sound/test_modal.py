"""The modal housing against analytic responses: a half-sine force pulse (closed form) and the
FMU's first impact (the free oscillation after the contact, from a quadrature of the force);
the level's scaling with the gains, the stems' sum, and the meshes found in a model
description."""

from types import SimpleNamespace

import numpy as np
from scipy.integrate import simpson

from gearrattle.sound import meshes as M
from gearrattle.sound.modal import Mode, ModalTransfer
from gearrattle.sound.render import render
from sound_support import FS, fmu, listen, sound_json

MODE = Mode(2000.0, 0.02, (1.0,))


def residue(mode):
    """p's impulse response is Re(2 r e^{s1 t}) with this r (docs/SOUND.md, The modal housing)."""
    s1, s2 = mode.poles()
    w = 2 * np.pi * mode.f
    return 2 * mode.zeta * w * s1 / (s1 - s2)


def half_sine_response(mode, F0, tau, t):
    """The closed-form response to F = F0 sin(pi t / tau) on [0, tau], zero elsewhere."""
    s1 = mode.poles()[0]
    om = np.pi / tau
    T = np.minimum(t, tau)

    def integral(c):  # of e^{c u} over [0, T]
        return (np.exp(c * T) - 1) / c

    conv = (integral(-s1 + 1j * om) - integral(-s1 - 1j * om)) / 2j
    return np.real(2 * residue(mode) * np.exp(s1 * t) * F0 * conv)


def test_half_sine_pulse_matches_the_closed_form_within_the_stated_bound():
    F0, errors = 100.0, []
    for sub in (2, 4, 8):
        h = 1.0 / (FS * sub)
        t = np.arange(240 * sub) * h
        tau = 15 * sub * h  # the pulse's end on the grid: F is smooth between samples
        F = np.where(t < tau, F0 * np.sin(np.pi * t / tau), 0.0)
        p = ModalTransfer([MODE]).pressure(F, 0, h)
        err = np.abs(p - half_sine_response(MODE, F0, tau, t)).max()
        # |F - F_lin| <= h^2/8 max|F''|, filtered by a mode whose |h(t)| integrates to at
        # most 2|r| / (zeta omega)
        bound = h * h / 8 * F0 * (np.pi / tau) ** 2 * 2 * abs(residue(MODE)) / (
            MODE.zeta * 2 * np.pi * MODE.f)
        assert err <= bound, f"subsample {sub}: error {err:.3g} Pa above the bound {bound:.3g}"
        errors.append(err)
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 3.5) & (ratios < 4.5)), f"not second order: {ratios}"


def test_one_mode_after_the_first_impact_is_the_analytic_damped_oscillation():
    from fmpy import read_model_description

    md = read_model_description(fmu())
    values = M.start_values(md, {})
    run = M.simulate(fmu(), md, values, 0.012)
    p = ModalTransfer([MODE]).pressure(run.forces[0], 0, run.h)
    t = run.t0 + np.arange(len(p)) * run.h
    F = run.forces[0]
    on = np.nonzero(F)[0]
    start, end = on[0], on[np.argmax(np.diff(on) > 1)] + 1 if np.any(np.diff(on) > 1) else None
    assert end is not None and len(run.impacts[0]) == 2, "expected two impacts in 12 ms"
    # the force of the first contact, sampled 8 times finer by the FMU, integrated by Simpson
    fine = M.simulate(fmu(), md, values, t[end + 1], subsample=32)
    tf = fine.t0 + np.arange(len(fine.forces[0])) * fine.h
    s1 = MODE.poles()[0]
    X = simpson(np.exp(-s1 * tf) * fine.forces[0], x=tf)
    free = slice(end + 1, on[on > end][0])  # from after the contact to the next impact
    want = np.real(2 * residue(MODE) * np.exp(s1 * t[free]) * X)
    err = np.abs(p[free] - want).max()
    assert err < 1e-3 * np.abs(want).max(), f"error {err:.3g} Pa of {np.abs(want).max():.3g}"
    assert t[start] < t[end] < t[free][0]


def test_doubling_every_gain_raises_the_level_by_6_02_db(tmp_path):
    from gearrattle.sound.modal import DEFAULT_MODES

    for name, k in (("one", 1), ("two", 2)):
        (tmp_path / f"{name}.toml").write_text("".join(
            f"[[mode]]\nf = {m.f}\nzeta = {m.zeta}\ngain = {k * m.gains[0]}\n"
            for m in DEFAULT_MODES))
        listen("--duration", 0.1, "--transfer", tmp_path / f"{name}.toml",
               "--out", tmp_path / name)
    one, two = (sound_json(tmp_path / n)["scenes"][0]["LAeq"] for n in ("one", "two"))
    assert abs(two - one - 20 * np.log10(2)) < 1e-3, f"{two - one:.5f} dB"


def test_stems_sum_to_the_mix_and_each_is_its_mesh_alone():
    from fmpy import read_model_description

    md = read_model_description(fmu())
    runs = [M.simulate(fmu(), md, M.start_values(md, {"A_rms": a}), 0.05) for a in (300, 500)]
    both = M.Run(h=runs[0].h, t0=0.0, forces=[r.forces[0] for r in runs],
                 impacts=[r.impacts[0] for r in runs], meshes=runs[0].meshes * 2, values={})
    modes = [Mode(1250.0, 0.02, (0.03, 0.01)), Mode(2900.0, 0.012, (0.02, 0.05))]
    snd = render(both, ModalTransfer(modes), M.SUBSAMPLE)
    np.testing.assert_allclose(np.sum(snd.stems, axis=0), snd.mix, rtol=0, atol=1e-15)
    for i, r in enumerate(runs):
        alone = [Mode(m.f, m.zeta, (m.gains[i],)) for m in modes]
        np.testing.assert_array_equal(render(r, ModalTransfer(alone), M.SUBSAMPLE).mix,
                                      snd.stems[i])
    assert abs(snd.shares().sum() - 1) < 1e-12


def _variable(name, causality, start=None):
    return SimpleNamespace(name=name, causality=causality, start=start, valueReference=0)


def test_the_meshes_come_from_the_model_description():
    gearbox = SimpleNamespace(modelVariables=[_variable("n_gears", "parameter", "3")] + [
        _variable(f"gear[{i}].{o}", "output") for i in range(1, 9)
        for o in ("F_contact", "impacts_Fplus", "impacts_Fminus")])
    ms = M.meshes(gearbox, {})
    assert [m.force.name for m in ms] == [f"gear[{i}].F_contact" for i in (1, 2, 3)]
    assert all(len(m.counters) == 2 for m in ms)
    assert len(M.meshes(gearbox, {"n_gears": 8})) == 8
    pair = SimpleNamespace(modelVariables=[_variable("F_contact", "output")])
    assert [m.force.name for m in M.meshes(pair, {})] == ["F_contact"]


def a_history(n, n0, h):
    """A force that rises smoothly from 0 to 200 N over n0 / 2 samples, rests there, then
    rattles: half-sine pulses of 1.4 ms on top of the 200 N from sample n0 on."""
    t = np.arange(n) * h
    F = 200.0 * np.sin(0.5 * np.pi * np.minimum(np.arange(n) / (n0 // 2), 1.0)) ** 2
    phase = (t - n0 * h) % 5e-3
    pulse = (t >= n0 * h) & (phase < 1.4e-3)
    F[pulse] += 30.0 * np.sin(np.pi * phase[pulse] / 1.4e-3)
    return F


def held_start_error(pressure, F, n0, every=1):
    """max |p| difference, relative to the peak, between the transfer applied to the whole
    history (the housing at rest at its start, under no force) and applied from sample n0 on
    alone (the force before n0 held at F[n0]); the pressure is at every `every`-th force
    sample."""
    whole = pressure(F)[n0 // every:]
    cut = pressure(F[n0:])
    return np.abs(cut - whole).max() / np.abs(whole).max()


def test_a_recording_started_under_load_is_the_whole_history_heard_from_then():
    # The smooth rise and the rest leave the housing silent at n0 (0.5 s): the history's
    # pressure from n0 on is what a recording starting there under the 200 N must give, not a
    # step response.
    h = 1.0 / (FS * M.SUBSAMPLE)
    n0 = int(0.5 / h)
    F = a_history(n0 + int(0.05 / h), n0, h)
    modal = ModalTransfer()
    err = held_start_error(lambda f: modal.pressure(f, 0, h), F, n0)
    assert err < 1e-6, f"held start differs by {err:.1e} of the peak"
    silent = modal.pressure(np.full(1000, 200.0), 0, h)
    assert np.abs(silent).max() < 1e-9, "a constant force sounds"
