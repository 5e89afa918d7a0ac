"""The Model Exchange master's Jacobian (gearrattle/model_exchange.py, Drivetrain.jac: the
FMU's fmi2GetDirectionalDerivative for the gear pair, monolithic.drivetrain_partials for the
shaft and the engine, tau_M through the chain rule) against central differences of the
master's own right-hand side, at states in each region of the contact law."""

import numpy as np
import pytest

from gearrattle import model_exchange as ME
from gearrattle import reference as R

G = R.DEFAULTS["G"]
# ξ in contact on F+, in its band, in the gap, in F-'s band, in contact on F- (each at least
# 0.3 µm from an edge, 3000 steps of the difference on ξ).
XIS = [-3e-6, -0.6e-6, 10e-6, G + 0.3e-6, G + 4e-6]
T = 0.0123
# Away from the initial state: ξ' = 2 mm/s (contact damping active), the engine's firing
# torque off its zero, the damper twisted and slipping.
OFFSETS = dict(omega_L=0.05, theta_M=0.7, phi=0.01, omega_E=3.0)
OMEGA_L = 1  # omega_L's place among the FMU's states (docs/MODEL_EXCHANGE.md)


@pytest.fixture(scope="module")
def drivetrain(fmus):
    with ME.Drivetrain() as dt_:
        yield dt_


def state(dt_, xi):
    """The initial state moved by OFFSETS, with ξ = xi and no event iteration: the FMU's
    outputs (tau_M among them), derivatives and directional derivatives all take the region
    ξ is in."""
    nx = dt_.nx
    y = dt_.y0.copy()
    y[dt_.i_xi] = xi
    y[OMEGA_L] += OFFSETS["omega_L"]
    y[nx] += OFFSETS["theta_M"]
    y[nx + 2] += OFFSETS["phi"]
    y[nx + 3] += OFFSETS["omega_E"]
    return y


@pytest.mark.parametrize("xi", XIS)
def test_jacobian_matches_central_differences_of_the_rhs(drivetrain, xi):
    dt_ = drivetrain
    y = state(dt_, xi)
    exact = dt_.jac(T, y)
    n = y.size
    for j in range(n):
        h = 1e-10 if j == dt_.i_xi else 1e-6 * max(1.0, abs(y[j]))
        step = h * np.eye(n)[j]
        up, down = dt_.rhs(T, y + step), dt_.rhs(T, y - step)
        fd = (up - down) / (2 * h)
        # 1e-6 relative, plus the rounding of the differenced values over the step
        tol = 1e-6 * np.maximum(np.abs(exact[:, j]), np.abs(fd)) + 8 * np.finfo(float).eps * np.maximum(np.abs(up), np.abs(down)) / h
        bad = np.abs(exact[:, j] - fd) > tol
        assert not bad.any(), (xi, j, np.nonzero(bad)[0], exact[bad, j], fd[bad])
    if not 0.0 <= xi <= G:
        # in contact the main shaft's acceleration moves with ξ, through tau_M alone
        assert exact[dt_.nx + 1, dt_.i_xi] != 0.0
