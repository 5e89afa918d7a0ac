"""gearrattle-study listen: the rattle of an FMU run as sound (docs/SOUND.md).

    gearrattle-study listen --fmu FMU [--set NAME=VALUE ...] [--transfer modal|MODES.toml|IR.wav]
                            --duration S [--from S] --out DIR [--compare --b-set NAME=VALUE ...]

DIR/rattle.wav (48 kHz, 32-bit float, calibrated in its comment), DIR/gear_<i>.wav per mesh when
the FMU has several, DIR/impacts.csv (the FMU's impact instants), DIR/spectrogram.png,
DIR/loudness.png and DIR/sound.txt (loudness, sharpness, A-weighted level, each mesh's share).
With --compare: the same for A (the --set values) in DIR/A and B (A's values changed by
--b-set) in DIR/B, DIR/ab.wav (A, a pause, B) and both metric sets side by side in DIR/sound.txt."""

import os
import sys

import numpy as np

PAUSE = 0.5  # silence between A and B in ab.wav [s]


def add_parser(sub):
    p = sub.add_parser("listen", help="the rattle as sound: WAV, spectrogram, loudness, "
                                      "sharpness (docs/SOUND.md)")
    p.add_argument("--fmu", default=os.path.join("target", "fmu", "GearRattle.fmu"),
                   help="the FMU (default target/fmu/GearRattle.fmu)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a start value (repeatable); excitation = 1 (the sine bench) unless set")
    p.add_argument("--transfer", default="modal",
                   help="modal (the default housing modes), MODES.toml ([[mode]] f, zeta, gain) "
                        "or IR.wav (impulse response in Pa/N at 48 kHz)")
    p.add_argument("--duration", type=float, required=True, help="simulated time [s]")
    p.add_argument("--from", dest="t_from", type=float, default=0.0, metavar="S",
                   help="heard from S seconds on (the start-up before it simulated in one "
                        "step and left out of the sound); default 0")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--compare", action="store_true",
                   help="also run B (the --set values changed by --b-set): DIR/ab.wav and both "
                        "metric sets side by side")
    p.add_argument("--b-set", action="append", default=[], metavar="NAME=VALUE",
                   help="a start value of B (repeatable, with --compare)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    return p


def _sets(texts, flag):
    from ..study.spec import parse_set

    return dict(parse_set(t, f"{flag} {t}") for t in texts)


def scenes(a, md):
    """[(label, start values)]: one scene, or A and B with --compare."""
    from .meshes import start_values

    sets = _sets(a.set, "--set")
    if a.b_set and not a.compare:
        raise ValueError("--b-set needs --compare (B is run only when comparing)")
    if not a.compare:
        return [("", start_values(md, sets))]
    if not a.b_set:
        raise ValueError("--compare needs B's values: add --b-set NAME=VALUE (e.g. --b-set "
                         "A_rms=500)")
    return [("A", start_values(md, sets)),
            ("B", start_values(md, {**sets, **_sets(a.b_set, "--b-set")}))]


def main(a):
    from fmpy.fmi1 import FMICallException

    from ..study.spec import StudyError

    try:
        lines, files = listen(a)
    except (ValueError, StudyError) as e:
        print(f"gearrattle-study listen: error: {e}", file=sys.stderr)
        return 2
    except (FMICallException, RuntimeError) as e:
        print(f"gearrattle-study listen: the FMU refused the run ({e}): check the --set values "
              f"against its model description", file=sys.stderr)
        return 1
    if not a.quiet:
        print("\n".join(lines))
        print("files:\n" + "\n".join(f"  {f}" for f in files))
    return 0


def listen(a):
    """Run the scenes and write the files; (report lines, files written)."""
    from fmpy import read_model_description

    from . import figures
    from .meshes import SUBSAMPLE, meshes, simulate
    from .metrics import FS, full_scale, metrics, read_wav, write_wav
    from .render import load_transfer, render

    if not os.path.isfile(a.fmu):
        raise ValueError(f"no FMU at {a.fmu}: build it first (make fmu) or give --fmu PATH")
    if not (a.duration > 0 and np.isfinite(a.duration)):
        raise ValueError(f"--duration {a.duration:g}: give a duration > 0 [s]")
    if not 0 <= a.t_from < a.duration:
        raise ValueError(f"--from {a.t_from:g}: give 0 <= --from < --duration [s]")
    md = read_model_description(a.fmu)
    transfer = load_transfer(a.transfer)
    todo = scenes(a, md)
    for _, values in todo:
        transfer.check_meshes(len(meshes(md, values)))
    os.makedirs(a.out, exist_ok=True)
    done = []
    for label, values in todo:
        run = simulate(a.fmu, md, values, a.duration, a.t_from)
        done.append((label, run, render(run, transfer, SUBSAMPLE)))
    scale = full_scale(*[s for _, _, snd in done for s in [snd.mix, *snd.stems]])
    files, heard = [], []
    for label, run, snd in done:
        where = os.path.join(a.out, label) if label else a.out
        os.makedirs(where, exist_ok=True)
        wav = write_wav(os.path.join(where, "rattle.wav"), snd.mix, scale)
        files.append(wav)
        if len(snd.stems) > 1:
            files += [write_wav(os.path.join(where, f"gear_{i + 1}.wav"), s, scale)
                      for i, s in enumerate(snd.stems)]
        files.append(_impacts_csv(os.path.join(where, "impacts.csv"), run))
        p, fs = read_wav(wav)
        m = metrics(p, fs)
        title = f"{os.path.basename(a.fmu)} {label} {_values_text(run.values)}".replace("  ", " ")
        files.append(figures.spectrogram(os.path.join(where, "spectrogram.png"), snd, run,
                                         title))
        heard.append((label, run, snd, m))
    if a.compare:
        pause = np.zeros(int(PAUSE * FS))
        files.append(write_wav(os.path.join(a.out, "ab.wav"),
                               np.concatenate([done[0][2].mix, pause, done[1][2].mix]), scale))
    files.append(figures.loudness(os.path.join(a.out, "loudness.png"),
                                  [(label or "rattle", m) for label, *_, m in heard],
                                  f"{os.path.basename(a.fmu)}: loudness against time"))
    lines = report(a, md, transfer, heard, scale)
    path = os.path.join(a.out, "sound.txt")
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    files += [path, _json(os.path.join(a.out, "sound.json"), a, transfer, heard, scale)]
    return lines, files


def _json(path, a, transfer, heard, scale):
    """sound.json: sound.txt's figures for scripts."""
    import json

    scenes = [{"label": label, "values": run.values, "N5": m.N5, "N_mean": m.N_mean,
               "sharpness": m.sharpness, "LAeq": m.LAeq,
               "impacts": [len(i) for i in run.impacts],
               "meshes": [mesh.force.name for mesh in run.meshes],
               "shares": [float(s) for s in snd.shares()],
               "cpu_s": {"simulation": run.cpu_s, "filtering": snd.cpu_s, "metrics": m.cpu_s}}
              for label, run, snd, m in heard]
    with open(path, "w") as fh:
        json.dump({"duration_s": a.duration, "from_s": a.t_from, "transfer": transfer.describe(),
                   "full_scale_Pa": scale, "scenes": scenes},
                  fh, indent=1, allow_nan=True)
    return path


def _values_text(values):
    return ", ".join(f"{k} = {v:g}" for k, v in values.items())


def _impacts_csv(path, run):
    with open(path, "w") as fh:
        fh.write("mesh,flank,t_lo,t_hi\n")
        for m, imp in zip(run.meshes, run.impacts):
            for lo, hi, flank in imp:
                name = {1: "F+", 2: "F-"}.get(int(flank), "onset")
                fh.write(f"{m.label},{name},{lo:.9f},{hi:.9f}\n")
    return path


def report(a, md, transfer, done, scale):
    """The lines of sound.txt: what was run and heard, the metrics (side by side for A/B)."""
    import mosqito

    from .meshes import SUBSAMPLE

    _, run0, _, _ = done[0]
    h_us = run0.h * 1e6
    heard = f"{a.duration - a.t_from:g} s from {a.t_from:g} s" if a.t_from else f"{a.duration:g} s"
    lines = [f"gearrattle-study listen: {a.fmu} (GUID {md.guid}), {heard}",
             f"  transfer: {transfer.describe()}",
             f"  meshes: {', '.join(m.force.name for m in run0.meshes)}, sampled every "
             f"{h_us:.3f} us (48 kHz x {SUBSAMPLE}); pressure exact for a force linear "
             f"between samples (docs/SOUND.md, Error)",
             f"  WAV: 48000 Hz, 32-bit float, sample 1.0 = {scale:g} Pa"]
    for label, run, snd, m in done:
        n = sum(len(i) for i in run.impacts)
        lines.append(f"  {label + ': ' if label else ''}{_values_text(run.values)}; "
                     f"{n} impacts; CPU: simulation {run.cpu_s:.2f} s ({run.steps} steps), "
                     f"filtering {snd.cpu_s:.2f} s, metrics {m.cpu_s:.2f} s "
                     f"(MoSQITo {mosqito.__version__})")
    rows = [("loudness N5 [sone]", "N5", "{:.3f}"), ("loudness mean [sone]", "N_mean", "{:.3f}"),
            ("sharpness [acum]", "sharpness", "{:.3f}"), ("LAeq [dB(A)]", "LAeq", "{:.2f}")]
    labels = [lab or "value" for lab, *_ in done]
    head = f"  {'metric':24s}" + "".join(f"{lab:>12s}" for lab in labels)
    if len(done) == 2:
        head += f"{'B - A':>12s}"
    lines += ["", head]
    for name, attr, fmt in rows:
        vals = [getattr(m, attr) for *_, m in done]
        line = f"  {name:24s}" + "".join(f"{fmt.format(v):>12s}" for v in vals)
        if len(done) == 2:
            line += f"{fmt.format(vals[1] - vals[0]):>12s}"
        lines.append(line)
    lines += ["", "  share of the sound energy (of the sum of the stems' energies):"]
    for label, run, snd, _ in done:
        lines.append(f"  {label + ': ' if label else ''}" + ", ".join(
            f"{mesh.label} {100 * s:.1f} %" for mesh, s in zip(run.meshes, snd.shares())))
    return lines
