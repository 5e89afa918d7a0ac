//! Motion of the main shaft (docs/MODEL.md §5): the paper's bench sine, or a polynomial
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
    /// A/w and A/w², the amplitudes of ω_M and θ_M, divided once here rather than at every
    /// right-hand side and every point of a free flight.
    a_over_w: f64,
    a_over_w2: f64,
}

impl Sine {
    pub fn new(a_rms: f64, f_exc: f64, omega_mean: f64) -> Self {
        let (amplitude, w) = (SQRT_2 * a_rms, 2.0 * PI * f_exc);
        Sine {
            amplitude,
            w,
            omega_mean,
            a_over_w: amplitude / w,
            a_over_w2: amplitude / w / w,
        }
    }

    /// Exact θ_M = ω̄ t − A/w² sin(wt), ω_M = ω̄ − A/w cos(wt), a_M = A sin(wt).
    #[inline]
    pub fn at(&self, t: f64) -> Shaft {
        let (sin, cos) = crate::math::sin_cos(self.w * t);
        Shaft {
            theta: self.omega_mean * t - self.a_over_w2 * sin,
            omega: self.omega_mean - self.a_over_w * cos,
            alpha: self.amplitude * sin,
        }
    }
}

/// The main shaft over an interval [t0, t1] (its start in [`SpanStart`]): its speed at t1 and
/// the angle turned, computed as a difference of motion, not of two large angles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Span {
    pub omega1: f64,
    /// θ_M(t1) − θ_M(t0) [rad].
    pub angle: f64,
}

/// What every span from t0 shares: the shaft's speed there and, for the sine, sin(w t0).
/// Computed once for the many spans of a free flight ([`Excitation::span_from`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpanStart {
    pub t0: f64,
    pub omega0: f64,
    sin0: f64,
}

impl Sine {
    /// ω_M(t0), and sin(w t0) for the angle.
    fn span_start(&self, t0: f64) -> SpanStart {
        let (sin0, cos0) = crate::math::sin_cos(self.w * t0);
        SpanStart {
            t0,
            omega0: self.omega_mean - self.a_over_w * cos0,
            sin0,
        }
    }

    /// ω_M at t1, and θ_M(t1) − θ_M(t0) = ω̄ (t1 − t0) − A/w² (sin wt1 − sin wt0): one sine
    /// and cosine.
    fn span_from(&self, start: &SpanStart, t1: f64) -> Span {
        let (s1, c1) = crate::math::sin_cos(self.w * t1);
        Span {
            omega1: self.omega_mean - self.a_over_w * c1,
            angle: self.omega_mean * (t1 - start.t0) - self.a_over_w2 * (s1 - start.sin0),
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

    /// What the spans from t0 share (see [`SpanStart`]).
    pub fn span_start(&self, t0: f64) -> SpanStart {
        match self {
            Excitation::Sine(s) => s.span_start(t0),
            Excitation::Polynomial(p) => SpanStart {
                t0,
                omega0: p.at(t0).omega,
                sin0: 0.0,
            },
        }
    }

    /// The shaft over [start.t0, t1].
    pub fn span_from(&self, start: &SpanStart, t1: f64) -> Span {
        match self {
            Excitation::Sine(s) => s.span_from(start, t1),
            Excitation::Polynomial(p) => {
                let (a, b) = (start.t0 - p.t0, t1 - p.t0);
                let s = &p.at_t0;
                Span {
                    omega1: s.omega + b * s.alpha,
                    angle: (b - a) * (s.omega + 0.5 * s.alpha * (a + b)),
                }
            }
        }
    }

    /// Taylor coefficients about t of ω_M and a_M, to M terms: for the sine, the k-th
    /// derivatives of ω̄ − A/w cos(wt) and A sin(wt) over k!; the polynomial's are exact.
    pub fn series<const M: usize>(&self, t: f64) -> ([f64; M], [f64; M]) {
        const { assert!(M < crate::math::INVERSES.len()) };
        let (mut omega, mut alpha) = ([0.0; M], [0.0; M]);
        match self {
            Excitation::Sine(s) => {
                let (sin, cos) = crate::math::sin_cos(s.w * t);
                // sin and cos of wt + kπ/2, k = 0..3.
                let quarter = [(sin, cos), (cos, -sin), (-sin, -cos), (-cos, sin)];
                let mut scale = 1.0; // w^k / k!
                for k in 0..M {
                    let (sin_k, cos_k) = quarter[k % 4];
                    omega[k] = -s.a_over_w * scale * cos_k;
                    alpha[k] = s.amplitude * scale * sin_k;
                    scale *= s.w * crate::math::INVERSES[k + 1];
                }
                omega[0] += s.omega_mean;
            }
            Excitation::Polynomial(p) => {
                let now = p.at(t);
                omega[0] = now.omega;
                alpha[0] = now.alpha;
                if M > 1 {
                    omega[1] = now.alpha;
                }
            }
        }
        (omega, alpha)
    }

    /// The largest |a_M| at any time: A for the sine, |α| for the polynomial.
    pub fn max_acceleration(&self) -> f64 {
        match self {
            Excitation::Sine(s) => s.amplitude.abs(),
            Excitation::Polynomial(p) => p.at_t0.alpha.abs(),
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

    /// A span's speeds are those of `at`, and its angle the difference of the angles, for
    /// both excitations.
    #[test]
    fn span_is_a_difference_of_motion() {
        let sine = Excitation::Sine(Sine::new(300.0, 30.0, 84.0));
        let poly = Excitation::Polynomial(Polynomial {
            t0: 0.2,
            at_t0: Shaft {
                theta: 1.0,
                omega: -40.0,
                alpha: 900.0,
            },
        });
        for e in [sine, poly] {
            let (t0, t1) = (0.2031, 0.2107);
            let start = e.span_start(t0);
            let span = e.span_from(&start, t1);
            let diff = e.at(t1).theta - e.at(t0).theta;
            assert!((span.angle - diff).abs() < 1e-13, "{e:?}");
            assert_eq!(start.omega0, e.at(t0).omega);
            assert_eq!(span.omega1, e.at(t1).omega);
        }
    }
}
