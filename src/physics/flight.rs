//! Free flight in closed form: in the gap the contact force is zero, and the equation of
//! motion (docs/MODEL.md §3) is linear in ω_L,
//!
//!   I_L ω_L' = B − C (ω_L − ω_S),   i.e.   u' = β − λ u,   u = ω_L − ω_S, λ = C/I_L, β = B/I_L,
//!
//! whose solution from u0 at τ = 0 is u(τ) = u0 e^(−λτ) + β φ1(τ), with
//! φ1(τ) = (1 − e^(−λτ))/λ and its integral φ2(τ) = (τ − φ1(τ))/λ (τ and τ²/2 when C = 0).
//! The loose gear turns by ω_S τ + u0 φ1 + β φ2, the main shaft by its own motion, so
//! ξ = r_L θ_L − r_M θ_M follows without integration (docs/MODEL.md §5: the paper's free flight
//! "with nearly constant, slowly decaying speed", S(t) = S0 e^(−C* t)).
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

use super::excitation::SpanStart;
use super::{Excitation, GearParams};

/// The transmission error and the lubricant's dissipated energy along a free flight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlightState {
    pub xi: f64,
    pub xi_dot: f64,
    /// ∫ C (ω_L − ω_S)² dτ since the start of the flight [J].
    pub e_lubricant: f64,
    /// ∫ (ω_L − ω_S) dτ since the start of the flight [rad].
    pub slip_integral: f64,
}

/// What every point of a free flight from (t0, ξ0, ξ'0) shares: the start, the shaft there
/// (one sine and cosine), u0 = ω_L(t0) − ω_S, and the drag's constants λ, 1/λ and
/// u∞ = B/C. Plain data, kept along a passage through the gap so that each point costs only
/// its own end ([`Flight::at`]), with no division.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlightStart {
    xi0: f64,
    xi_dot0: f64,
    shaft: SpanStart,
    u0: f64,
    /// λ = C/I_L [1/s].
    lambda: f64,
    /// 1/λ, infinite when C = 0 (then unused).
    inv_lambda: f64,
    /// u∞ = B/C, the speed the drag settles u to (0 when C = 0, then unused).
    u_inf: f64,
}

impl FlightStart {
    /// Whether this is the start of a flight from (t0, ξ0, ξ'0), to the bit.
    pub fn is_from(&self, t0: f64, xi0: f64, xi_dot0: f64) -> bool {
        self.shaft.t0 == t0 && self.xi0 == xi0 && self.xi_dot0 == xi_dot0
    }
}

/// A free flight under the main shaft's imposed motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flight<'a> {
    pub params: &'a GearParams,
    pub excitation: &'a Excitation,
    pub start: FlightStart,
}

impl<'a> Flight<'a> {
    /// The flight from (t0, ξ0, ξ'0).
    pub fn new(
        params: &'a GearParams,
        excitation: &'a Excitation,
        t0: f64,
        xi0: f64,
        xi_dot0: f64,
    ) -> Self {
        let shaft = excitation.span_start(t0);
        // u0 = ω_L(t0) − ω_S from the shaft's speed at t0.
        let u0 = (xi_dot0 + params.r_M * shaft.omega0) / params.r_L - params.omega_S;
        Flight {
            params,
            excitation,
            start: FlightStart {
                xi0,
                xi_dot0,
                shaft,
                u0,
                lambda: params.C / params.I_L,
                inv_lambda: params.I_L / params.C,
                u_inf: if params.C == 0.0 {
                    0.0
                } else {
                    params.B / params.C
                },
            },
        }
    }

    /// ξ, ξ' and the lubricant's energy at t ≥ t0: one e^(−λτ) − 1 and the shaft at t (a
    /// sine and cosine) per call.
    pub fn at(&self, t: f64) -> FlightState {
        let p = self.params;
        let FlightStart {
            xi0,
            shaft,
            u0,
            lambda,
            inv_lambda,
            ..
        } = self.start;
        let span = self.excitation.span_from(&shaft, t);
        let tau = t - shaft.t0;
        let x = lambda * tau;
        // e^(−x) − 1, exact to the last digits for small x; φ1 = (1 − e^(−x))/λ, τ if C = 0.
        let em1 = (-x).exp_m1();
        let phi1 = if p.C == 0.0 { tau } else { -em1 * inv_lambda };
        let mut u = u0 * (1.0 + em1);
        let mut slipped = u0 * phi1;
        let mut turned_L = p.omega_S * tau + slipped;
        if p.B != 0.0 {
            let beta = p.B / p.I_L;
            u += beta * phi1;
            let drift = beta * tau * tau * phi2(x);
            turned_L += drift;
            slipped += drift;
        }
        FlightState {
            xi: xi0 + (p.r_L * turned_L - p.r_M * span.angle),
            xi_dot: p.r_L * (p.omega_S + u) - p.r_M * span.omega1,
            e_lubricant: self.dissipated(tau, phi1, em1),
            slip_integral: slipped,
        }
    }

