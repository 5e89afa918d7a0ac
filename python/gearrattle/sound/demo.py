"""The sound part of `make demo` (docs/SOUND.md): scene S1 and the default gearbox idling with
warm and cold oil (docs/GEARBOX.md §9's 40 °C and −10 °C) through the default housing, run by
`gearrattle-study listen`, and their metrics side by side. The gearbox's two runs are one A/B
pair, so that their files share one calibration and the cold box sounds as much quieter as it
is."""

import json
import os
import shutil

WARM, COLD = 40.0, -10.0  # oil temperatures [°C] of the gearbox demo (docs/GEARBOX.md §9)
# Each gearbox run is heard from the statistics window's start (docs/GEARBOX.md §9: the start-up
# strikes every gear, even cold) for one second [s].
BOX_FROM, BOX_HEARD = 0.5, 1.0


def _listen(args, where):
    """Run `gearrattle-study listen` with args into where; the scenes of its sound.json."""
    from ..study.cli import main as study

    if study(["listen", *args, "--out", where, "--quiet"]):
        raise RuntimeError(f"gearrattle-study listen {' '.join(args)} failed")
    with open(os.path.join(where, "sound.json")) as fh:
        return json.load(fh)["scenes"]


def s1(fmu, out, duration):
    """S1 into out/S1_sound/ and out/S1_rattle.wav; (its row of the table, its spectrogram)."""
    where = os.path.join(out, "S1_sound")
    scene, = _listen(["--fmu", fmu, "--duration", f"{duration:g}"], where)
    wav = shutil.copy(os.path.join(where, "rattle.wav"), os.path.join(out, "S1_rattle.wav"))
    return (f"S1 ({duration:g} s)", scene, wav), os.path.join(where, "spectrogram.png")


def gearbox(box_fmu, out, t_from=BOX_FROM, heard=BOX_HEARD):
    """The gearbox at idle, warm (A) and cold (B), into out/gearbox_sound/ (each run's mix and
    per-gear stems gear_<i>.wav in A/ and B/, ab.wav warm then cold) and
    out/gearbox_{warm,cold}_rattle.wav; (their rows of the table, the warm spectrogram)."""
    where = os.path.join(out, "gearbox_sound")
    scenes = _listen(["--fmu", box_fmu, "--duration", f"{t_from + heard:g}",
                      "--from", f"{t_from:g}", "--set", f"T_oil={WARM:g}",
                      "--compare", "--b-set", f"T_oil={COLD:g}"], where)
    rows = []
    for (name, T), label, scene in zip((("warm", WARM), ("cold", COLD)), "AB", scenes):
        wav = shutil.copy(os.path.join(where, label, "rattle.wav"),
                          os.path.join(out, f"gearbox_{name}_rattle.wav"))
        rows.append((f"gearbox {T:g} °C ({heard:g} s from {t_from:g} s)", scene, wav))
    return rows, os.path.join(where, "A", "spectrogram.png")


def print_table(rows):
    """The metrics of the demo's sounds side by side, each with its file."""
    print("\nThe rattle heard through the default housing (docs/SOUND.md; absolute levels only "
          "as good as the housing's illustrative gains):")
    w = max(len(r[0]) for r in rows)
    print(f"  {'':{w}}  {'impacts':>7}  {'N5 [sone]':>9}  {'N_mean':>7}  {'sharpness':>9}  "
          f"{'LAeq':>8}  file")
    for name, s, wav in rows:
        sharp = "-" if s["sharpness"] != s["sharpness"] else f"{s['sharpness']:.2f}"
        print(f"  {name:{w}}  {sum(s['impacts']):7d}  {s['N5']:9.2f}  {s['N_mean']:7.2f}  "
              f"{sharp:>9}  {s['LAeq']:8.1f}  {wav}")
    print("  (N5, N_mean: ISO 532-1 loudness [sone]; sharpness DIN 45692 [acum], - in silence; "
          "LAeq [dB(A)])")
