"""A statistics window asked to open within rounding of a communication step's end opens
there: the steps succeed, on the flywheel's inputs, the engine (Radau IIA) and the imposed
input side (the gears stepped apart), and every gear's stat_* outputs are those of the window
that opens on the communication point (tests/support/window_opening.py's master)."""

import math

import pytest

from support import window_opening as W

# An idle-like speed, 84 rad/s, oscillating at 26.7 Hz with 600 rad/s² (the flywheel's or the
# input side's motion).
W_OSC = 2 * math.pi * 26.7


def motion(prefix):
    def at(t):
        return {f"theta_{prefix}": 84.0 * t + 600.0 / W_OSC**2 * math.sin(W_OSC * t),
                f"omega_{prefix}": 84.0 + 600.0 / W_OSC * math.cos(W_OSC * t),
                f"alpha_{prefix}": -600.0 * math.sin(W_OSC * t)}
    return at


MODES = {
    "flywheel_inputs": ({"excitation": 0, "n_gears": 3}, motion("F")),
    "engine_radau": ({"excitation": 1, "n_gears": 3, "solver": 2}, lambda t: {}),
    "input_side": ({"excitation": 2, "n_gears": 3}, motion("I")),
}


@pytest.mark.parametrize("mode", MODES)
def test_a_window_within_rounding_of_a_step_end_opens_there(box_unzipdir, box_md, mode):
    start, inputs = MODES[mode]
    W.assert_opens_on_the_step_end(lambda stats_from: W.stats(box_unzipdir, box_md, start, inputs, stats_from))
