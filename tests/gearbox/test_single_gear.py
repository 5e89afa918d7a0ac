"""One loose gear on an imposed input side (n_gears = 1, excitation 2) against GearRattle.fmu
driven by the same main-shaft motion (excitation 0): the same contact law (MODEL.md §2) on
the same motion, fed to both by fmpy's input interpolation, so the two agree to rounding.
The motion is the input side's of the coupled default box (B1), recorded from the reference
(gearbox_reference.recorded_motion)."""

import functools

import numpy as np
import pytest

from gearrattle import gearbox_fmu as GF
from gearrattle import gearbox_reference as R
from support.fmu import FMU_PATH as GEAR_FMU

T_END, DT = 0.3, 1e-4
# GearRattle's parameters under gear 1's names in the gearbox (rho = 1, T_oil = 40 °C: C as given).
SHARED = ("I_L", "r_L", "r_M", "G", "K_star", "alpha", "epsilon", "C_LM", "C", "B", "gap_start")


@functools.lru_cache(maxsize=None)
def _motion():
    t = np.arange(int(round(T_END / DT)) + 1) * DT
    return R.recorded_motion(t, R.params("B1"))


def _signal(names, m):
    sig = np.zeros(m["t"].size, dtype=[("time", np.float64)] + [(n, np.float64) for n in names])
    sig["time"] = m["t"]
    for n, k in zip(names, ("theta_I", "omega_I", "alpha_I")):
        sig[n] = m[k]
    return sig


def test_one_gear_on_recorded_input_side_matches_gear_rattle(gearbox_fmu):
    from fmpy import simulate_fmu

    if not GEAR_FMU.is_file():
        pytest.fail(f"{GEAR_FMU} does not exist: build it with `make fmu`, then rerun", pytrace=False)
    m = _motion()
    p = R.params("B1")
    g1 = {k: p[f"gear[1].{k}"] for k in SHARED}
    box = GF.simulate(gearbox_fmu, T_END, DT, inputs=_signal(("theta_I", "omega_I", "alpha_I"), m),
                      n_gears=1, excitation=2, **{f"gear[1].{k}": v for k, v in g1.items()})
    pair = simulate_fmu(str(GEAR_FMU), start_time=0.0, stop_time=T_END, step_size=DT, output_interval=DT,
                        start_values=g1,
                        input=_signal(("theta_M", "omega_M", "alpha_M"), m),
                        output=["xi", "xi_dot", "impacts_Fplus", "impacts_Fminus"])
    G = g1["G"]
    xi_box, xi_pair = box["gear[1].xi"], pair["xi"]
    err = np.max(np.abs(xi_box - xi_pair)) / G
    assert err <= 1e-12, f"max |xi_box - xi_pair| = {err:.2e} G"
    assert box["gear[1].impacts_Fplus"][-1] == pair["impacts_Fplus"][-1]
    assert box["gear[1].impacts_Fminus"][-1] == pair["impacts_Fminus"][-1]
    assert pair["impacts_Fplus"][-1] + pair["impacts_Fminus"][-1] > 10  # the gear rattles
