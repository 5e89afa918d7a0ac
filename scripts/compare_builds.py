"""Every output of two builds of GearRattle.fmu and GearboxRattle.fmu every 1e-4 s, compared
bit for bit through fmpy: S1-S3 (sine, co-simulation and Model Exchange), the inputs and torque
modes, Radau IIA, the gearbox on its engine (co-simulation and Model Exchange) and on an
imposed input side, each with stats_from 0 and 0.2. For a change that must leave the
trajectories as they are (docs/DECISIONS.md, D57).

    PYTHONPATH=python python scripts/compare_builds.py BEFORE_DIR AFTER_DIR [NAME_FILTER]

BEFORE_DIR and AFTER_DIR each hold GearRattle.fmu and GearboxRattle.fmu (target/fmu/ of two
checkouts). Prints one line per run and 'N passed, N failed'; exits 1 if any run differs."""

import math
import pathlib
import sys

import numpy as np
from fmpy import simulate_fmu

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from gearrattle import reference as R  # noqa: E402
from support.fmu import main_shaft_input  # noqa: E402

BASE, FIX = sys.argv[1], sys.argv[2]
DT = 1e-4


def sim(path, t_end, fmi_type="CoSimulation", inputs=None, **start):
    return simulate_fmu(path, stop_time=t_end, step_size=DT if fmi_type == "CoSimulation" else None,
                        output_interval=DT, fmi_type=fmi_type, start_values=start, input=inputs)


def bits(column):
    return column.view(np.uint64) if column.dtype == np.float64 else column


def same(a, b):
    """Whether two results are the same to the bit, and the first columns that are not."""
    if a.dtype.names != b.dtype.names or a.shape != b.shape:
        return False, "shape"
    bad = [n for n in a.dtype.names if not np.array_equal(bits(a[n]), bits(b[n]))]
    return not bad, bad[:5]


def torque_input(t_end):
    """An S1-like torque on GearRattle's main shaft (I_M times the bench's acceleration)."""
    t = np.arange(int(round(t_end / DT)) + 1) * DT
    amp = 0.008 * math.sqrt(2) * 300.0
    sig = np.zeros(t.size, dtype=[("time", np.float64), ("tau_in", np.float64)])
    sig["time"], sig["tau_in"] = t, amp * np.sin(2 * math.pi * 30.0 * t)
    return sig


def input_side(t_end):
    """The gearbox's input side at 84 rad/s, oscillating at 26.7 Hz with 600 rad/s²."""
    t = np.arange(int(round(t_end / DT)) + 1) * DT
    w = 2 * math.pi * 26.7
    sig = np.zeros(t.size, dtype=[("time", np.float64), ("theta_I", np.float64), ("omega_I", np.float64), ("alpha_I", np.float64)])
    sig["time"] = t
    sig["theta_I"] = 84.0 * t + 600.0 / w**2 * np.sin(w * t)
    sig["omega_I"] = 84.0 + 600.0 / w * np.cos(w * t)
    sig["alpha_I"] = -600.0 * np.sin(w * t)
    return sig


# (name, model, t_end, interface, inputs, start values)
cases = []
for scene in ("S1", "S2", "S3"):
    sc = R.SCENES[scene]
    for sf in (0.0, 0.2):
        cases.append((f"GR {scene} sine CS sf={sf}", "GearRattle", 1.0, "CoSimulation", None,
                      dict(excitation=1, stats_from=sf, **sc)))
        cases.append((f"GR {scene} sine ME sf={sf}", "GearRattle", 0.3, "ModelExchange", None,
                      dict(excitation=1, stats_from=sf, **sc)))
for sf in (0.0, 0.2):
    inp = main_shaft_input("S1", 1.0)
    cases.append((f"GR S1 inputs CS sf={sf}", "GearRattle", 1.0, "CoSimulation", inp, dict(excitation=0, stats_from=sf)))
    cases.append((f"GR S1 inputs ME sf={sf}", "GearRattle", 0.3, "ModelExchange", main_shaft_input("S1", 0.3), dict(excitation=0, stats_from=sf)))
    cases.append((f"GR torque CS sf={sf}", "GearRattle", 1.0, "CoSimulation", torque_input(1.0),
                   dict(excitation=2, stats_from=sf, omega_M=-math.sqrt(2) * 300.0 / (2 * math.pi * 30.0))))
    cases.append((f"GR S1 sine Radau CS sf={sf}", "GearRattle", 0.5, "CoSimulation", None, dict(excitation=1, solver=2, stats_from=sf)))
for sf in (0.0, 0.2):
    cases.append((f"GB exc1 CS sf={sf}", "GearboxRattle", 1.0, "CoSimulation", None, dict(excitation=1, stats_from=sf)))
    cases.append((f"GB exc2 CS sf={sf}", "GearboxRattle", 1.0, "CoSimulation", input_side(1.0), dict(excitation=2, stats_from=sf)))
    cases.append((f"GB exc1 ME sf={sf}", "GearboxRattle", 0.2, "ModelExchange", None, dict(excitation=1, stats_from=sf)))
cases.append((f"GB exc1 CS default", "GearboxRattle", 1.0, "CoSimulation", None, dict(excitation=1)))
cases.append((f"GB exc2 CS default", "GearboxRattle", 1.0, "CoSimulation", input_side(1.0), dict(excitation=2)))

which = sys.argv[3] if len(sys.argv) > 3 else ""
fails = runs = 0
for name, model, t_end, fmi_type, inp, start in cases:
    if which not in name:
        continue
    a = sim(f"{BASE}/{model}.fmu", t_end, fmi_type, inp, **start)
    b = sim(f"{FIX}/{model}.fmu", t_end, fmi_type, inp, **start)
    ok, bad = same(a, b)
    runs += 1
    fails += not ok
    print(f"{'same' if ok else 'DIFFERENT'}: {name}: {len(a)} rows x {len(a.dtype.names)} columns {bad if not ok else ''}", flush=True)
print(f"{runs - fails} passed, {fails} failed")
sys.exit(1 if fails else 0)
