"""The FMU against the independent reference (gearrattle.gearbox_reference) on the default
box warm (B1) and cold (B2) and on a run-down (R1), in both interfaces: each gear's xi within
1e-4 G_i and its impact counts exact over the scene's pointwise-predictable window, its
impact rate within the reference's spread over perturbed runs beyond (docs/GEARBOX.md §8)."""

import numpy as np
import pytest

from gearrattle import gearbox_fmu as GF
from gearrattle import gearbox_reference as R
from support.gearbox import RATE_SPREAD, WINDOW, counts_away_from_impacts, reference_scene, scene_start

T_END, DT = 2.0, 1e-4
# The FMU's tolerance over the pointwise windows, its error well below 1e-4 G there:
# co-simulation's own solver, or fmpy's CVode in Model Exchange (at 1e-10 gear 1 of B1 reaches
# 1.0e-4 G at 0.35 s, at 1e-12 4.3e-6 G).
TOL = {"CoSimulation": 1e-10, "ModelExchange": 1e-12}
# The tolerance of the rates' runs to T_END: the rates are statistics over 1.5 s, not a
# trajectory, and 1e-9 keeps them within the reference's spread at a fraction of CVode's work
# at 1e-12.
RATE_TOL = {"CoSimulation": 1e-10, "ModelExchange": 1e-9}
# Rates beyond the window: 0.5 s to the end (the statistics window). Two runs each within the
# reference's spread of the mean rate differ by up to twice it.
RATE_T0 = 0.5


def _runs(box_run, box_md, scene, fmi_type, t_end, tol):
    """The FMU's run to t_end and the reference's (rtol 1e-12, to T_END), with outputs every
    DT, and the index of each FMU row among the reference's (fmpy's Model Exchange loop may
    leave out an output point that an event falls on)."""
    if fmi_type == "ModelExchange" and box_md.modelExchange is None:
        pytest.fail("the FMU does not offer Model Exchange yet", pytrace=False)
    fmu, ref = box_run(t_end, DT, fmi_type, tol, **scene_start(scene)), reference_scene(scene, T_END, DT)
    ix = np.round(fmu["time"] / DT).astype(int)
    assert np.allclose(fmu["time"], ref.t[ix], rtol=0, atol=1e-12)
    assert ix.size >= 0.999 * np.count_nonzero(ref.t <= t_end + 1e-12)
    return fmu, ref, ix


def _window_runs(box_run, box_md, scene, fmi_type):
    """The runs over the scene's pointwise window: Model Exchange's to the window's end alone,
    co-simulation's to T_END (the one run of its rates too)."""
    t_end = WINDOW[scene] if fmi_type == "ModelExchange" else T_END
    return _runs(box_run, box_md, scene, fmi_type, t_end, TOL[fmi_type])


BOTH = [(s, f) for s in ("B1", "B2", "R1") for f in ("CoSimulation", "ModelExchange")]


@pytest.mark.parametrize("scene,fmi_type", BOTH)
def test_xi_pointwise_over_window(box_run, box_md, scene, fmi_type):
    fmu, ref, ix = _window_runs(box_run, box_md, scene, fmi_type)
    w = fmu["time"] <= WINDOW[scene] + 1e-12
    xi = GF.per_gear(fmu, "xi")[:, w]
    G = np.array([R.gear(ref.params, i + 1)["G"] for i in range(xi.shape[0])])
    err = np.max(np.abs(xi - ref.xi[:, ix[w]]), axis=1) / G
    assert np.all(err < 1e-4), f"{scene} {fmi_type}: max |xi - xi_ref| / G per gear {err}"


@pytest.mark.parametrize("scene,fmi_type", BOTH)
def test_impact_counts_over_window(box_run, box_md, scene, fmi_type):
    fmu, ref, ix = _window_runs(box_run, box_md, scene, fmi_type)
    w = fmu["time"] <= WINDOW[scene] + 1e-12
    want, got = counts_away_from_impacts(ref, ref.t[ix[w]], GF.impact_counts(fmu)[:, w])
    assert np.array_equal(got[:, -1], want[:, -1]), f"{scene} {fmi_type}: counts {got[:, -1]} vs {want[:, -1]}"
    assert np.array_equal(got, want), f"{scene} {fmi_type}: the counts differ at some samples"


@pytest.mark.parametrize("scene,fmi_type", [b for b in BOTH if b[0] != "B2"])
def test_impact_rates_beyond_window(box_run, box_md, scene, fmi_type):
    fmu, ref, _ = _runs(box_run, box_md, scene, fmi_type, T_END, RATE_TOL[fmi_type])
    t = fmu["time"]
    counts = GF.impact_counts(fmu)
    k0, k1 = np.searchsorted(t, RATE_T0 - 1e-9), t.size - 1
    got = (counts[:, k1] - counts[:, k0]) / (t[k1] - t[k0])
    want = ref.impact_rates(RATE_T0, T_END)
    spread = 2 * RATE_SPREAD[: got.size]
    assert np.all(np.abs(got - want) <= spread * want + 1.0), f"{scene} {fmi_type}: rates {got} vs {want}"
