"""The sound's cost and error against the force's sampling (make bench-sound): CPU times of the
simulation alone (one fmi2DoStep), of the simulation stepped on the sound's grid, of the
filtering, of writing the WAV and of the psychoacoustic metrics (MoSQITo), for a scene; and the
pressure's error at each subsample against a 32-times-finer grid. With --cost, only the WAV's
cost against the simulation alone, side by side, and the metrics' (issue #31's 3x target).

Run by scripts/bench_sound.py."""

import ctypes
import os
import tempfile
import time

import numpy as np

REFERENCE = 32  # subsample of the reference pressure
SUBSAMPLES = (1, 2, 4, 8)


def _cpu(f, *args, repeat=3):
    """(smallest CPU time of `repeat` calls, the last result): the least disturbed run on a
    shared machine."""
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.process_time()
        out = f(*args)
        best = min(best, time.process_time() - t0)
    return best, out


def _initialised(unzipdir, md, values):
    from fmpy import instantiate_fmu

    from gearrattle.sound.meshes import _set

    inst = instantiate_fmu(unzipdir, md, fmi_type="CoSimulation")
    inst.setupExperiment(startTime=0.0)
    _set(inst, md, values)
    inst.enterInitializationMode()
    inst.exitInitializationMode()
    return inst


def _free(inst):
    inst.terminate()
    inst.freeInstance()


def alone(unzipdir, md, values, duration):
    """CPU of one fmi2DoStep to duration: the simulation as the studies run it."""
    inst = _initialised(unzipdir, md, values)
    t0 = time.process_time()
    inst.doStep(0.0, duration)
    cpu = time.process_time() - t0
    _free(inst)
    return cpu


def reads_alone(unzipdir, md, values, n):
    """CPU of the reads of n steps of meshes.record (the forces at every step, the counters at
    every WAV sample) without the steps: what calling the FMU's getters from Python costs."""
    from gearrattle.calls import raw_calls
    from gearrattle.sound.meshes import SUBSAMPLE, meshes

    ms = meshes(md, values)
    inst = _initialised(unzipdir, md, values)
    vr_f = (ctypes.c_uint * len(ms))(*[m.force.valueReference for m in ms])
    vr_c = (ctypes.c_uint * (2 * len(ms)))(*[c.valueReference for m in ms for c in m.counters])
    F, C = np.zeros((n, len(ms))), np.zeros(len(vr_c), dtype=np.int32)
    _, get_real, get_int = raw_calls(inst)
    vf, vc, comp = ctypes.addressof(vr_f), ctypes.addressof(vr_c), inst.component
    f_at, c_at = F.ctypes.data, C.ctypes.data
    t0 = time.process_time()
    for k in range(n):
        get_real(comp, vf, len(ms), f_at + 8 * len(ms) * k)
        if k % SUBSAMPLE == 0:
            get_int(comp, vc, len(vr_c), c_at)
    cpu = time.process_time() - t0
    _free(inst)
    return cpu


def sampled_alone(unzipdir, md, values, duration, read):
    """CPU of meshes.record's calls of the FMU's sampling entry over duration (CHUNK each),
    reading the forces at every point if `read`, else none: the FMU's part of the stepping.
    None where the FMU does not export the entry."""
    from gearrattle.calls import sampled_call
    from gearrattle.sound.meshes import CHUNK, FS, SUBSAMPLE, meshes

    ms = meshes(md, values) if read else []
    inst = _initialised(unzipdir, md, values)
    call = sampled_call(inst)
    if call is None:
        _free(inst)
        return None
    h = 1.0 / (FS * SUBSAMPLE)
    n, every = int(round(duration / h)), int(round(CHUNK / h))
    vr = (ctypes.c_uint * max(1, len(ms)))(*[m.force.valueReference for m in ms])
    F = np.zeros((every, len(ms)))
    comp, vr_at, f_at = inst.component, ctypes.addressof(vr), F.ctypes.data
    t0 = time.process_time()
    for k in range(0, n, every):
        call(comp, k * h, h, min(every, n - k), vr_at, len(ms), f_at)
    cpu = time.process_time() - t0
    _free(inst)
    return cpu


