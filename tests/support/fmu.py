"""The built FMU and its contract as the FMU tests read them, and the main-shaft input signal
that drives the FMU in input mode."""

import pathlib
import tomllib

import numpy as np

from gearrattle import reference as R

ROOT = pathlib.Path(__file__).resolve().parents[2]
FMU_PATH = ROOT / "target" / "fmu" / "GearRattle.fmu"
CONTRACT_PATH = ROOT / "modelDescription" / "GearRattle.toml"


def contract_outputs() -> list:
    """Every output of the contract, in its order: the FMU runs record them all, so an output
    added to modelDescription/GearRattle.toml is recorded without an edit here."""
    with open(CONTRACT_PATH, "rb") as f:
        return [v["name"] for v in tomllib.load(f)["variable"] if v["causality"] == "output"]


OUTPUTS = contract_outputs()


def main_shaft_input(scene: str, t_end: float, dt: float = 1e-4, fields=("theta_M", "omega_M", "alpha_M"), **overrides):
    """Structured input array for fmpy: the analytic sine motion of the main shaft (§5)."""
    p = R.params(scene, **overrides)
    n = int(round(t_end / dt))
    t = np.arange(n + 1) * dt
    th, om, al = R.main_shaft(t, p)
    values = {"theta_M": th, "omega_M": om, "alpha_M": al}
    sig = np.zeros(t.size, dtype=[("time", np.float64)] + [(f, np.float64) for f in fields])
    sig["time"] = t
    for f in fields:
        sig[f] = values[f]
    return sig


FMU3_PATH = ROOT / "target" / "fmu" / "fmi3" / "GearRattle.fmu"
