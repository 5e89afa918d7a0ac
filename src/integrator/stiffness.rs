//! When a problem is stiff for DOPRI5, and when it no longer is: the rule of [`Method::Auto`]
//! (see `solver`).
//!
//! - explicit → implicit: Hairer's DOPRI5 estimate of h·ρ from its last two stages
//!   ([`stiffness`]), stiff after 5 accepted steps above a threshold ([`StiffnessDetector`];
//!   the estimate weighed by the tolerance scales and the threshold lowered from 3.25 to 2,
//!   see [`STIFF_H_RHO`]);
//! - implicit → explicit: h·ρ(J) with the spectral radius of Radau's Jacobian
//!   ([`spectral_radius`]) and the step size Radau proposes, at most the same threshold on 5
//!   accepted steps in a row: DOPRI5 could then take those steps stably.
//!
//! [`Method::Auto`]: super::solver::Method::Auto

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::control::Tolerance;
use super::dopri5;
use super::options::OPTIONS;

/// Spectral radius max |λ| of a Jacobian (infinite if J is not finite). With the step size h
/// of the implicit method, h·ρ(J) tells whether DOPRI5 could take that step stably (its
/// stability interval on the negative real axis is about [−3.3, 0]).
///
/// A component that no derivative depends on (a zero column of J, the quadratures of an
/// energy) adds the eigenvalue 0 and leaves the others those of J without its row and column
/// (expand det(λI − J) along that column): ρ is taken on the rest, in closed form for one or
/// two components (a gear pair's ξ, ξ'), else by a Schur decomposition. It is taken at every
/// new Jacobian, which Radau IIA evaluates at most steps of a stiff contact.
pub fn spectral_radius<const N: usize>(j: &[[f64; N]; N]) -> f64 {
    if j.iter().flatten().any(|v| !v.is_finite()) {
        return f64::INFINITY;
    }
    let mut live = [0; N];
    let mut n = 0;
    for c in 0..N {
        if j.iter().any(|row| row[c] != 0.0) {
            live[n] = c;
            n += 1;
        }
    }
    let at = |r: usize, c: usize| j[live[r]][live[c]];
    match n {
        0 => 0.0,
        1 => at(0, 0).abs(),
        2 => {
            // λ = tr/2 ± √disc: real when disc ≥ 0, else a conjugate pair with |λ|² = det.
            let half_trace = 0.5 * (at(0, 0) + at(1, 1));
            let half_diff = 0.5 * (at(0, 0) - at(1, 1));
            let disc = half_diff * half_diff + at(0, 1) * at(1, 0);
            if disc >= 0.0 {
                half_trace.abs() + disc.sqrt()
            } else {
                (at(0, 0) * at(1, 1) - at(0, 1) * at(1, 0)).sqrt()
            }
        }
        _ => DMatrix::from_fn(n, n, at)
            .complex_eigenvalues()
            .iter()
            .map(|l| l.norm())
            .fold(0.0, f64::max),
    }
}

/// Hairer's stiffness estimate from an explicit DOPRI5 step: h·ρ ≈ h·‖k7 − k6‖ / ‖y1 − y6‖
/// (both stages at t + h), in the tolerance's weighted norm over its controlled components.
/// Hairer's DOPRI5 takes the plain Euclidean norm; with components of unlike units (a
/// position and a velocity) that estimate sees the singular values of J rather than its
/// eigenvalues (from 1 to k for x'' = −k x) and missed a resting stiff contact entirely;
/// weighed by the tolerance scales (atol of a velocity = atol of the position × the contact
/// frequency, as `Rattle::tolerance` sets them) it sees |λ|. 0 when y1 = y6.
pub fn stiffness<const N: usize>(trial: &dopri5::Trial<N>, tol: &Tolerance<N>) -> f64 {
    let (y6, k6) = trial.stage6();
    let k7 = trial.k_end();
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..tol.controlled {
        let scale = tol.atol[i] + tol.rtol * trial.y0[i].abs().max(trial.y1[i].abs());
        num += ((k7[i] - k6[i]) / scale).powi(2);
        den += ((trial.y1[i] - y6[i]) / scale).powi(2);
    }
    if den > 0.0 {
        trial.h * (num / den).sqrt()
    } else {
        0.0
    }
}

/// The threshold of h·ρ, both ways ([`OPTIONS`]`.stiff_h_rho`). An accepted step with
/// h·|λ| > 2 leaves that mode an error of about (h·|λ|)⁶/720 ≈ 9 % of its amplitude per step:
/// it is accepted only when the mode has died out, which is what stiffness means.
pub const STIFF_H_RHO: f64 = OPTIONS.stiff_h_rho;
/// Stiff verdicts (not interrupted by `CALM_STEPS` non-stiff ones in a row) that make a
/// problem stiff.
pub const STIFF_STEPS: u32 = OPTIONS.stiff_steps;
const CALM_STEPS: u32 = OPTIONS.calm_steps;

