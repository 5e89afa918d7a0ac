"""The loose gears on an imposed input side (excitation 2) against GearRattle.fmu
driven by the same main-shaft motion (excitation 0): the same contact law (docs/MODEL.md §2) on
the same motion, fed to both alike by fmpy's input interpolation. The motion is the input
side's of the coupled default box (B1), recorded from the reference
(gearbox_reference.recorded_motion).

On an imposed input side the box steps each gear as GearRattle steps its one gear on the
input side's motion times rho_i (docs/GEARBOX.md §11), so the two agree to rounding at the
default tolerance: 1e-12 G over 0.3 s and some 30 impacts per gear, contacts included, and the
same window statistics; with three gears and ratios other than 1, each gear against its own
GearRattle.fmu."""

import functools

import numpy as np
import pytest

from gearrattle import gearbox_fmu as GF
from gearrattle import gearbox_reference as R
from support.fmu import BUILD_FMU, FMU_PATH, require

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


# The window's figures both FMUs give, per gear (docs/METRICS.md), over [STATS_FROM, T_END].
STATS = ("stat_impacts_Fplus", "stat_impacts_Fminus", "stat_v_mean_Fplus", "stat_v_max_Fplus", "stat_rattle_power",
         "stat_a_rms", "stat_a_peak", "stat_F_std", "stat_contact_fraction", "stat_P_lubricant")
STATS_FROM = 0.1


def _gear_rattle_run(gear_fmu, g, rho, m):
    """GearRattle.fmu with gear g's pair on the main-shaft motion rho times the input side's."""
    from fmpy import simulate_fmu

    sig = _signal(("theta_M", "omega_M", "alpha_M"), m)
    for n in ("theta_M", "omega_M", "alpha_M"):
        sig[n] = rho * sig[n]
    return simulate_fmu(gear_fmu, start_time=0.0, stop_time=T_END, step_size=DT, output_interval=DT,
                        start_values=dict(g, omega_S=0.0, stats_from=STATS_FROM), input=sig,
                        output=["xi", "xi_dot", "impacts_Fplus", "impacts_Fminus", *STATS])


@pytest.mark.parametrize("rhos", [(1.0,), (1.0, 0.62, 1.45)], ids=["one_gear", "three_gears"])
def test_gears_on_recorded_input_side_match_gear_rattle(gearbox_fmu, rhos):
    """Each gear of the box (gears 1, 2, 3 of B1 with the ratios `rhos`) against GearRattle.fmu
    on rho_i times the input side's motion: 1e-12 G at the default tolerance, the same impacts,
    and the window's figures over [STATS_FROM, T_END] to 1e-12."""
    gear_fmu = require(FMU_PATH, BUILD_FMU)
    m = _motion()
    p = R.params("B1")
    gears = [{k: p[f"gear[{i}].{k}"] for k in SHARED} for i in range(1, len(rhos) + 1)]
    start = {f"gear[{i}].{k}": v for i, g in enumerate(gears, start=1) for k, v in g.items()}
    start.update({f"gear[{i}].rho": rho for i, rho in enumerate(rhos, start=1)})
    box = GF.simulate(gearbox_fmu, T_END, DT, inputs=_signal(("theta_I", "omega_I", "alpha_I"), m),
                      gear_fields=GF.GEAR_OUTPUTS + STATS, n_gears=len(rhos), excitation=2,
                      stats_from=STATS_FROM, **start)
    for i, (g, rho) in enumerate(zip(gears, rhos), start=1):
        pair = _gear_rattle_run(gear_fmu, g, rho, m)
        err = np.abs(box[f"gear[{i}].xi"] - pair["xi"]) / g["G"]
        assert np.max(err) <= 1e-12, f"gear {i}: max |xi_box - xi_pair| = {np.max(err):.2e} G"
        for flank in ("impacts_Fplus", "impacts_Fminus"):
            assert box[f"gear[{i}].{flank}"][-1] == pair[flank][-1], f"gear {i} {flank}"
        assert pair["impacts_Fplus"][-1] + pair["impacts_Fminus"][-1] > 10, f"gear {i} rattles"
        assert box[f"gear[{i}].stat_rattle_power"][-1] > 0 and box[f"gear[{i}].stat_a_rms"][-1] > 0
        for name in STATS:
            np.testing.assert_allclose(box[f"gear[{i}].{name}"][-1], pair[name][-1], rtol=1e-12, err_msg=f"gear {i} {name}")