def cost(fmu, unzip, md, values, duration):
    """Print the CPU of the simulation alone, of the WAV (the forces sampled, filtered, the mix
    and stems written) and of the metrics, best of 3 for the first two."""
    from gearrattle.calls import SAMPLED
    from gearrattle.sound.meshes import CHUNK, SUBSAMPLE, simulate
    from gearrattle.sound.metrics import full_scale, metrics, write_wav
    from gearrattle.sound.modal import ModalTransfer
    from gearrattle.sound.render import render

    def wav():
        run = simulate(unzip, md, values, duration)
        snd = render(run, ModalTransfer(), SUBSAMPLE)
        scale = full_scale(snd.mix, *snd.stems)
        with tempfile.TemporaryDirectory() as d:
            for i, p in enumerate([snd.mix, *snd.stems] if len(snd.stems) > 1 else [snd.mix]):
                write_wav(os.path.join(d, f"{i}.wav"), p, scale)
        return run, snd

    t_alone = min(alone(unzip, md, values, duration) for _ in range(3))
    t_wav, (run, snd) = _cpu(wav)
    t_met, m = _cpu(metrics, snd.mix, repeat=1)
    print(f"cost of the sound of {fmu} ({', '.join(f'{k} = {v:g}' for k, v in values.items())}), "
          f"{duration:g} s simulated, {len(run.forces)} meshes, default modal housing; CPU s")
    print(f"  {'simulation alone':>16s} {'WAV':>8s} {'ratio':>7s}   {'of the WAV: stepping':>20s} "
          f"{'filtering':>9s}   {'metrics':>8s}")
    print(f"  {t_alone:16.3f} {t_wav:8.3f} {t_wav / t_alone:6.1f}x   {run.cpu_s:20.3f} "
          f"{snd.cpu_s:9.3f}   {t_met:8.3f}")
    steps = min(sampled_alone(unzip, md, values, duration, False) or 0 for _ in range(3))
    if steps:
        read = min(sampled_alone(unzip, md, values, duration, True) for _ in range(3))
        print(f"  of the stepping, inside the FMU ({SAMPLED}, {CHUNK * 1e3:g} ms a call): the "
              f"steps alone {steps:.3f}, with the forces read at each point {read:.3f}")


def report(fmu, duration, sets, cost_only=False):
    """Prints the sound's cost and error against the force's sampling for the FMU's scene with
    the `sets` (NAME=VALUE texts), `duration` seconds simulated; with `cost_only`, only the
    WAV's cost against the simulation alone, and the metrics'."""
    import mosqito
    from fmpy import extract, read_model_description

    from gearrattle.study.spec import parse_set
    from gearrattle.calls import SAMPLED
    from gearrattle.sound.meshes import SUBSAMPLE, simulate, start_values
    from gearrattle.sound.metrics import full_scale, metrics, write_wav
    from gearrattle.sound.modal import ModalTransfer
    from gearrattle.sound.render import render

    md = read_model_description(fmu)
    unzip = extract(fmu)
    values = start_values(md, dict(parse_set(t, f"--set {t}") for t in sets))
    if cost_only:
        return cost(fmu, unzip, md, values, duration)
    transfer = ModalTransfer()
    t_alone = min(alone(unzip, md, values, duration) for _ in range(3))
    ref = simulate(unzip, md, values, duration, subsample=REFERENCE)
    p_ref = render(ref, transfer, REFERENCE).mix
    print(f"sound of {fmu} ({', '.join(f'{k} = {v:g}' for k, v in values.items())}), "
          f"{duration:g} s simulated, default modal housing; CPU seconds, best of 3")
    print(f"  simulation alone (one fmi2DoStep): {t_alone:.4f} s")
    print(f"  {'subsample':>9s} {'step [us]':>9s} {'simulation':>10s} {'filtering':>9s} "
          f"{'max error':>9s} {'RMS error':>9s}   (error of p against subsample {REFERENCE})")
    for sub in SUBSAMPLES:
        t_sim, run = _cpu(simulate, unzip, md, values, duration, 0.0, sub)
        t_filt, snd = _cpu(render, run, transfer, sub)
        e = snd.mix - p_ref
        mark = "  <- used" if sub == SUBSAMPLE else ""
        print(f"  {sub:9d} {run.h * 1e6:9.3f} {t_sim:10.3f} {t_filt:9.3f} "
              f"{np.abs(e).max() / np.abs(p_ref).max():9.1e} "
              f"{np.sqrt(np.mean(e ** 2) / np.mean(p_ref ** 2)):9.1e}{mark}")
        if sub == SUBSAMPLE:
            mix, steps, t_grid = snd.mix, run.steps, t_sim
    t_steps = min(sampled_alone(unzip, md, values, duration, False) or 0 for _ in range(3))
    if t_steps:
        t_read = min(sampled_alone(unzip, md, values, duration, True) for _ in range(3))
        print(f"  of the simulation at subsample {SUBSAMPLE} ({t_grid:.3f} s, {steps} steps): "
              f"inside the FMU ({SAMPLED}) the steps alone {t_steps:.3f} s, with the forces "
              f"read at each {t_read:.3f} s")
    else:
        t_reads = min(reads_alone(unzip, md, values, steps) for _ in range(3))
        print(f"  of the simulation at subsample {SUBSAMPLE} ({t_grid:.3f} s, {steps} steps): "
              f"the reads from Python {t_reads:.3f} s; the rest, fmi2DoStep from Python, "
              f"{(t_grid - t_reads) / steps * 1e6:.2f} us a step")
    with tempfile.TemporaryDirectory() as d:
        t_wav, _ = _cpu(write_wav, os.path.join(d, "x.wav"), mix, full_scale(mix))
    t_met, m = _cpu(metrics, mix)
    print(f"  writing the WAV: {t_wav:.3f} s; metrics (MoSQITo {mosqito.__version__} loudness "
          f"and sharpness, LAeq): {t_met:.3f} s")
    print(f"  N5 {m.N5:.2f} sone, N_mean {m.N_mean:.2f} sone, sharpness {m.sharpness:.2f} acum, "
          f"LAeq {m.LAeq:.1f} dB(A)")

