//! Torque mode: the rattling gear pair with the main shaft a rigid inertia I_M driven by the
//! drivetrain's torque τ_in, as a piecewise-smooth ODE for the integrator. The equations
//! (docs/MODEL.md §3 with the shaft's own equation of [`MainShaft`]):
//!
//!   ω_L  = (ξ' + r_M ω_M) / r_L
//!   I_L ω_L' = B − r_L F − C (ω_L − ω_S)
//!   I_M ω_M' = τ_in + r_M F
//!   ξ''  = r_L ω_L' − r_M ω_M',   θ_M' = ω_M
//!
//! State: ξ, ξ' and θ_M, ω_M (under error control), then the quadratures of
//! [`crate::rattle::window::quadrature`]: E_contact, E_lubricant, the work
//! W_shaft = ∫ −τ_M ω_M dt the shaft feeds into the loose gear, ∫a² dt, ∫F dt and ∫F² dt.
//! The regions, edges and impact counts are those of the kinematic [`Rattle`](super::Rattle).
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

use super::window::{Window, quadrature};
use super::{Impacts, LOCAL_SHARE, contact_pieces, quadrature_rates, scales};
pub use super::{XI, XI_DOT};
use crate::integrator::{Jacobian, System, Tolerance};
use crate::physics::{Dynamics, Loads, MainShaft, Region, Shaft, TorqueRamp};

/// Components of the state vector after ξ, ξ' (the quadratures' meanings as in
/// [`crate::rattle`]).
pub const THETA_M: usize = 2;
pub const OMEGA_M: usize = 3;
pub const E_CONTACT: usize = 4;
pub const E_LUBRICANT: usize = E_CONTACT + quadrature::E_LUBRICANT;
pub const W_SHAFT: usize = E_CONTACT + quadrature::W_SHAFT;
pub const A2: usize = E_CONTACT + quadrature::A2;
pub const F1: usize = E_CONTACT + quadrature::F1;
pub const F2: usize = E_CONTACT + quadrature::F2;
pub const N: usize = E_CONTACT + quadrature::COUNT;

pub type State = [f64; N];

/// The torque-driven pair with its `N`-component state (the gear pairs' common code,
/// `contact_pieces!`, is written for any size).
pub type TorqueRattle = DrivenRattle<N>;

/// The gear pair, the region it is in, the main shaft's inertia and the torque driving it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DrivenRattle<const N: usize> {
    pub dynamics: Dynamics,
    pub main: MainShaft,
    pub region: Region,
    pub torque: TorqueRamp,
    pub impacts: Impacts,
    pub window: Window,
}

impl<const N: usize> DrivenRattle<N> {
    /// The pair at ξ, with no statistics window (one opens with
    /// [`GearPair::with_window`](super::GearPair::with_window)).
    pub fn new(dynamics: Dynamics, main: MainShaft, torque: TorqueRamp, xi: f64) -> Self {
        let region = dynamics.law.classify(xi);
        DrivenRattle {
            region,
            dynamics,
            main,
            torque,
            impacts: Impacts::default(),
            window: Window::closed(region),
        }
    }

    /// Error weights: ξ and ξ' as in [`Rattle::tolerance`](super::Rattle::tolerance); θ_M and
    /// ω_M on the same scales seen on the pitch line (divided by r_M), so that the shaft's
    /// error moves ξ no more than the gear's own.
    pub fn tolerance(&self, rtol: f64) -> Tolerance<N> {
        let rtol = rtol * LOCAL_SHARE;
        let (xi_scale, xi_dot_scale) = scales(&self.dynamics.params);
        let r_M = self.dynamics.params.r_M;
        let mut atol = [0.0; N];
        atol[..E_CONTACT].copy_from_slice(&[
            rtol * xi_scale,
            rtol * xi_dot_scale,
            rtol * xi_scale / r_M,
            rtol * xi_dot_scale / r_M,
        ]);
        Tolerance {
            rtol,
            atol,
            controlled: E_CONTACT,
        }
    }

