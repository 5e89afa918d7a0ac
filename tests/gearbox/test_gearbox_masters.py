"""libcosim and Ecos run GearboxRattle coupled with the Flywheel partner as its engine
(excitation 0; gearrattle.gearbox_masters): short runs that must complete, stay near idle,
rattle, and agree between the two masters (both fixed-step on the same steps; their first
steps feed the box's inputs a little differently, which moves phi by some 1e-8 rad, and
up to 4e-6 rad where the damper changes stage)."""

import numpy as np
import pytest

from gearrattle import gearbox_masters as GM
from gearrattle.masters import FLYWHEEL_FMU, OMEGA_IDLE
from support.fmu import require

T_END, H = 0.2, 1e-4


@pytest.fixture(scope="module")
def runs(gearbox_fmu):
    require(FLYWHEEL_FMU, "`make flywheel-fmu`")
    return {m: run(T_END, H) for m, run in GM.MASTERS.items()}


@pytest.mark.parametrize("master", sorted(GM.MASTERS))
def test_coupled_with_the_flywheel(runs, master):
    rec = runs[master]
    assert rec["time"].size == round(T_END / H) and rec["time"][-1] == pytest.approx(T_END, abs=1e-9)
    assert np.all(np.isfinite(rec["phi"])) and np.all(np.isfinite(rec["tau_F"]))
    assert np.all(np.abs(rec["omega_F"] / OMEGA_IDLE - 1) < 0.2)
    assert rec["impacts"][:, -1].sum() > 0, rec["impacts"][:, -1]


def test_masters_agree(runs):
    a, b = runs["libcosim"], runs["ecos"]
    np.testing.assert_allclose(a["omega_F"], b["omega_F"], rtol=1e-9)
    np.testing.assert_allclose(a["phi"], b["phi"], rtol=0, atol=1e-5)  # phi_1 = 0.052 rad
    assert np.array_equal(a["impacts"][:, -1], b["impacts"][:, -1])
