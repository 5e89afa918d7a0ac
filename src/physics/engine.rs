//! The built-in engine that drives the flywheel (docs/GEARBOX.md §4): a mean speed Ω, optionally
//! ramped at a constant rate Ω', with two engine orders of angular-acceleration amplitudes
//! a_k:
//!
//!   α_F(t) = Ω' + Σ_k a_k cos ψ_k(t),   ψ_k = n_k (Ω t + Ω' t²/2) + phase_k
//!
//! from ω_F(0) = Ω + Σ_k a_k/(n_k Ω) sin phase_k and θ_F(0) = 0. At a steady speed (Ω' = 0)
//! ω_F and θ_F have the exact closed form of [`Engine::steady_at`]; under a ramp their
//! integrals are Fresnel integrals, for which there is no closed form here: the system
//! integrates ω_F and θ_F as states from [`Engine::alpha`].

use serde::{Deserialize, Serialize};

use super::Shaft;

/// One engine order: ψ = n (Ω t + Ω' t²/2) + phase, amplitude a [rad/s²].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct EngineOrder {
    /// The order n (the firing order of a four-stroke engine with z cylinders is z/2).
    pub n: f64,
    /// Angular-acceleration amplitude a [rad/s²].
    pub a: f64,
    /// Phase [rad].
    pub phase: f64,
}

/// The engine's parameters (docs/GEARBOX.md §4, §6).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct EngineParams {
    /// Mean speed at t = 0 [rpm].
    pub rpm: f64,
    /// Ramp of the mean speed [rpm/s] (0: steady).
    pub rpm_rate: f64,
    pub orders: [EngineOrder; 2],
}

impl EngineParams {
    /// docs/GEARBOX.md §6: 800 rpm, four cylinders, order 2 at 600 rad/s², order 4 at 120 rad/s².
    pub fn idle() -> Self {
        EngineParams {
            rpm: 800.0,
            rpm_rate: 0.0,
            orders: [
                EngineOrder {
                    n: 2.0,
                    a: 600.0,
                    phase: 0.0,
                },
                EngineOrder {
                    n: 4.0,
                    a: 120.0,
                    phase: 0.0,
                },
            ],
        }
    }
}

/// rpm to rad/s.
const RPM: f64 = std::f64::consts::PI / 30.0;

/// The engine's motion in SI units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Engine {
    /// Ω at t = 0 [rad/s] and its ramp Ω' [rad/s²].
    omega: f64,
    ramp: f64,
    orders: [EngineOrder; 2],
}

impl Engine {
    pub fn new(p: &EngineParams) -> Self {
        Engine {
            omega: p.rpm * RPM,
            ramp: p.rpm_rate * RPM,
            orders: p.orders,
        }
    }

    /// Whether the mean speed is steady (no ramp): ω_F and θ_F then in closed form.
    pub fn is_steady(&self) -> bool {
        self.ramp == 0.0
    }

    /// α_F(t) = Ω' + Σ a_k cos ψ_k(t).
    #[inline]
    pub fn alpha(&self, t: f64) -> f64 {
        let turned = self.omega * t + 0.5 * self.ramp * t * t;
        self.ramp
            + self
                .orders
                .iter()
                .map(|o| o.a * (o.n * turned + o.phase).cos())
                .sum::<f64>()
    }

    /// ω_F(0) = Ω + Σ a_k/(n_k Ω) sin phase_k: the speed about which the orders oscillate
    /// with a zero mean.
    pub fn omega_start(&self) -> f64 {
        self.omega
            + self
                .orders
                .iter()
                .map(|o| o.a / (o.n * self.omega) * o.phase.sin())
                .sum::<f64>()
    }

    /// At a steady speed, θ_F, ω_F and α_F at t exactly: with ψ_k = n_k Ω t + phase_k,
    /// ω_F = Ω + Σ a_k/(n_k Ω) sin ψ_k and θ_F = Ω t − Σ a_k/(n_k Ω)² (cos ψ_k − cos phase_k).
    /// None under a ramp.
    #[inline]
    pub fn steady_at(&self, t: f64) -> Option<Shaft> {
        if !self.is_steady() {
            return None;
        }
        let mut shaft = Shaft {
            theta: self.omega * t,
            omega: self.omega,
            alpha: 0.0,
        };
        for o in &self.orders {
            let w = o.n * self.omega;
            let (sin, cos) = (w * t + o.phase).sin_cos();
            shaft.theta -= o.a / (w * w) * (cos - o.phase.cos());
            shaft.omega += o.a / w * sin;
            shaft.alpha += o.a * cos;
        }
        Some(shaft)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn engine(rpm_rate: f64) -> Engine {
        let mut p = EngineParams::idle();
        p.rpm_rate = rpm_rate;
        p.orders[0].phase = 0.7;
        p.orders[1].phase = -1.9;
        Engine::new(&p)
    }

    /// The steady closed form starts at θ_F = 0, ω_F(0), and its ω_F and θ_F are the
    /// integrals of α_F and ω_F (Simpson's rule over 0.3 s in 30 000 steps).
    #[test]
    fn steady_closed_form_integrates_alpha() {
        let e = engine(0.0);
        let s0 = e.steady_at(0.0).expect("steady");
        assert_eq!(s0.theta, 0.0);
        assert!((s0.omega - e.omega_start()).abs() < 1e-12);
        let (n, t1) = (30_000, 0.3);
        let h = t1 / n as f64;
        let simpson = |f: &dyn Fn(f64) -> f64| {
            (0..n)
                .map(|k| {
                    let t = k as f64 * h;
                    h / 6.0 * (f(t) + 4.0 * f(t + 0.5 * h) + f(t + h))
                })
                .sum::<f64>()
        };
        let s1 = e.steady_at(t1).expect("steady");
        let d_omega = simpson(&|t| e.alpha(t));
        assert!((s1.omega - s0.omega - d_omega).abs() < 1e-9, "{d_omega}");
        let theta = simpson(&|t| e.steady_at(t).unwrap().omega);
        assert!((s1.theta - theta).abs() < 1e-9, "{theta}");
        for t in [0.0, 0.013, 0.29] {
            assert_eq!(e.steady_at(t).unwrap().alpha, e.alpha(t));
        }
    }

    /// Under a ramp: no closed form, and α_F by hand at t = 0 and 1 s (1200 rpm/s = 40π
    /// rad/s², ψ_k(1) = n_k (Ω + Ω'/2) + phase_k).
    #[test]
    fn ramp_by_hand() {
        let e = engine(1200.0);
        assert!(e.steady_at(0.1).is_none());
        let ramp = 40.0 * std::f64::consts::PI;
        let a0 = ramp + 600.0 * 0.7f64.cos() + 120.0 * (-1.9f64).cos();
        assert!((e.alpha(0.0) - a0).abs() < 1e-9);
        let turned = 800.0 * RPM + 0.5 * ramp;
        let a1 = ramp + 600.0 * (2.0 * turned + 0.7).cos() + 120.0 * (4.0 * turned - 1.9).cos();
        assert!((e.alpha(1.0) - a1).abs() < 1e-9);
    }
}
