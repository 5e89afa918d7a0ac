//! Model Exchange's Jacobian for fmi2GetDirectionalDerivative: ∂ẋ/∂(x, u) and the outputs'
//! partials, analytic, from the contact law's slopes (docs/MODEL.md §2,
//! [`ContactLaw::slopes`](crate::physics::ContactLaw::slopes)) through the equations of
//! motion (§3) in Model Exchange's coordinates, in the region ξ is in, as the derivatives.
//!
//! Each quantity carries its gradient over the knowns (a forward-mode derivative): the NX
//! states, then the inputs θ_M, ω_M, α_M, τ_in. The primitives are ξ, ω_L, the shaft's angle
//! Θ and speed Ω, and the torque τ on it; Θ and Ω are the states x_theta_M, x_omega_M in the
//! torque mode, the inputs theta_M, omega_M in the inputs mode, functions of time alone in
//! the sine mode; τ is tau_in in the torque mode. Then, with F_ξ = ∂F/∂ξ, F_v = ∂F/∂ξ':
//!
//!   ξ' = r_L ω_L − r_M Ω,  dF = F_ξ dξ + F_v dξ'
//!   α_L = (B − r_L F − C (ω_L − ω_S)) / I_L,  α_M = (τ + r_M F) / I_M (torque mode; else 0)
//!
//! and the quadratures' rates F_c ξ', C (ω_L − ω_S)², −r_M F Ω, a², F, F² by the chain rule.
#![allow(non_snake_case)]

use std::ops::{Add, Mul, Sub};

use super::{NX, Point, ShaftFrom};
use crate::contract::{Causality, DERIVATIVES, Kind, STATES, find, vr};
use crate::rattle::window::{Quadratures, Slopes, quadrature};

/// The states' indices in x (the quadratures of [`quadrature`] follow from X_QUADRATURES on).
const X_XI: usize = 0;
const X_OMEGA_L: usize = 1;
const X_THETA_M: usize = 2;
const X_OMEGA_M: usize = 3;
const X_QUADRATURES: usize = 4;

/// Number of knowns: the states, then the inputs of [`INPUTS`].
pub const NK: usize = NX + INPUTS.len();

/// The inputs a column can be taken along, in the order of the columns after the states.
pub const INPUTS: [u32; 4] = [vr::theta_M, vr::omega_M, vr::alpha_M, vr::tau_in];

/// A gradient over the knowns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gradient(pub [f64; NK]);

impl Gradient {
    const ZERO: Gradient = Gradient([0.0; NK]);

    fn unit(column: usize) -> Self {
        let mut g = Self::ZERO;
        g.0[column] = 1.0;
        g
    }
}

impl Add for Gradient {
    type Output = Gradient;
    fn add(self, other: Gradient) -> Gradient {
        Gradient(std::array::from_fn(|i| self.0[i] + other.0[i]))
    }
}

impl Sub for Gradient {
    type Output = Gradient;
    fn sub(self, other: Gradient) -> Gradient {
        Gradient(std::array::from_fn(|i| self.0[i] - other.0[i]))
    }
}

impl Mul<Gradient> for f64 {
    type Output = Gradient;
    fn mul(self, g: Gradient) -> Gradient {
        Gradient(g.0.map(|v| self * v))
    }
}

/// The column of a known: a state's index in x, or NX + its index in [`INPUTS`].
pub fn column(known: u32) -> Option<usize> {
    STATES
        .iter()
        .position(|&s| s == known)
        .or_else(|| INPUTS.iter().position(|&u| u == known).map(|i| NX + i))
}

/// The gradients of the derivatives and of the outputs that have one, at one point.
pub struct Jacobian {
    /// ∂ẋ_i/∂known, in the state vector's order.
    derivatives: [Gradient; NX],
    theta_L: Gradient,
    omega_L: Gradient,
    alpha_L: Gradient,
    xi_dot: Gradient,
    force: Gradient,
    theta_M: Gradient,
    omega_M: Gradient,
    alpha_M: Gradient,
    r_L: f64,
    r_M: f64,
    /// The statistics' slopes over the quadratures.
    window: Slopes,
}

