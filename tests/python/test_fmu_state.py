"""FMU state: rollback and re-step is bit-identical, a serialized state restores
bit-identically into a second instance, and corrupt or foreign bytes are refused without
harm to the instance."""

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException

OUT = ["xi", "xi_dot", "F_contact", "tau_M", "E_contact", "E_lubricant", "theta_L", "omega_L"]
COUNTERS = ["impacts_Fplus", "impacts_Fminus", "contact"]


def read(s, vrs):
    reals = s.getReal([vrs[n] for n in OUT])
    ints = s.getInteger([vrs[n] for n in COUNTERS])
    return np.array(reals), tuple(ints)


def run(s, vrs, t0, n, h):
    trace = []
    for k in range(n):
        s.doStep(t0 + k * h, h)
        trace.append(read(s, vrs))
    return trace


def same(a, b):
    return all(np.array_equal(x[0], y[0]) and x[1] == y[1] for x, y in zip(a, b))


def test_rollback_then_restep_is_bit_identical(slave, vrs):
    s = slave("rollback", excitation=1)
    run(s, vrs, 0.0, 37, 1e-3)  # somewhere in the rattle
    state = s.getFMUstate()
    first = run(s, vrs, 0.037, 40, 5e-4)
    s.setFMUstate(state)
    again = run(s, vrs, 0.037, 40, 5e-4)
    assert same(first, again)
    assert first[-1][1][:2] != (0, 0), "impacts happened in the window"
    s.freeFMUstate(state)


def test_serialized_state_restores_into_another_instance(slave, vrs):
    a = slave("a", excitation=1)
    run(a, vrs, 0.0, 50, 1e-3)
    blob = a.serializeFMUstate(a.getFMUstate())
    b = slave("b", excitation=1)  # a fresh instance at t = 0
    b.setFMUstate(b.deSerializeFMUstate(blob))
    assert same([read(a, vrs)], [read(b, vrs)])
    assert same(run(a, vrs, 0.05, 30, 1e-3), run(b, vrs, 0.05, 30, 1e-3))


@pytest.mark.parametrize("damage", ["flip", "truncate", "foreign"])
def test_corrupt_or_foreign_state_is_refused(slave, vrs, damage):
    s = slave("corrupt", excitation=1)
    run(s, vrs, 0.0, 10, 1e-3)
    blob = bytearray(s.serializeFMUstate(s.getFMUstate()))
    if damage == "flip":
        blob[len(blob) // 2] ^= 0x40
    elif damage == "truncate":
        blob = blob[:-3]
    else:
        blob = bytearray(b"FMU state of some other model" * 4)
    before = read(s, vrs)
    with pytest.raises(FMICallException):
        s.deSerializeFMUstate(bytes(blob))
    assert same([before], [read(s, vrs)])
    run(s, vrs, 0.01, 5, 1e-3)  # still usable
