"""Input derivatives, output derivatives and directional derivatives, checked
against finite differences and against the same motion given as plain inputs."""

import numpy as np
from gearrattle import reference as R


def shaft(t):
    """theta_M, omega_M, alpha_M of scene S1's main shaft at t (docs/MODEL.md §5)."""
    return [float(x[0]) for x in R.main_shaft(np.array([t]), R.params("S1"))]


def drive(s, vrs, n, h, with_derivatives):
    """Steps S1's main shaft given as theta_M alone plus its derivatives, or as the three inputs."""
    xi = []
    for k in range(n):
        t = k * h
        th, om, al = shaft(t)
        if with_derivatives:
            s.setReal([vrs["theta_M"]], [th])
            s.setRealInputDerivatives([vrs["theta_M"], vrs["theta_M"]], [1, 2], [om, al])
        else:
            s.setReal([vrs["theta_M"], vrs["omega_M"], vrs["alpha_M"]], [th, om, al])
        s.doStep(t, h)
        xi.append(s.getReal([vrs["xi"]])[0])
    return np.array(xi)


def start_inputs(slave, name):
    """An inputs-mode instance started on S1's main shaft."""
    return slave(name, **dict(zip(["theta_M", "omega_M", "alpha_M"], shaft(0.0))))


def test_input_derivatives_drive_the_extrapolation(slave, vrs):
    """theta_M with its derivatives (orders 1, 2) steps exactly like theta_M, omega_M, alpha_M
    given as inputs, and both follow the sine bench closely at a 0.5 ms step."""
    a = start_inputs(slave, "derivatives")
    b = start_inputs(slave, "inputs")
    n, h = 100, 5e-4
    xa, xb = drive(a, vrs, n, h, True), drive(b, vrs, n, h, False)
    np.testing.assert_array_equal(xa, xb)
    ref = R.simulate(R.params("S1"), n * h, t_eval=h * np.arange(1, n + 1))
    assert np.max(np.abs(xa - ref.xi)) < 1e-2 * 25e-6
    # Without any derivative (theta_M alone, held speed), the same run is far worse.
    c = start_inputs(slave, "theta only")
    xc = []
    for k in range(n):
        c.setReal([vrs["theta_M"]], [shaft(k * h)[0]])
        c.doStep(k * h, h)
        xc.append(c.getReal([vrs["xi"]])[0])
    assert np.max(np.abs(np.array(xc) - ref.xi)) > 10 * np.max(np.abs(xa - ref.xi))


def in_contact(slave, vrs):
    """An inputs-mode instance stepped until the teeth are pressed into flank F-."""
    s = start_inputs(slave, "contact")
    h = 1e-4
    for k in range(2000):
        th, om, al = shaft(k * h)
        s.setReal([vrs["theta_M"], vrs["omega_M"], vrs["alpha_M"]], [th, om, al])
        s.doStep(k * h, h)
        if s.getReal([vrs["xi"]])[0] > 25e-6 + 2e-6:
            return s, (k + 1) * h
    raise AssertionError("never reached full contact on F-")


def test_directional_derivatives_match_finite_differences(slave, vrs):
    s, _ = in_contact(slave, vrs)
    state = s.getFMUstate()
    outs = ["tau_M", "F_contact", "xi", "xi_dot", "alpha_L", "a_pitch_L", "theta_L", "omega_L"]
    for inp, delta in (("theta_M", 1e-9), ("omega_M", 1e-6)):
        analytic = s.getDirectionalDerivative([vrs[o] for o in outs], [vrs[inp]], [1.0])
        base = s.getReal([vrs[o] for o in outs])
        value = s.getReal([vrs[inp]])[0]
        s.setReal([vrs[inp]], [value + delta])
        moved = s.getReal([vrs[o] for o in outs])
        s.setFMUstate(state)
        for o, a, b0, b1 in zip(outs, analytic, base, moved):
            fd = (b1 - b0) / delta
            # The outputs' own rounding, magnified by 1/delta, is part of the difference.
            rounding = 4 * np.spacing(max(abs(b0), abs(b1))) / delta
            assert abs(a - fd) <= 1e-4 * max(abs(fd), 1e-6) + 1e-9 + rounding, (o, inp, a, fd)
    # The coupling stiffness a master sees: dtau_M/dtheta_M = -r_M^2 dF/dxi < 0 in contact.
    k = s.getDirectionalDerivative([vrs["tau_M"]], [vrs["theta_M"]], [1.0])[0]
    assert k < -1e3


def test_output_derivatives_match_the_motion(slave, vrs):
    """fmi2GetRealOutputDerivatives against the equations of motion of the independent
    reference at the FMU's own state (ξ, ξ' read at t): ξ' and ξ'' = r_L ω_L' − r_M a_M, ω_L and
    ω_L', dF/dt along the motion (central difference of the reference's contact law), r_M dF/dt.
    (A finite difference of the outputs in time would measure the dense output's derivative:
    in sine mode the FMU serves communication points from its steps' interpolants.)"""
    s = slave("outder", excitation=1)
    h = 1e-3
    for k in range(30):
        s.doStep(k * h, h)
    t = 30 * h
    names = ["xi", "xi_dot", "theta_L", "omega_L", "F_contact", "tau_M"]
    d = s.getRealOutputDerivatives([vrs[n] for n in names], [1] * len(names))
    xi, xi_dot = s.getReal([vrs["xi"], vrs["xi_dot"]])
    p = R.params()
    om_l, al_l, _ = R.loose_gear(t, xi, xi_dot, p)
    _, _, a_m = R.main_shaft(t, p)
    xi_ddot = p["r_L"] * al_l - p["r_M"] * a_m
    step = 1e-9
    df = (
        R.contact_force(xi + xi_dot * step, xi_dot + xi_ddot * step, p)
        - R.contact_force(xi - xi_dot * step, xi_dot - xi_ddot * step, p)
    ) / (2 * step)
    expected = [xi_dot, xi_ddot, om_l, al_l, df, p["r_M"] * df]
    assert abs(df) > 0, "the gear should be in contact at 30 ms"
    for n, a, f in zip(names, d, expected):
        assert abs(a - f) <= 1e-4 * abs(f) + 1e-9 * (1 + abs(f)), (n, a, f)
