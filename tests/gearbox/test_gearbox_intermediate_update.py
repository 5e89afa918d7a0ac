"""GearboxRattle's FMI 3.0 intermediate update (target/fmu/fmi3/GearboxRattle.fmu): the
intermediateUpdate callback called once per impact of any gear inside fmi3DoStep, at the
independent reference's instants, the step ended early at the impact where it requests it,
and the trajectory that of a master that passes no callback, to the bit."""

import numpy as np
from support.intermediate_update import IntermediateUpdate
from test_gearbox_fmi3 import (  # noqa: F401 (the FMU's fixtures)
    EARLY_H,
    EARLY_T_END,
    box3_md,
    box3_path,
    box3_unzipdir,
    stepped_to_impacts,
    vr3,
)


def test_called_once_per_impact_of_any_gear(box3_md, box3_unzipdir, vr3):
    """One call per impact of any gear, at the reference's instants (gearrattle.gearbox_reference,
    scene B1) within 1e-9 s at rtol 1e-10, the early return offered; no request, no early
    return; a request at the third call ends that step at the third impact; the trajectory
    that of the run without the callback, to the bit."""
    from support.gearbox import reference_scene

    assert box3_md.coSimulation.canReturnEarlyAfterIntermediateUpdate
    update = IntermediateUpdate()
    returned, _, total, grid = stepped_to_impacts(box3_md, box3_unzipdir, vr3, False, update=update)
    ref = reference_scene("B1", EARLY_T_END, EARLY_H)
    ref_t = np.sort(np.concatenate([d["t"] for d in ref.impacts[:5]]))
    assert total > 10 and len(update.calls) == total == ref_t.size and returned.size == 0
    assert np.max(np.abs(np.array(update.times()) - ref_t)) < 1e-9
    assert update.flags() == {(False, False, True, True)}
    _, _, _, plain = stepped_to_impacts(box3_md, box3_unzipdir, vr3, False, early_return=False)
    np.testing.assert_array_equal(grid, plain)
    requested = IntermediateUpdate(request_at=3)
    returned, at_return, _, grid = stepped_to_impacts(box3_md, box3_unzipdir, vr3, False, update=requested)
    assert list(returned) == [requested.times()[2]] and [n for _, n in at_return] == [3]
    np.testing.assert_array_equal(grid, plain)
