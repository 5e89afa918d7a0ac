//! Taylor coefficients of the motion in full contact (MODEL.md §2-3), for the integrator's
//! Taylor steps. There s = 1 and the penetration δ stays at least ε away from the kink of
//! δ|δ|^(α−1) at δ = 0, so the solution is analytic and its coefficients follow one from
//! another:
//!
//! - u = |δ|/G > 0 and v = u^α: u v' = α u' v, hence k u₀ v_k = Σ_{j=1..k} (α j − (k − j)) u_j v_{k−j};
//! - F_k = ±K* G v_k (the elastic force, + on F−) plus C_LM (k+1) ξ_{k+1};
//! - ξ'' = (r_L B − r_L² F − C (ξ' + r_M ω_M − r_L ω_S)) / I_L − r_M a_M (MODEL.md §3 with
//!   ω_L = (ξ' + r_M ω_M)/r_L) gives ξ_{k+2} = ξ''_k / ((k+1)(k+2)).
#![allow(non_snake_case)]

use super::{Dynamics, Excitation, Region};

/// Coefficients about t of the motion in full contact: ξ to M terms, F and ω_M to M − 2
/// (the rest left 0), so that ξ and ξ' and the power flows come to M − 1 terms.
pub struct ContactSeries<const M: usize> {
    pub xi: [f64; M],
    /// Contact force F = F_k + F_c [N].
    pub force: [f64; M],
    /// The main shaft's speed ω_M [rad/s].
    pub omega_M: [f64; M],
}

impl<const M: usize> ContactSeries<M> {
    /// The series about (t, ξ, ξ') in `region`, None outside full contact or where δ = 0.
    pub fn new(
        dynamics: &Dynamics,
        excitation: &Excitation,
        region: Region,
        t: f64,
        xi: f64,
        xi_dot: f64,
    ) -> Option<Self> {
        let p = &dynamics.params;
        // δ = σ G u: σ = −1 on F+ (δ = ξ), +1 on F− (δ = ξ − G).
        let (sigma, offset) = match region {
            Region::ContactPlus => (-1.0, 0.0),
            Region::ContactMinus => (1.0, p.G),
            _ => return None,
        };
        let u0 = sigma * (xi - offset) / p.G;
        if u0 <= 0.0 {
            return None;
        }
        let (omega_M, a_M) = excitation.series::<M>(t);
        let (lever, drag) = (p.r_L * p.r_L / p.I_L, p.C / p.I_L);
        let constant = (p.r_L * p.B + p.C * p.r_L * p.omega_S) / p.I_L;
        let mut s = ContactSeries {
            xi: [0.0; M],
            force: [0.0; M],
            omega_M,
        };
        s.xi[0] = xi;
        s.xi[1] = xi_dot;
        // v = u^α through the contact law's own v₀, so that the first term is the force the
        // right-hand side gives.
        let elastic0 = dynamics.law.force(region, xi, xi_dot).elastic;
        let scale = sigma * p.K_star * p.G;
        let (mut u, mut v) = ([0.0; M], [0.0; M]);
        let (sigma_over_G, inv_u0) = (sigma / p.G, 1.0 / u0);
        u[0] = u0;
        v[0] = elastic0 / scale;
        for k in 0..M - 2 {
            if k > 0 {
                u[k] = sigma_over_G * s.xi[k];
                let mut acc = 0.0;
                for j in 1..=k {
                    acc += (p.alpha * j as f64 - (k - j) as f64) * u[j] * v[k - j];
                }
                v[k] = acc * inv_u0 / k as f64;
            }
            let rate = (k + 1) as f64 * s.xi[k + 1];
            s.force[k] = scale * v[k] + p.C_LM * rate;
            let mut xi_ddot =
                -lever * s.force[k] - drag * (rate + p.r_M * omega_M[k]) - p.r_M * a_M[k];
            if k == 0 {
                xi_ddot += constant;
            }
            s.xi[k + 2] = xi_ddot / ((k + 1) * (k + 2)) as f64;
        }
        Some(s)
    }
}
