//! Taylor coefficients of the motion in full contact (docs/MODEL.md §2-3), for the integrator's
//! Taylor steps. There s = 1 and the penetration δ stays at least ε away from the kink of
//! δ|δ|^(α−1) at δ = 0, so the solution is analytic and its coefficients follow one from
//! another:
//!
//! - u = |δ|/G > 0 and v = u^α: u v' = α u' v, hence k u₀ v_k = Σ_{j=1..k} (α j − (k − j)) u_j v_{k−j}
//!   = (α + 1) Σ j u_j v_{k−j} − k Σ u_j v_{k−j};
//! - F_k = ±K* G v_k (the elastic force, + on F−) plus C_LM (k+1) ξ_{k+1};
//! - ξ'' = (r_L B − r_L² F − C (ξ' + r_M ω_M − r_L ω_S)) / I_L − r_M a_M (docs/MODEL.md §3 with
//!   ω_L = (ξ' + r_M ω_M)/r_L) gives ξ_{k+2} = ξ''_k / ((k+1)(k+2)).
#![allow(non_snake_case)]

use super::{Dynamics, Excitation, Region};
use crate::math::INVERSES;

/// Coefficients about t of the motion in full contact: ξ and ω_M to M terms, F to M − 2 (the
/// rest left 0), so that ξ' and the power flows come to M − 1 terms.
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
        const { assert!(M < INVERSES.len()) };
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
        // ju_j = j u_j; no division on the terms' chain (INVERSES).
        let (mut u, mut ju, mut v) = ([0.0; M], [0.0; M], [0.0; M]);
        let (sigma_over_G, inv_u0, alpha_plus_1) = (sigma / p.G, 1.0 / u0, p.alpha + 1.0);
        u[0] = u0;
        v[0] = elastic0 / scale;
        for k in 0..M - 2 {
            if k > 0 {
                u[k] = sigma_over_G * s.xi[k];
                ju[k] = k as f64 * u[k];
                v[k] = power_term(alpha_plus_1, &u, &ju, &v, k, inv_u0);
            }
            let rate = (k + 1) as f64 * s.xi[k + 1];
            s.force[k] = scale * v[k] + p.C_LM * rate;
            let mut xi_ddot =
                -lever * s.force[k] - drag * (rate + p.r_M * omega_M[k]) - p.r_M * a_M[k];
            if k == 0 {
                xi_ddot += constant;
            }
            s.xi[k + 2] = xi_ddot * (INVERSES[k + 1] * INVERSES[k + 2]);
        }
        Some(s)
    }
}

/// The term k ≥ 1 of v = u^a from u's terms 0..=k (and j u_j) and v's 0..k, given a + 1 and
/// 1/u₀: v_k = ((a + 1)/k Σ_{j=1..k} j u_j v_{k−j} − Σ_{j=1..k} u_j v_{k−j}) / u₀, from
/// u v' = a u' v; two independent sums of products, no division. The sums take v_{k−1}, the
/// newest term, last, so that they run while it is still being formed.
#[inline]
fn power_term(a_plus_1: f64, u: &[f64], ju: &[f64], v: &[f64], k: usize, inv_u0: f64) -> f64 {
    let (mut weighted, mut plain) = (0.0, 0.0);
    for j in (1..=k).rev() {
        weighted += ju[j] * v[k - j];
        plain += u[j] * v[k - j];
    }
    (a_plus_1 * INVERSES[k] * weighted - plain) * inv_u0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{GearParams, Sine};

    /// (2 + 3τ)^a for a = 4/3, 3/2, 1 and 10/9: the terms are 2^a C(a, k) (3/2)^k.
    #[test]
    fn power_terms_are_binomial() {
        for a in [4.0 / 3.0, 1.5, 1.0, 10.0 / 9.0] {
            let u = [2.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
            let ju: [f64; 12] = std::array::from_fn(|j| j as f64 * u[j]);
            let mut v = [0.0; 12];
            v[0] = 2f64.powf(a);
            let mut binomial = v[0];
            for k in 1..12 {
                v[k] = power_term(a + 1.0, &u, &ju, &v, k, 0.5);
                binomial *= (a - (k - 1) as f64) / k as f64 * 1.5;
                assert!(
                    (v[k] - binomial).abs() <= 1e-14 * binomial.abs().max(1e-3),
                    "a {a}, k {k}: {} vs {binomial}",
                    v[k]
                );
            }
        }
    }

    /// A linear spring (α = 1) with no damping, drag or forcing: ξ = δ₀ cos ωt + (ξ'₀/ω)
    /// sin ωt on F+, ω² = r_L² K*/I_L; every term of the series against the cosine's and
    /// sine's.
    #[test]
    fn linear_contact_gives_the_harmonic_terms() {
        let mut p = GearParams::paper();
        (p.alpha, p.C, p.C_LM) = (1.0, 0.0, 0.0);
        let dynamics = Dynamics::new(p);
        let still = Excitation::Sine(Sine::new(0.0, 30.0, 0.0));
        let (xi0, xi_dot0) = (-3e-6, 0.004);
        let s = ContactSeries::<12>::new(&dynamics, &still, Region::ContactPlus, 0.3, xi0, xi_dot0)
            .expect("full contact");
        let w = (p.r_L * p.r_L * p.K_star / p.I_L).sqrt();
        let mut scale = 1.0; // w^k / k!
        for k in 0..12 {
            let expected = match k % 4 {
                0 => xi0,
                1 => xi_dot0 / w,
                2 => -xi0,
                _ => -xi_dot0 / w,
            } * scale;
            assert!(
                (s.xi[k] - expected).abs() <= 1e-12 * (xi0.abs() * scale),
                "k {k}: {} vs {expected}",
                s.xi[k]
            );
            scale *= w / (k + 1) as f64;
        }
        assert!(
            ContactSeries::<12>::new(&dynamics, &still, Region::BandPlus, 0.3, -0.5e-6, 0.0)
                .is_none()
        );
    }
}