    /// ∫0^τ C u² ds: with u = u∞ + a e^(−λs), a = u0 − u∞,
    /// C (u∞² τ + 2 u∞ a φ1 + a² (1 − e^(−2λτ))/(2λ)), where (1 − e^(−2λτ))/(2λ) =
    /// φ1 (1 + em1/2) since 1 − e^(−2x) = −em1 (2 + em1); nothing when C = 0.
    fn dissipated(&self, tau: f64, phi1: f64, em1: f64) -> f64 {
        let p = self.params;
        if p.C == 0.0 {
            return 0.0;
        }
        let FlightStart { u0, u_inf, .. } = self.start;
        let a = u0 - u_inf;
        p.C * (u_inf * (u_inf * tau + 2.0 * a * phi1) + a * a * phi1 * (1.0 + 0.5 * em1))
    }

    /// A bound on |ξ''| over the whole flight from t0 on: r_L |ω_L'(t0)| + r_M max |a_M|
    /// (ω_L' = −λ (u0 − B/C) e^(−λτ) decays, or is B/I_L when C = 0).
    pub fn acceleration_bound(&self) -> f64 {
        let p = self.params;
        let omega_L_dot = (p.B - p.C * self.start.u0) / p.I_L;
        p.r_L * omega_L_dot.abs() + p.r_M * self.excitation.max_acceleration()
    }
}

/// (x − 1 + e^(−x))/x², ½ at x = 0: its series Σ (−x)^k/(k+2)! below x = ½, where the
/// closed form would lose digits to cancellation (17 terms: below 1e-17 at ½).
fn phi2(x: f64) -> f64 {
    if x.abs() < 0.5 {
        let mut term = 0.5;
        let mut sum = 0.5;
        for k in 1..17 {
            term *= -x / (k + 2) as f64;
            sum += term;
        }
        sum
    } else {
        (x + (-x).exp_m1()) / (x * x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{Polynomial, Shaft, Sine};

    /// The closed form against a fine classical RK4 integration of docs/MODEL.md §3 with F = 0,
    /// written here from the equations (ξ'' = r_L ω_L' − r_M a_M), for the bench's sine and
    /// a drivetrain's polynomial, with and without B, C and ω_S.
    #[test]
    fn flight_matches_integrated_equations() {
        let sine = Excitation::Sine(Sine::new(300.0, 30.0, 84.0));
        let poly = Excitation::Polynomial(Polynomial {
            t0: 0.001,
            at_t0: Shaft {
                theta: 2.0,
                omega: 80.0,
                alpha: -350.0,
            },
        });
        let mut params = GearParams::paper();
        for (excitation, B, C, omega_S) in [
            (sine, 0.0, 0.025, 0.0),
            (sine, 0.3, 0.025, 12.0),
            (poly, -0.2, 0.4, 3.0),
            (sine, 0.1, 0.0, 5.0),
            (poly, 0.0, 0.0, 0.0),
        ] {
            (params.B, params.C, params.omega_S) = (B, C, omega_S);
            let (t0, xi0, xi_dot0) = (0.0123, 7e-6, -0.04);
            let flight = Flight::new(&params, &excitation, t0, xi0, xi_dot0);
            let p = &params;
            let f = |t: f64, y: [f64; 3]| {
                let shaft = excitation.at(t);
                let omega_L = (y[1] + p.r_M * shaft.omega) / p.r_L;
                let alpha_L = (p.B - p.C * (omega_L - p.omega_S)) / p.I_L;
                let u = omega_L - p.omega_S;
                [y[1], p.r_L * alpha_L - p.r_M * shaft.alpha, p.C * u * u]
            };
            let (mut t, mut y) = (t0, [xi0, xi_dot0, 0.0]);
            let h = 1e-6;
            for _ in 0..3000 {
                let add =
                    |y: [f64; 3], k: [f64; 3], s: f64| std::array::from_fn(|i| y[i] + s * k[i]);
                let k1 = f(t, y);
                let k2 = f(t + h / 2.0, add(y, k1, h / 2.0));
                let k3 = f(t + h / 2.0, add(y, k2, h / 2.0));
                let k4 = f(t + h, add(y, k3, h));
                y = std::array::from_fn(|i| {
                    y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
                });
                t += h;
            }
            let exact = flight.at(t);
            // Within RK4's error and rounding: 1e-11 of the distance and speed change.
            let (moved, sped) = ((y[0] - xi0).abs(), (y[1] - xi_dot0).abs());
            assert!(
                (exact.xi - y[0]).abs() < 1e-16 + 1e-11 * moved,
                "xi {} vs {}",
                exact.xi,
                y[0]
            );
            assert!(
                (exact.xi_dot - y[1]).abs() < 1e-14 + 1e-11 * sped,
                "xi' {} vs {}",
                exact.xi_dot,
                y[1]
            );
            let e_scale = y[2].abs().max(1e-300);
            assert!(
                (exact.e_lubricant - y[2]).abs() <= 1e-10 * e_scale,
                "E {} vs {}",
                exact.e_lubricant,
                y[2]
            );
        }
    }

    /// φ2's series agrees with the closed form (x − 1 + e^(−x))/x² on both sides of where it
    /// takes over (x = ½), where the closed form still has 13 good digits.
    #[test]
    fn phi2_series_meets_closed_form() {
        let closed = |x: f64| (x - 1.0 + (-x).exp()) / (x * x);
        for x in [0.49, 0.3, -0.3, -0.49, 0.5, 0.8] {
            assert!(
                (phi2(x) - closed(x)).abs() < 1e-14,
                "{x}: {} vs {}",
                phi2(x),
                closed(x)
            );
        }
        assert_eq!(phi2(0.0), 0.5);
    }
}
