"""FMI 3.0 Co-Simulation's intermediate update (target/fmu/fmi3/GearRattle.fmu): the
intermediateUpdate callback called once per impact inside fmi3DoStep at the reference's
instants, the step ended early at the impact where the callback requests it (with early
return allowed), and the trajectory of a master that passes the callback that of one that
does not, to the bit."""

import numpy as np
import pytest
from fmpy.fmi3 import FMU3Slave
from support.early_return import step_to_impacts
from support.fmu import BUILD_FMU3, FMU3_PATH, session_fixtures
from support.intermediate_update import IntermediateUpdate

from gearrattle import reference as R

fmu3_path, md3, unzipdir3 = session_fixtures(FMU3_PATH, BUILD_FMU3, ("fmu3_path", "md3", "unzipdir3"))

T_END, H = 0.1, 1e-3


def vr_of(md, name):
    return next(v.valueReference for v in md.modelVariables if v.name == name)


def stepped(md3, unzipdir3, update=None, early_return=False, h=H, t_end=T_END):
    """Scene S1 over t_end in communication steps of h with the intermediateUpdate callback
    `update` (None: NULL), each early return followed by a step to the same communication
    point: the early returns (the time, the callback's calls and the impacts by then), the
    impacts at the end and xi, xi' at every communication point."""
    fmu = FMU3Slave(guid=md3.instantiationToken, unzipDirectory=unzipdir3,
                    modelIdentifier=md3.coSimulation.modelIdentifier, instanceName="intermediate")
    fmu.instantiate(earlyReturnAllowed=early_return, intermediateUpdate=update)
    fmu.enterInitializationMode(startTime=0.0)
    fmu.setInt64([vr_of(md3, "excitation")], [1])
    fmu.setFloat64([vr_of(md3, "f_exc"), vr_of(md3, "A_rms")], [R.SCENES["S1"]["f_exc"], R.SCENES["S1"]["A_rms"]])
    fmu.exitInitializationMode()
    counts = [vr_of(md3, "impacts_Fplus"), vr_of(md3, "impacts_Fminus")]
    returned, at_return, grid = step_to_impacts(
        fmu, t_end, h, False, lambda: (len(update.calls), sum(fmu.getInt32(counts))),
        lambda: fmu.getFloat64([vr_of(md3, "xi"), vr_of(md3, "xi_dot")]))
    total = sum(fmu.getInt32(counts))
    fmu.terminate()
    fmu.freeInstance()
    return [(t, *at) for t, at in zip(returned, at_return)], total, grid


@pytest.mark.parametrize("early_return", [False, True], ids=["no early return", "early return allowed"])
def test_called_once_per_impact_at_its_instant(md3, unzipdir3, early_return):
    """One call per impact counted, at the reference's instants within the FMI 2.0 sine tests'
    1e-7 s, the step finished there, no intermediate variable to set or get, the early return
    offered where the importer allows it; no request, no early return, and xi, xi' at the
    communication points those of the run without the callback, to the bit."""
    update = IntermediateUpdate()
    returns, total, grid = stepped(md3, unzipdir3, update, early_return)
    ref = R.scene("S1", T_END)
    assert total > 10 and len(update.calls) == total == ref.impact_t.size
    assert np.max(np.abs(np.array(update.times()) - ref.impact_t)) < 1e-7
    assert update.flags() == {(False, False, True, early_return)}
    assert returns == []
    _, _, plain = stepped(md3, unzipdir3)
    np.testing.assert_array_equal(grid, plain)


def test_one_step_over_every_impact(md3, unzipdir3):
    """One communication step of 0.3 s from 0, continued after each impact to its own end
    (from one impact the rest 0.3 - t rounds to another end): the calls of the steps of H,
    and the state at 0.3 s that of the step without the callback, to the bit."""
    update, steps = IntermediateUpdate(), IntermediateUpdate()
    _, total, grid = stepped(md3, unzipdir3, update, h=0.3, t_end=0.3)
    stepped(md3, unzipdir3, steps, t_end=0.3)
    assert update.times() == steps.times() and len(update.calls) == total
    assert any(t + (0.3 - t) != 0.3 for t in update.times())
    _, _, plain = stepped(md3, unzipdir3, h=0.3, t_end=0.3)
    np.testing.assert_array_equal(grid, plain)


def test_early_return_where_the_callback_requests_it(md3, unzipdir3):
    """A request at the third call ends that step at the third impact (its time the call's,
    three impacts counted); the run goes on as the one without requests, to the bit. Without
    early return allowed the request is not offered and the step goes on."""
    update = IntermediateUpdate(request_at=3)
    returns, total, grid = stepped(md3, unzipdir3, update, early_return=True)
    assert returns == [(update.times()[2], 3, 3)]
    _, plain_total, plain = stepped(md3, unzipdir3)
    assert total == plain_total
    np.testing.assert_array_equal(grid, plain)
    refused, _, _ = stepped(md3, unzipdir3, IntermediateUpdate(request_at=3))
    assert refused == []