    /// Loads on the gear pair and the main shaft's motion (with its acceleration) at (t, y).
    #[inline]
    pub fn loads(&self, t: f64, y: &[f64; N]) -> (Loads, Shaft) {
        self.dynamics.driven_loads(
            self.region,
            y[XI],
            y[XI_DOT],
            &self.main,
            y[THETA_M],
            y[OMEGA_M],
            self.torque.at(t),
        )
    }
}

impl<const N: usize> System<N> for DrivenRattle<N> {
    #[inline]
    fn rhs(&self, t: f64, y: &[f64; N]) -> [f64; N] {
        let (loads, shaft) = self.loads(t, y);
        let q = quadrature_rates(&self.dynamics.params, &loads, y[XI_DOT], shaft.omega);
        let mut f = [0.0; N];
        f[..E_CONTACT].copy_from_slice(&[y[XI_DOT], loads.xi_ddot, shaft.omega, shaft.alpha]);
        f[E_CONTACT..].copy_from_slice(&q[..N - E_CONTACT]);
        f
    }
}

impl<const N: usize> Jacobian<N> for DrivenRattle<N> {
    /// ∂f_i/∂y_j from the equations of the module with F_ξ = ∂F/∂ξ, F_v = ∂F/∂ξ'
    /// ([`ContactLaw::slopes`](crate::physics::ContactLaw::slopes)):
    /// ∂ξ''/∂ξ = −k F_ξ, ∂ξ''/∂ξ' = −k F_v − C/I_L, ∂ξ''/∂ω_M = −C r_M/I_L with
    /// k = r_L²/I_L + r_M²/I_M; ∂ω_M'/∂ξ = r_M F_ξ/I_M, ∂ω_M'/∂ξ' = r_M F_v/I_M; θ_M and the
    /// quadratures enter no right-hand side. The quadratures' rows follow from their rates.
    fn jacobian(&self, t: f64, y: &[f64; N]) -> [[f64; N]; N] {
        let p = &self.dynamics.params;
        let (xi, xi_dot, omega_M) = (y[XI], y[XI_DOT], y[OMEGA_M]);
        let (loads, _) = self.loads(t, y);
        let law = &self.dynamics.law;
        let f = law.slopes(self.region, xi, xi_dot);
        let fc = law.dissipative_slopes(self.region, xi, xi_dot);
        let (r_L, r_M, I_M) = (p.r_L, p.r_M, self.main.I_M);
        let k = r_L * r_L / p.I_L + r_M * r_M / I_M;
        let slip = loads.omega_L - p.omega_S;
        let force = loads.force.total();
        let mut j = [[0.0; N]; N];
        j[XI][XI_DOT] = 1.0;
        j[XI_DOT][XI] = -k * f.d_xi;
        j[XI_DOT][XI_DOT] = -k * f.d_xi_dot - p.C / p.I_L;
        j[XI_DOT][OMEGA_M] = -p.C * r_M / p.I_L;
        j[THETA_M][OMEGA_M] = 1.0;
        j[OMEGA_M][XI] = r_M * f.d_xi / I_M;
        j[OMEGA_M][XI_DOT] = r_M * f.d_xi_dot / I_M;
        // E_contact' = F_c ξ'
        j[E_CONTACT][XI] = fc.d_xi * xi_dot;
        j[E_CONTACT][XI_DOT] = fc.d_xi_dot * xi_dot + loads.force.dissipative;
        // E_lubricant' = C (ω_L − ω_S)², ω_L = (ξ' + r_M ω_M) / r_L
        j[E_LUBRICANT][XI_DOT] = 2.0 * p.C * slip / r_L;
        j[E_LUBRICANT][OMEGA_M] = 2.0 * p.C * slip * r_M / r_L;
        // W_shaft' = −r_M F ω_M
        j[W_SHAFT][XI] = -r_M * f.d_xi * omega_M;
        j[W_SHAFT][XI_DOT] = -r_M * f.d_xi_dot * omega_M;
        j[W_SHAFT][OMEGA_M] = -r_M * force;
        // (∫a²)' = a², a = r_L α_L = (r_L/I_L)(B − r_L F − C (ω_L − ω_S))
        let a = r_L * loads.alpha_L;
        let lever = r_L / p.I_L;
        let da = [
            -lever * r_L * f.d_xi,
            -lever * (r_L * f.d_xi_dot + p.C / r_L),
            -lever * p.C * r_M / r_L,
        ];
        // (∫F)' = F and (∫F²)' = F²
        let df = [f.d_xi, f.d_xi_dot, 0.0];
        for (col, (da, df)) in [XI, XI_DOT, OMEGA_M]
            .into_iter()
            .zip(da.into_iter().zip(df))
        {
            j[A2][col] = 2.0 * a * da;
            j[F1][col] = df;
            j[F2][col] = 2.0 * force * df;
        }
        j
    }
}

