"""The drivetrain partner on its own: the packaged FMU, its idle behaviour, its FMU state."""

import shutil
import subprocess
import zipfile

import numpy as np
import pytest

from gearrattle import monolithic as M

FW = M.FLYWHEEL


def test_validates(fmus):
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu

    _, flywheel = fmus
    assert validate_fmu(str(flywheel)) == []
    md = read_model_description(str(flywheel))
    cs = md.coSimulation
    assert cs.modelIdentifier == "Flywheel"
    assert cs.canInterpolateInputs and cs.maxOutputDerivativeOrder == 1
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate
    by_name = {v.name: v for v in md.modelVariables}
    # the connection names of GearRattle's main-shaft inputs and its torque output
    for name in ("theta_M", "omega_M", "alpha_M"):
        assert by_name[name].causality == "output"
    assert by_name["tau_M"].causality == "input"
    # the monolithic reference uses the FMU's defaults
    for name, value in FW.items():
        assert float(by_name[name].start) == pytest.approx(value, rel=1e-15), name
    # alpha_M is the only output with direct feedthrough (from tau_M)
    index = {v.name: i + 1 for i, v in enumerate(md.modelVariables)}
    deps = {u.variable.name: [d.name for d in u.dependencies] for u in md.outputs}
    assert deps["alpha_M"] == ["tau_M"] and deps["theta_M"] == [] and deps["omega_M"] == []
    assert index["tau_M"] > 0


def test_exports_only_fmi2_functions(fmus, tmp_path):
    _, flywheel = fmus
    nm = shutil.which("nm")
    if nm is None:
        pytest.skip("nm (binutils) not installed")
    with zipfile.ZipFile(flywheel) as z:
        so = tmp_path / "Flywheel.so"
        so.write_bytes(z.read("binaries/linux64/Flywheel.so"))
    out = subprocess.run([nm, "-D", "--defined-only", str(so)], capture_output=True, text=True, check=True).stdout
    names = [line.split()[-1] for line in out.splitlines() if line.strip()]
    # FMI 2.0's Co-Simulation functions and fmi2-shell's sampling entry (docs/SOUND.md)
    assert len(names) == 35 and all(n.startswith("fmi2") or n == "gearRattleDoStepSampled"
                                    for n in names), names


def _run_alone(fmus, t_end=0.5, h=1e-4):
    from fmpy import simulate_fmu

    _, flywheel = fmus
    return simulate_fmu(str(flywheel), stop_time=t_end, step_size=h, output_interval=h, output=["omega_M", "alpha_M", "omega_E"])


def test_idle_acyclism(fmus):
    """Without the gear pair (tau_M = 0): an idle near 800 rpm with a firing frequency of
    26.7 Hz; the engine speed swings by about +-30 rpm and the main shaft, above the damper's
    22 Hz resonance, by more; its angular acceleration reaches ~900 rad/s^2, three times the
    ~260 rad/s^2 from which the loose gear leaves its flank (README of the partner)."""
    r = _run_alone(fmus)
    late = r["time"] >= 0.3
    rpm = 30.0 / np.pi
    om_e, om_m, al_m = r["omega_E"][late], r["omega_M"][late], r["alpha_M"][late]
    assert 790 < om_e.mean() * rpm < 830
    assert 20 < (om_e.max() - om_e.min()) / 2 * rpm < 60
    assert 40 < (om_m.max() - om_m.min()) / 2 * rpm < 80
    assert 700 < np.abs(al_m).max() < 1200
    # the dominant frequency of alpha_M is the 2nd engine order
    spectrum = np.abs(np.fft.rfft(al_m - al_m.mean()))
    f = np.fft.rfftfreq(al_m.size, 1e-4)
    assert f[np.argmax(spectrum)] == pytest.approx(2 * om_e.mean() / (2 * np.pi), abs=6.0)


def test_state_rollback_and_serialization(fmus):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    _, flywheel = fmus
    md = read_model_description(str(flywheel))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzip = extract(str(flywheel))
    slaves = []
    for name in ("a", "b"):
        s = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier="Flywheel", instanceName=name)
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
        slaves.append(s)
    a, b = slaves
    try:
        outs = [vr[n] for n in ("theta_M", "omega_M", "alpha_M", "omega_E")]
        a.setReal([vr["tau_M"]], [-0.8])
        a.setRealInputDerivatives([vr["tau_M"]], [1], [25.0])
        a.doStep(0.0, 1e-3)
        state = a.getFMUstate()
        blob = a.serializeFMUstate(state)
        a.doStep(1e-3, 2e-3)
        first = a.getReal(outs)
        a.setFMUstate(state)
        a.doStep(1e-3, 2e-3)
        assert a.getReal(outs) == first  # bit-identical re-step
        restored = b.deSerializeFMUstate(blob)
        b.setFMUstate(restored)
        b.doStep(1e-3, 2e-3)
        assert b.getReal(outs) == first  # and in another instance
        corrupt = bytearray(blob)
        corrupt[30] ^= 0x40
        with pytest.raises(Exception):
            b.deSerializeFMUstate(bytes(corrupt))
        a.freeFMUstate(state)
        b.freeFMUstate(restored)
    finally:
        for s in slaves:
            s.terminate()
            s.freeInstance()
