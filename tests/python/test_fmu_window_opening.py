"""A statistics window asked to open within rounding of a communication step's end opens
there: the steps succeed, in every mode, and the stat_* outputs are those of the window that
opens on the communication point (tests/support/window_opening.py's master)."""

import pytest

from gearrattle import reference as R
from support import window_opening as W

P = R.params("S1")
# The bench's S1 motion of the main shaft as inputs, or as the torque that moves a shaft too
# heavy for the contact to push (I_M = 10 kg m²) along it.
HEAVY = 10.0


def shaft(t):
    theta, omega, alpha = (float(x) for x in R.main_shaft(t, P))
    return {"theta_M": theta, "omega_M": omega, "alpha_M": alpha}


def torque(t):
    return {"tau_in": HEAVY * shaft(t)["alpha_M"]}


MODES = {
    "inputs": ({"excitation": 0}, shaft),
    "inputs_radau": ({"excitation": 0, "solver": 2}, shaft),
    "sine_radau": ({"excitation": 1, "f_exc": P["f_exc"], "A_rms": P["A_rms"], "solver": 2}, lambda t: {}),
    "torque": ({"excitation": 2, "I_M": HEAVY, "omega_M": shaft(0.0)["omega_M"]}, torque),
}


@pytest.mark.parametrize("mode", MODES)
def test_a_window_within_rounding_of_a_step_end_opens_there(unzipdir, model_description, mode):
    start, inputs = MODES[mode]
    W.assert_opens_on_the_step_end(lambda stats_from: W.stats(unzipdir, model_description, start, inputs, stats_from))