contact_pieces!(
    DrivenRattle,
    fn shaft(&self, t: f64, y: &[f64; N]) -> Shaft {
        self.loads(t, y).1
    }
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::GearParams;

    /// Every term of the Jacobian against central differences of the right-hand side, in
    /// each region, with every parameter that enters it switched on (drag, carrier speed,
    /// external torque, contact damping, a torque ramp).
    #[test]
    fn jacobian_matches_finite_differences() {
        for alpha in [1.0, 4.0 / 3.0, 1.5] {
            let params = GearParams {
                alpha,
                B: 0.3,
                omega_S: 12.0,
                ..GearParams::paper()
            };
            let torque = TorqueRamp {
                t0: 0.01,
                tau0: 2.0,
                rate: -40.0,
            };
            let main = MainShaft { I_M: 0.008 };
            let g = params.G;
            for xi in [-3e-6, -0.6e-6, 10e-6, g + 0.3e-6, g + 4e-6] {
                let sys = TorqueRattle::new(Dynamics::new(params), main, torque, xi);
                let (t, y) = (0.0123, [xi, 0.013, 4.5, 83.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6]);
                let j = sys.jacobian(t, &y);
                let scale = [1e-12, 1e-8, 1e-6, 1e-6, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3];
                for col in 0..N {
                    let (mut up, mut down) = (y, y);
                    up[col] += scale[col];
                    down[col] -= scale[col];
                    let (fu, fd) = (sys.rhs(t, &up), sys.rhs(t, &down));
                    for row in 0..N {
                        let fdiff = (fu[row] - fd[row]) / (2.0 * scale[col]);
                        let tol = 1e-6 * fdiff.abs().max(j[row][col].abs()) + 1e-9;
                        assert!(
                            (j[row][col] - fdiff).abs() <= tol,
                            "alpha {alpha} xi {xi:e} ∂f{row}/∂y{col}: {} against {fdiff}",
                            j[row][col]
                        );
                    }
                }
            }
        }
    }

    /// With a very heavy shaft driven by I_M a_M(t), the torque mode moves the shaft as the
    /// imposed motion would, and its right-hand side for ξ is the kinematic one.
    #[test]
    fn heavy_shaft_follows_its_torque() {
        let params = GearParams::paper();
        let main = MainShaft { I_M: 1e9 };
        let torque = TorqueRamp {
            t0: 0.0,
            tau0: 3e11,
            rate: 0.0,
        };
        let sys = TorqueRattle::new(Dynamics::new(params), main, torque, -2e-6);
        let mut y = [0.0; N];
        y[..4].copy_from_slice(&[-2e-6, 0.01, 1.0, 50.0]);
        let f = sys.rhs(0.0, &y);
        assert_eq!(f[THETA_M], 50.0);
        assert!((f[OMEGA_M] - 300.0).abs() < 1e-6);
        let shaft = Shaft {
            theta: 1.0,
            omega: 50.0,
            alpha: 300.0,
        };
        let kinematic = sys
            .dynamics
            .loads(Region::ContactPlus, y[XI], y[XI_DOT], &shaft);
        assert!((f[XI_DOT] - kinematic.xi_ddot).abs() < 1e-6 * kinematic.xi_ddot.abs());
    }
}