impl Jacobian {
    /// The gradients at `point`, with the statistics window's slopes there.
    pub(super) fn new(point: &Point, window: Slopes) -> Self {
        let p = &point.dynamics.params;
        let law = &point.dynamics.law;
        let (loads, shaft) = (&point.loads, &point.shaft);
        let input = |u: u32| column(u).expect("an input");
        // The primitives' gradients.
        let d_xi = Gradient::unit(X_XI);
        let d_omega_L = Gradient::unit(X_OMEGA_L);
        let (d_theta, d_omega, d_tau) = match point.shaft_from {
            ShaftFrom::States(_) => (
                Gradient::unit(X_THETA_M),
                Gradient::unit(X_OMEGA_M),
                Gradient::unit(input(vr::tau_in)),
            ),
            ShaftFrom::Inputs => (
                Gradient::unit(input(vr::theta_M)),
                Gradient::unit(input(vr::omega_M)),
                Gradient::ZERO,
            ),
            ShaftFrom::Time => (Gradient::ZERO, Gradient::ZERO, Gradient::ZERO),
        };
        let f = law.slopes(point.region, point.xi, point.xi_dot);
        let fc = law.dissipative_slopes(point.region, point.xi, point.xi_dot);
        let xi_dot = p.r_L * loads.omega_L - p.r_M * shaft.omega;
        let force = loads.force.total();
        let slip = loads.omega_L - p.omega_S;
        let a = p.r_L * loads.alpha_L;

        let d_xi_dot = p.r_L * d_omega_L - p.r_M * d_omega;
        let d_force = f.d_xi * d_xi + f.d_xi_dot * d_xi_dot;
        let d_dissipative = fc.d_xi * d_xi + fc.d_xi_dot * d_xi_dot;
        let d_alpha_L = (1.0 / p.I_L) * (-p.r_L * d_force - p.C * d_omega_L);
        let d_alpha_M = match point.shaft_from {
            ShaftFrom::States(main) => (1.0 / main.I_M) * (d_tau + p.r_M * d_force),
            // A function of time (sine mode), or 0: the inputs mode holds the shaft's speed
            // between the importer's inputs.
            _ => Gradient::ZERO,
        };
        let (d_x_theta_M, d_x_omega_M) = match point.shaft_from {
            ShaftFrom::States(_) => (d_omega, d_alpha_M),
            _ => (Gradient::ZERO, Gradient::ZERO),
        };
        let derivatives = [
            d_xi_dot,
            d_alpha_L,
            d_x_theta_M,
            d_x_omega_M,
            // E_contact' = F_c ξ'
            xi_dot * d_dissipative + loads.force.dissipative * d_xi_dot,
            // E_lubricant' = C (ω_L − ω_S)²
            (2.0 * p.C * slip) * d_omega_L,
            // W_shaft' = −r_M F Ω
            (-p.r_M * shaft.omega) * d_force - (p.r_M * force) * d_omega,
            // (∫a²)' = a², a = r_L α_L
            (2.0 * a * p.r_L) * d_alpha_L,
            // (∫F)' = F, (∫F²)' = F²
            d_force,
            (2.0 * force) * d_force,
        ];
        Jacobian {
            derivatives,
            theta_L: (1.0 / p.r_L) * (d_xi + p.r_M * d_theta),
            omega_L: d_omega_L,
            alpha_L: d_alpha_L,
            xi_dot: d_xi_dot,
            force: d_force,
            theta_M: d_theta,
            omega_M: d_omega,
            alpha_M: d_alpha_M,
            r_L: p.r_L,
            r_M: p.r_M,
            window,
        }
    }

    /// The gradient of a derivative or of a Real output; None for the others. The window's
    /// figures other than its RMS, standard deviation and powers, and the impact speed,
    /// change at events only: their gradients are zero.
    pub fn gradient(&self, unknown: u32) -> Option<Gradient> {
        if let Some(i) = DERIVATIVES.iter().position(|&d| d == unknown) {
            return Some(self.derivatives[i]);
        }
        Some(match unknown {
            vr::theta_L => self.theta_L,
            vr::omega_L => self.omega_L,
            vr::alpha_L => self.alpha_L,
            vr::a_pitch_L => self.r_L * self.alpha_L,
            vr::xi => Gradient::unit(X_XI),
            vr::xi_dot => self.xi_dot,
            vr::F_contact => self.force,
            vr::tau_M => self.r_M * self.force,
            vr::E_contact => Gradient::unit(X_QUADRATURES + quadrature::E_CONTACT),
            vr::E_lubricant => Gradient::unit(X_QUADRATURES + quadrature::E_LUBRICANT),
            vr::theta_M_out => self.theta_M,
            vr::omega_M_out => self.omega_M,
            vr::alpha_M_out => self.alpha_M,
            vr::stat_a_rms => over_quadratures(&self.window.a_rms),
            vr::stat_F_std => over_quadratures(&self.window.F_std),
            vr::stat_P_contact => over_quadratures(&self.window.P_contact),
            vr::stat_P_lubricant => over_quadratures(&self.window.P_lubricant),
            _ if find(Kind::Real, unknown).is_some_and(|v| v.causality == Causality::Output) => {
                Gradient::ZERO
            }
            _ => return None,
        })
    }
}