/// Hairer's DOPRI5 switching rule, fed with [`stiffness`] of each accepted step: stiff after
/// [`STIFF_STEPS`] (5) verdicts h·ρ > [`STIFF_H_RHO`], the count restarting after 6 non-stiff
/// verdicts in a row.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StiffnessDetector {
    stiff: u32,
    calm: u32,
}

impl StiffnessDetector {
    /// Records one accepted step's h·ρ; true when the problem is now judged stiff.
    pub fn observe(&mut self, h_rho: f64) -> bool {
        if h_rho > STIFF_H_RHO {
            self.calm = 0;
            self.stiff += 1;
            self.stiff >= STIFF_STEPS
        } else {
            self.calm += 1;
            if self.calm >= CALM_STEPS {
                self.stiff = 0;
            }
            false
        }
    }
}

/// Both directions of the hand-over, with their memories (part of the solver's state).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Switch {
    detector: StiffnessDetector,
    /// Accepted implicit steps in a row that DOPRI5 could have taken stably.
    calm: u32,
}

impl Switch {
    /// After an accepted DOPRI5 step with its [`stiffness`] estimate: true to go implicit.
    pub fn to_implicit(&mut self, h_rho: f64) -> bool {
        let stiff = self.detector.observe(h_rho);
        if stiff {
            *self = Switch::default();
        }
        stiff
    }

    /// After an accepted Radau IIA step, with h·ρ(J) for the step size it proposes next:
    /// true to go back to DOPRI5.
    pub fn to_explicit(&mut self, h_rho: f64) -> bool {
        self.calm = if h_rho <= STIFF_H_RHO {
            self.calm + 1
        } else {
            0
        };
        let calm = self.calm >= STIFF_STEPS;
        if calm {
            *self = Switch::default();
        }
        calm
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::System;
    use crate::integrator::control::Controller;
    use crate::integrator::test_systems::{Linear, tolerance};

    #[test]
    fn stiffness_estimate_of_dopri5() {
        // Scalar y' = λ y: k7 − k6 = λ (y1 − y6) exactly.
        struct Scalar(f64);
        impl System<1> for Scalar {
            fn rhs(&self, _: f64, y: &[f64; 1]) -> [f64; 1] {
                [self.0 * y[0]]
            }
        }
        let mut trial = dopri5::Trial::empty();
        dopri5::step(&Scalar(-300.0), 0.0, &[1.0], &[-300.0], 0.01, 1, &mut trial);
        assert!((stiffness(&trial, &tolerance(1e-6, [1e-6])) - 3.0).abs() < 1e-12);

        // The stiff linear system under DOPRI5 with its own controller: once the fast mode has
        // died out the steps hover at the stability limit and the detector fires.
        let tol = tolerance(1e-6, [1e-6; 2]);
        let mut controller = Controller::default();
        let mut detector = StiffnessDetector::default();
        let (mut t, mut y, mut h) = (0.0, [1.0, 0.0], 1e-7);
        let mut k1 = Linear.rhs(t, &y);
        let mut accepted = 0;
        let mut fired_at = None;
        while t < 1e-3 && fired_at.is_none() {
            let mut trial = dopri5::Trial::empty();
            dopri5::step(&Linear, t, &y, &k1, h, 2, &mut trial);
            let verdict = controller.judge(tol.norm(&trial.y0, &trial.y1, &trial.err), h);
            if verdict.accept {
                accepted += 1;
                t += h;
                y = trial.y1;
                k1 = *trial.k_end();
                if detector.observe(stiffness(&trial, &tol)) {
                    fired_at = Some((t, accepted, stiffness(&trial, &tol)));
                }
            }
            h = verdict.h_next;
        }
        println!("DOPRI5 on λ = −1, −1e6: judged stiff at (t, steps, h·ρ) = {fired_at:?}");
        let (t, steps, h_rho) = fired_at.expect("stiffness not detected");
        assert!(t < 1e-4 && steps < 100, "{t} {steps}");
        assert!((2.0..4.0).contains(&h_rho));
    }

    #[test]
    fn spectral_radius_of_a_contact_jacobian() {
        let k: f64 = 1e10;
        let c = 0.4 * k.sqrt();
        let rho = spectral_radius(&[[0.0, 1.0], [-k, -c]]);
        assert!((rho / k.sqrt() - 1.0).abs() < 1e-12, "{rho}");
        let rho = spectral_radius(&Linear::A);
        assert!((rho / 1e6 - 1.0).abs() < 1e-9, "{rho}");
        assert_eq!(spectral_radius(&[[f64::NAN]]), f64::INFINITY);
        // A quadrature (a zero column) leaves the pair's ρ; a third coupled component goes
        // through the Schur decomposition.
        let quadrature = [[0.0, 1.0, 0.0], [-k, -c, 0.0], [1.0, c, 0.0]];
        assert!((spectral_radius(&quadrature) / k.sqrt() - 1.0).abs() < 1e-12);
        let [[a, b], [d, e]] = Linear::A;
        let coupled = [[a, b, 0.0], [d, e, 0.0], [1.0, 1.0, -5.0]];
        assert!((spectral_radius(&coupled) / 1e6 - 1.0).abs() < 1e-9);
    }
}
