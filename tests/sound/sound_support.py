"""Helpers of the sound tests (imported by name; a conftest.py here would shadow tests/python's):
the FMU (a missing build FAILS, never skips), `gearrattle-study listen` run as a user runs it,
and the FMU's impact instants read independently of the sound package (fmpy's simulate_fmu)."""

import contextlib
import io
import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
FMU = ROOT / "target" / "fmu" / "GearRattle.fmu"
GEARBOX_FMU = ROOT / "target" / "fmu" / "GearboxRattle.fmu"
STUDY = pathlib.Path(sys.executable).parent / "gearrattle-study"
FS = 48000


def fmu(path=FMU):
    if not path.is_file():
        pytest.fail(f"{path} does not exist: build it first with `make fmu`, then rerun the "
                    f"tests", pytrace=False)
    return str(path)


def listen(*args, check=True, process=False, fmu_path=FMU):
    """Run `gearrattle-study listen` with these arguments: (exit code, stderr). In this process
    (the command's main with these arguments), or as a user runs it (process=True)."""
    argv = ["listen", "--fmu", fmu(fmu_path), *map(str, args), "--quiet"]
    if process:
        p = subprocess.run([str(STUDY), *argv], capture_output=True, text=True, timeout=120)
        code, err = p.returncode, p.stderr
    else:
        from gearrattle.study.cli import main

        buf = io.StringIO()
        with contextlib.redirect_stderr(buf):
            code = main(argv)
        err = buf.getvalue()
    if check and code != 0:
        raise AssertionError(f"listen {' '.join(map(str, args))} failed ({code}):\n{err[-3000:]}")
    return code, err


def sound_json(out):
    return json.loads((pathlib.Path(out) / "sound.json").read_text())


def impact_samples(duration, start_values, subsample=4, fmu_path=FMU, prefixes=("",)):
    """Per prefix (a mesh: "" or "gear[i]."), the first WAV sample after each of its impacts:
    the counters read by simulate_fmu every 1/(FS subsample) s give each impact's interval,
    within one WAV sample interval. One array for the single prefix "", else a list."""
    from fmpy import simulate_fmu

    h = 1.0 / (FS * subsample)
    names = [p + c for p in prefixes for c in ("impacts_Fplus", "impacts_Fminus")]
    r = simulate_fmu(fmu(fmu_path), start_values={"excitation": 1, **start_values},
                     stop_time=duration, output_interval=h, output=names)
    out = []
    for p in prefixes:
        n = r[p + "impacts_Fplus"].astype(int) + r[p + "impacts_Fminus"].astype(int)
        k = np.nonzero(np.diff(n) > 0)[0] + 1
        assert np.all(np.diff(n) <= 1), f"two impacts of {p or 'the mesh'} in one output interval"
        out.append((k + subsample - 1) // subsample)  # the WAV sample at or after its end
    return out[0] if prefixes == ("",) else out