/// A row over the quadratures as a gradient over the knowns.
fn over_quadratures(row: &Quadratures) -> Gradient {
    let mut g = Gradient::ZERO;
    g.0[X_QUADRATURES..X_QUADRATURES + quadrature::COUNT].copy_from_slice(row);
    g
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contract::VARIABLES;
    use crate::instance::simulation::{EXCITATION_INPUTS, EXCITATION_SINE, EXCITATION_TORQUE};
    use crate::instance::{Carry, Simulation};
    use crate::physics::{GearParams, Shaft};
    use fmi2_shell::Continuous;
    use fmi2_shell::values::Values;

    const T: f64 = 0.0123;
    const SHAFT: Shaft = Shaft {
        theta: 4.5,
        omega: 83.0,
        alpha: 900.0,
    };
    const TAU: (f64, f64) = (2.0, -40.0);

    /// A simulation in `excitation`'s mode with every parameter that enters the Jacobian
    /// switched on (drag, carrier speed, external torque, contact damping), at time T with the
    /// states x and the inputs `shaft` and `tau` (as the importer sets them), the pair's
    /// region settled where ξ is.
    fn at(excitation: i64, alpha: f64, x: &[f64; NX], shaft: Shaft, tau: f64) -> Simulation {
        let mut values = Values::start(VARIABLES);
        values.set_integer(vr::excitation, excitation);
        for (v, value) in [
            (vr::alpha, alpha),
            (vr::B, 0.3),
            (vr::omega_S, 12.0),
            (vr::I_M, 0.008),
            (vr::A_rms, 300.0),
            (vr::f_exc, 30.0),
            (vr::omega_mean, 84.0),
        ] {
            values.set_real(v, value);
        }
        let mut sim =
            Simulation::new(&values, 0.0, 0.0, 1e-6, Carry::All).expect("valid parameters");
        sim.set_time(T).expect("a finite shaft at T");
        sim.set_shaft_inputs(shaft);
        sim.set_torque(tau, TAU.1);
        // The window opens at the quadratures' origin, so that the statistics are non-zero.
        let mut origin = *x;
        origin[X_QUADRATURES..].fill(0.0);
        sim.set_continuous_states(&origin);
        sim.update_discrete_states();
        sim.set_continuous_states(x);
        sim
    }

    /// The derivatives and the outputs the Jacobian gives, as one vector.
    fn unknowns(sim: &Simulation, outputs: &[u32]) -> Vec<f64> {
        let mut v = sim.derivatives().to_vec();
        v.extend(
            outputs
                .iter()
                .map(|&o| sim.real_output(o).expect("an output")),
        );
        v
    }

    /// Every entry of ∂(derivatives, outputs)/∂(states, inputs) against central differences
    /// of `derivatives` and of the outputs as computed, in each region of the contact law
    /// and each drive mode, for three stiffening exponents. The inputs are moved alone, as an
    /// importer sets them: the states x must stay as set.
    #[test]
    fn jacobian_matches_finite_differences() {
        let probe = at(EXCITATION_SINE, 1.0, &[1e-5; NX], SHAFT, TAU.0).jacobian();
        let outputs: Vec<u32> = VARIABLES
            .iter()
            .filter(|v| v.causality == Causality::Output && probe.gradient(v.vr).is_some())
            .map(|v| v.vr)
            .collect();
        let g = GearParams::paper().G;
        let steps = [
            1e-10, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-3, 1e-6,
        ];
        for excitation in [EXCITATION_INPUTS, EXCITATION_SINE, EXCITATION_TORQUE] {
            for alpha in [1.0, 4.0 / 3.0, 1.5] {
                for xi in [-3e-6, -0.6e-6, 10e-6, g + 0.3e-6, g + 4e-6] {
                    // ∫F² above (∫F)²/T: a positive variance of F.
                    let x = [xi, 64.0, 4.5, 83.0, 0.1, 0.2, 0.3, 0.4, 0.5, 30.0];
                    let sim = at(excitation, alpha, &x, SHAFT, TAU.0);
                    let j = sim.jacobian();
                    let rows: Vec<Gradient> = DERIVATIVES
                        .iter()
                        .chain(&outputs)
                        .map(|&u| j.gradient(u).expect("given"))
                        .collect();
                    for (col, h) in steps.into_iter().enumerate() {
                        let moved = |sign: f64| {
                            let (mut moved, mut x, mut shaft) = (sim, x, SHAFT);
                            let d = sign * h;
                            match col {
                                c if c < NX => {
                                    x[c] += d;
                                    moved.set_continuous_states(&x);
                                }
                                c if INPUTS[c - NX] == vr::tau_in => {
                                    moved.set_torque(TAU.0 + d, TAU.1);
                                }
                                c => {
                                    match INPUTS[c - NX] {
                                        vr::theta_M => shaft.theta += d,
                                        vr::omega_M => shaft.omega += d,
                                        _ => shaft.alpha += d,
                                    }
                                    moved.set_shaft_inputs(shaft);
                                }
                            }
                            unknowns(&moved, &outputs)
                        };
                        let (up, down) = (moved(1.0), moved(-1.0));
                        for (row, gradient) in rows.iter().enumerate() {
                            let fd = (up[row] - down[row]) / (2.0 * h);
                            let exact = gradient.0[col];
                            // Relative, plus the rounding of the values differenced.
                            let rounding = up[row].abs().max(down[row].abs()) * f64::EPSILON / h;
                            let tol = 1e-6 * fd.abs().max(exact.abs()) + 4.0 * rounding + 1e-9;
                            assert!(
                                (exact - fd).abs() <= tol,
                                "mode {excitation} alpha {alpha} xi {xi:e}: row {row} column {col}: {exact} against {fd}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// Model Exchange's outputs take the contact in the region ξ is in, as the derivatives:
    /// ξ set into contact from the gap, with no event yet, gives α_L = der(ω_L) and the force
    /// and τ_M that equation of motion implies, F = (B − C (ω_L − ω_S) − I_L α_L) / r_L,
    /// where the region kept since the last event (co-simulation's outputs) still reads the
    /// gap's zero force.
    #[test]
    fn outputs_take_the_region_xi_is_in() {
        let gap = [10e-6, 64.0, 4.5, 83.0, 0.1, 0.2, 0.3, 0.4, 0.5, 30.0];
        for excitation in [EXCITATION_INPUTS, EXCITATION_SINE, EXCITATION_TORQUE] {
            let mut sim = at(excitation, 4.0 / 3.0, &gap, SHAFT, TAU.0);
            let mut x = gap;
            x[X_XI] = -3e-6;
            sim.set_continuous_states(&x);
            let p = sim.now().dynamics.params;
            let alpha_L = sim.derivatives()[X_OMEGA_L];
            let force = (p.B - p.C * (x[X_OMEGA_L] - p.omega_S) - p.I_L * alpha_L) / p.r_L;
            let read = |vr| sim.model_exchange_output(vr).expect("an output");
            assert!(
                force.abs() > 1.0,
                "mode {excitation}: in contact, F = {force}"
            );
            assert_eq!(read(vr::alpha_L), alpha_L, "mode {excitation}");
            let tol = 1e-9 * force.abs();
            assert!(
                (read(vr::F_contact) - force).abs() <= tol,
                "mode {excitation}"
            );
            assert!(
                (read(vr::tau_M) - p.r_M * force).abs() <= p.r_M * tol,
                "mode {excitation}"
            );
            assert_eq!(
                sim.real_output(vr::F_contact),
                Some(0.0),
                "mode {excitation}"
            );
        }
    }

    /// The Jacobian's columns hold x fixed, as FMI's states are: a new time (sine mode: the
    /// shaft's speed moves) or new inputs leave fmi2GetContinuousStates as set, to rounding.
    #[test]
    fn the_states_stay_as_set_when_time_and_inputs_move() {
        let x = [3e-6, 64.0, 4.5, 83.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6];
        for excitation in [EXCITATION_INPUTS, EXCITATION_SINE, EXCITATION_TORQUE] {
            let mut sim = at(excitation, 1.0, &x, SHAFT, TAU.0);
            sim.set_time(T + 1e-3).expect("a finite shaft at T + 1 ms");
            sim.set_shaft_inputs(Shaft {
                omega: 90.0,
                ..SHAFT
            });
            sim.set_torque(-1.0, 0.0);
            let now = sim.continuous_states();
            for (i, (now, set)) in now.iter().zip(x).enumerate() {
                let unused = (2..4).contains(&i) && excitation != EXCITATION_TORQUE;
                assert!(
                    unused || (now - set).abs() <= 1e-14 * set.abs(),
                    "mode {excitation}: x[{i}] = {now} after {set}"
                );
            }
        }
    }
}
