"""A master that allows FMI 3.0's early return, as the FMI 3.0 tests of both models drive it."""

import numpy as np


def step_to_impacts(fmu, t_end, h, event_mode, at_return, at_point):
    """Steps an initialised FMU3Slave from 0 to t_end in communication steps of h, each early
    return followed by a step from where it stopped to the same communication point: the
    times returned early, `at_return()` read there (in event mode if `event_mode`, which the
    instance was made with), and `at_point()` at every communication point."""
    if event_mode:
        # eventModeUsed: initialisation ends in event mode.
        assert fmu.updateDiscreteStates()[0] is False
        fmu.enterStepMode()
    t, k, returned, at, points = 0.0, 1, [], [], []
    while k <= round(t_end / h):
        event, terminate, early, last = fmu.doStep(t, k * h - t)
        assert (event, terminate) == (early and event_mode, False)
        if early:
            assert t < last < k * h
            if event_mode:
                fmu.enterEventMode()
            returned.append(last)
            at.append(at_return())
            if event_mode:
                fmu.updateDiscreteStates()
                fmu.enterStepMode()
        else:
            assert last == k * h
            points.append(at_point())
            k += 1
        t = last
    return np.array(returned), at, np.array(points)
