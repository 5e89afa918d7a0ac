"""One loose gear on an imposed input side (n_gears = 1, excitation 2) against GearRattle.fmu
driven by the same main-shaft motion (excitation 0): the same contact law (docs/MODEL.md §2) on
the same motion, fed to both alike by fmpy's input interpolation. The motion is the input
side's of the coupled default box (B1), recorded from the reference
(gearbox_reference.recorded_motion).

Until the first contact the two agree to rounding (the same feed and the same free flight).
From it on, the box's multi-edge integrator and GearRattle's take different steps through the
contacts, so they differ by the error each tolerates: at rtol 1e-8, 1e-10, 1e-12 the largest
difference over 0.3 s is 1.6e-6, 2.3e-8, 1.6e-10 G, scaling with the tolerance."""

import functools

import numpy as np

from gearrattle import gearbox_fmu as GF
from gearrattle import gearbox_reference as R
from support.fmu import BUILD_FMU, FMU_PATH, require

T_END, DT, TOL = 0.3, 1e-4, 1e-12
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

    gear_fmu = require(FMU_PATH, BUILD_FMU)
    m = _motion()
    p = R.params("B1")
    g1 = {k: p[f"gear[1].{k}"] for k in SHARED}
    box = GF.simulate(gearbox_fmu, T_END, DT, tol=TOL, inputs=_signal(("theta_I", "omega_I", "alpha_I"), m),
                      n_gears=1, excitation=2, **{f"gear[1].{k}": v for k, v in g1.items()})
    pair = simulate_fmu(gear_fmu, start_time=0.0, stop_time=T_END, step_size=DT, output_interval=DT,
                        relative_tolerance=TOL, start_values=g1,
                        input=_signal(("theta_M", "omega_M", "alpha_M"), m),
                        output=["xi", "xi_dot", "impacts_Fplus", "impacts_Fminus"])
    G = g1["G"]
    xi_box, xi_pair = box["gear[1].xi"], pair["xi"]
    first = np.argmax(pair["impacts_Fplus"] + pair["impacts_Fminus"] > 0)
    err = np.abs(xi_box - xi_pair) / G
    assert np.max(err[:first]) <= 1e-13, f"before the first contact: {np.max(err[:first]):.2e} G"
    assert np.max(err) <= 1e-9, f"max |xi_box - xi_pair| = {np.max(err):.2e} G"
    assert box["gear[1].impacts_Fplus"][-1] == pair["impacts_Fplus"][-1]
    assert box["gear[1].impacts_Fminus"][-1] == pair["impacts_Fminus"][-1]
    assert pair["impacts_Fplus"][-1] + pair["impacts_Fminus"][-1] > 10  # the gear rattles
