//! Motion of the main shaft (MODEL.md §5): the paper's bench sine, or a polynomial
//! extrapolation of the drivetrain's inputs over a communication step; in torque mode, the
//! drivetrain's torque on the shaft, extrapolated linearly over the step.

use serde::{Deserialize, Serialize};

use std::f64::consts::{PI, SQRT_2};

/// Angle θ_M [rad], speed ω_M [rad/s] and angular acceleration a_M [rad/s²] of the main shaft.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Shaft {
    pub theta: f64,
    pub omega: f64,
    pub alpha: f64,
}

/// The bench: a_M = A sin(2πf t), A = √2 A_rms, on top of a constant mean speed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sine {
    amplitude: f64,
    w: f64,
    omega_mean: f64,
}

impl Sine {
    pub fn new(a_rms: f64, f_exc: f64, omega_mean: f64) -> Self {
        Sine {
            amplitude: SQRT_2 * a_rms,
            w: 2.0 * PI * f_exc,
            omega_mean,
        }
    }

    /// Exact θ_M = ω̄ t − A/w² sin(wt), ω_M = ω̄ − A/w cos(wt), a_M = A sin(wt).
    #[inline]
    pub fn at(&self, t: f64) -> Shaft {
        let (sin, cos) = crate::math::sin_cos(self.w * t);
        let a_over_w = self.amplitude / self.w;
        Shaft {
            theta: self.omega_mean * t - a_over_w / self.w * sin,
            omega: self.omega_mean - a_over_w * cos,
            alpha: self.amplitude * sin,
        }
    }
}

/// Taylor polynomial of the main shaft about t0: θ0 + ω0 τ + α0 τ²/2 (τ = t − t0).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Polynomial {
    pub t0: f64,
    pub at_t0: Shaft,
}

impl Polynomial {
    #[inline]
    pub fn at(&self, t: f64) -> Shaft {
        let tau = t - self.t0;
        let s = &self.at_t0;
        Shaft {
            theta: s.theta + tau * (s.omega + 0.5 * tau * s.alpha),
            omega: s.omega + tau * s.alpha,
            alpha: s.alpha,
        }
    }
}

/// Torque mode: the torque τ_in the drivetrain applies to the main shaft, τ0 + τ̇ (t − t0)
/// over a step (τ̇ from fmi2SetRealInputDerivatives, else 0: a hold).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TorqueRamp {
    pub t0: f64,
    /// τ_in at t0 [N m].
    pub tau0: f64,
    /// dτ_in/dt [N m/s].
    pub rate: f64,
}

impl TorqueRamp {
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        self.tau0 + self.rate * (t - self.t0)
    }
}

/// What drives the main shaft.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Excitation {
    Sine(Sine),
    Polynomial(Polynomial),
}

impl Excitation {
    #[inline]
    pub fn at(&self, t: f64) -> Shaft {
        match self {
            Excitation::Sine(s) => s.at(t),
            Excitation::Polynomial(p) => p.at(t),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// θ, ω, a of the sine are consistent derivatives (central differences).
    #[test]
    fn sine_derivatives_are_consistent() {
        let s = Sine::new(300.0, 30.0, 84.0);
        let h = 1e-6;
        for t in [0.0, 0.0123, 0.5] {
            let (m, p, c) = (s.at(t - h), s.at(t + h), s.at(t));
            assert!(((p.theta - m.theta) / (2.0 * h) - c.omega).abs() < 1e-6);
            assert!(((p.omega - m.omega) / (2.0 * h) - c.alpha).abs() < 1e-4);
        }
        assert_eq!(s.at(0.0).alpha, 0.0);
    }
}
