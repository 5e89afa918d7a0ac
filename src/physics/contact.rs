//! Contact law of the tooth pair (docs/MODEL.md §2, the paper's eqs. 5-9 and §6.2).
//!
//! The transmission error ξ runs through five regions; inside each, the force is a smooth
//! (analytic) function of ξ and ξ'. The integrator keeps the region fixed for a whole step
//! and ends steps on the band edges ξ = −ε, 0, G, G+ε, so no step straddles a kink.
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

use super::GearParams;

/// Where ξ lies: the regions of docs/MODEL.md §2, from flank F+ (ξ ≤ 0) to flank F− (ξ ≥ G).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Region {
    /// ξ < −ε: full contact on flank F+ (s = 1).
    ContactPlus,
    /// −ε ≤ ξ ≤ 0: entering flank F+ through the smoothing band.
    BandPlus,
    /// 0 < ξ < G: free flight in the backlash (s = 0).
    Gap,
    /// G ≤ ξ ≤ G + ε: entering flank F− through the smoothing band.
    BandMinus,
    /// ξ > G + ε: full contact on flank F− (s = 1).
    ContactMinus,
}

impl Region {
    /// Contact flag of the FMU: 0 gap, 1 flank F+, 2 flank F−.
    pub fn flank(self) -> i32 {
        match self {
            Region::ContactPlus | Region::BandPlus => 1,
            Region::Gap => 0,
            Region::BandMinus | Region::ContactMinus => 2,
        }
    }
}

/// The exponent α of the elastic law, with fast paths for the usual contact types.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
enum Power {
    /// α = 1: linear spring.
    One,
    /// α = 4/3 (the paper's value): a cube root instead of a general power.
    FourThirds,
    /// α = 3/2 (Hertzian point contact): a square root.
    ThreeHalves,
    /// Any other α: |δ/G|^(α−1) through powf.
    General(f64),
}

/// Elastic and dissipative parts of the contact force along ξ [N].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactForce {
    /// F_k = s K* δ |δ/G|^(α−1), the paper's K_ξ.
    pub elastic: f64,
    /// F_c = s C_LM ξ', the paper's C_ξ.
    pub dissipative: f64,
}

impl ContactForce {
    pub const NONE: ContactForce = ContactForce {
        elastic: 0.0,
        dissipative: 0.0,
    };

    /// F = F_k + F_c.
    pub fn total(&self) -> f64 {
        self.elastic + self.dissipative
    }
}

/// The contact law of docs/MODEL.md §2 for one set of parameters, with its constants folded.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactLaw {
    K_star: f64,
    C_LM: f64,
    G: f64,
    epsilon: f64,
    inv_G: f64,
    /// π / (2ε): s = sin²(π δ / (2ε)) inside a band.
    half_pi_over_eps: f64,
    power: Power,
}

impl ContactLaw {
    pub fn new(p: &GearParams) -> Self {
        let power = if p.alpha == 1.0 {
            Power::One
        } else if p.alpha == 4.0 / 3.0 {
            Power::FourThirds
        } else if p.alpha == 1.5 {
            Power::ThreeHalves
        } else {
            Power::General(p.alpha - 1.0)
        };
        ContactLaw {
            K_star: p.K_star,
            C_LM: p.C_LM,
            G: p.G,
            epsilon: p.epsilon,
            inv_G: 1.0 / p.G,
            half_pi_over_eps: std::f64::consts::FRAC_PI_2 / p.epsilon,
            power,
        }
    }

    /// Whether the force of `region` starts, where the region borders the gap, as a
    /// non-integer power below 3 of the penetration: a contact entered without a smoothing
    /// band (ε = 0) with α not an integer. Inside a band s ∝ δ² makes it δ^(α+2), and a
    /// contact entered from its band starts at δ = ∓ε, away from the singular point.
    pub fn rough_at_onset(&self, region: Region) -> bool {
        let contact = matches!(region, Region::ContactPlus | Region::ContactMinus);
        let rough_power = match self.power {
            Power::One => false,
            Power::FourThirds | Power::ThreeHalves => true,
            Power::General(exponent) => (exponent + 1.0).fract() != 0.0 && exponent < 2.0,
        };
        contact && self.epsilon == 0.0 && rough_power
    }

    /// The region that contains ξ (the gap taken closed, [0, G]).
    pub fn classify(&self, xi: f64) -> Region {
        let banded = self.epsilon > 0.0;
        if xi < -self.epsilon {
            Region::ContactPlus
        } else if xi < 0.0 {
            Region::BandPlus
        } else if xi <= self.G {
            Region::Gap
        } else if banded && xi <= self.G + self.epsilon {
            Region::BandMinus
        } else {
            Region::ContactMinus
        }
    }

    /// Interval of ξ over which `region`'s formula is the contact law.
    pub fn bounds(&self, region: Region) -> (f64, f64) {
        let (e, g) = (self.epsilon, self.G);
        match region {
            Region::ContactPlus => (f64::NEG_INFINITY, -e),
            Region::BandPlus => (-e, 0.0),
            Region::Gap => (0.0, g),
            Region::BandMinus => (g, g + e),
            Region::ContactMinus => (g + e, f64::INFINITY),
        }
    }

    /// The region entered when ξ leaves `region` downwards (bands skipped when ε = 0).
    pub fn below(&self, region: Region) -> Region {
        let banded = self.epsilon > 0.0;
        match region {
            Region::ContactPlus | Region::BandPlus => Region::ContactPlus,
            Region::Gap if banded => Region::BandPlus,
            Region::Gap => Region::ContactPlus,
            Region::BandMinus => Region::Gap,
            Region::ContactMinus if banded => Region::BandMinus,
            Region::ContactMinus => Region::Gap,
        }
    }

    /// The region entered when ξ leaves `region` upwards (bands skipped when ε = 0).
    pub fn above(&self, region: Region) -> Region {
        let banded = self.epsilon > 0.0;
        match region {
            Region::ContactPlus if banded => Region::BandPlus,
            Region::ContactPlus => Region::Gap,
            Region::BandPlus => Region::Gap,
            Region::Gap if banded => Region::BandMinus,
            Region::Gap | Region::BandMinus | Region::ContactMinus => Region::ContactMinus,
        }
    }

    /// |δ/G|^(α−1): the factor that the elastic law (δ times it) and its slope (α times it)
    /// share, computed once for both.
    #[inline]
    fn stiffening(&self, delta: f64) -> f64 {
        let ratio = delta.abs() * self.inv_G;
        match self.power {
            Power::One => 1.0,
            Power::FourThirds => crate::math::cbrt(ratio),
            Power::ThreeHalves => ratio.sqrt(),
            Power::General(exponent) => ratio.powf(exponent),
        }
    }

    /// α, the ratio of the elastic law's slope α|δ/G|^(α−1) to the stiffening |δ/G|^(α−1).
    #[inline]
    fn alpha(&self) -> f64 {
        match self.power {
            Power::One => 1.0,
            Power::FourThirds => 4.0 / 3.0,
            Power::ThreeHalves => 1.5,
            Power::General(exponent) => 1.0 + exponent,
        }
    }

    /// Smoothing factor s in a band, as a function of the penetration δ ∈ [−ε, 0] on F+ or
    /// δ ∈ [0, ε] on F−: s = ½(1 − sin(π/ε (ε/2 ∓ δ))) = sin²(π δ / (2ε)).
    #[inline]
    fn smoothing(&self, delta: f64) -> f64 {
        crate::math::sin_squared(self.half_pi_over_eps * delta)
    }

    /// Contact force for ξ, ξ' with the formula of `region` (docs/MODEL.md §2).
    #[inline]
    pub fn force(&self, region: Region, xi: f64, xi_dot: f64) -> ContactForce {
        let (s, delta) = match region {
            Region::Gap => return ContactForce::NONE,
            Region::ContactPlus => (1.0, xi),
            Region::ContactMinus => (1.0, xi - self.G),
            Region::BandPlus => (self.smoothing(xi), xi),
            Region::BandMinus => {
                let delta = xi - self.G;
                (self.smoothing(delta), delta)
            }
        };
        ContactForce {
            elastic: s * self.K_star * (delta * self.stiffening(delta)),
            dissipative: s * self.C_LM * xi_dot,
        }
    }
}

/// Partial derivatives of the contact force: ∂F/∂ξ [N/m] and ∂F/∂ξ' [N s/m].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForceSlopes {
    pub d_xi: f64,
    pub d_xi_dot: f64,
}

impl ContactLaw {
    /// s, ds/dξ and the penetration δ with the formula of `region`; None in the gap (s = 0).
    #[inline]
    fn blend(&self, region: Region, xi: f64) -> Option<(f64, f64, f64)> {
        Some(match region {
            Region::Gap => return None,
            Region::ContactPlus => (1.0, 0.0, xi),
            Region::ContactMinus => (1.0, 0.0, xi - self.G),
            Region::BandPlus | Region::BandMinus => {
                let delta = if region == Region::BandPlus {
                    xi
                } else {
                    xi - self.G
                };
                let ds = self.half_pi_over_eps * (2.0 * self.half_pi_over_eps * delta).sin();
                (self.smoothing(delta), ds, delta)
            }
        })
    }

    /// ∂F/∂ξ and ∂F/∂ξ' with the formula of `region`: the contact's instantaneous stiffness
    /// and damping along ξ (s' = (π/2ε) sin(π δ/ε) inside a band).
    pub fn slopes(&self, region: Region, xi: f64, xi_dot: f64) -> ForceSlopes {
        let Some((s, ds, delta)) = self.blend(region, xi) else {
            return ForceSlopes {
                d_xi: 0.0,
                d_xi_dot: 0.0,
            };
        };
        let stiffening = self.stiffening(delta);
        let unsmoothed = self.K_star * (delta * stiffening) + self.C_LM * xi_dot;
        ForceSlopes {
            d_xi: ds * unsmoothed + s * self.K_star * (self.alpha() * stiffening),
            d_xi_dot: s * self.C_LM,
        }
    }

    /// ∂F_c/∂ξ and ∂F_c/∂ξ' of the dissipative part alone, F_c = s C_LM ξ' (for the
    /// Jacobian of the dissipated energy's quadrature).
    pub fn dissipative_slopes(&self, region: Region, xi: f64, xi_dot: f64) -> ForceSlopes {
        let (s, ds) = self
            .blend(region, xi)
            .map_or((0.0, 0.0), |(s, ds, _)| (s, ds));
        ForceSlopes {
            d_xi: ds * self.C_LM * xi_dot,
            d_xi_dot: s * self.C_LM,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classify_is_consistent_with_bounds() {
        for eps in [0.0, 1e-6] {
            let law = ContactLaw::new(&GearParams {
                epsilon: eps,
                ..GearParams::paper()
            });
            for k in -40..=40 {
                let xi = k as f64 * 1e-6;
                let r = law.classify(xi);
                let (lo, hi) = law.bounds(r);
                assert!(lo <= xi && xi <= hi, "{xi} in {r:?} [{lo}, {hi}]");
            }
        }
    }

    /// The analytic slopes match central differences of the force in every region.
    #[test]
    fn slopes_match_finite_differences() {
        for alpha in [1.0, 4.0 / 3.0, 1.5, 10.0 / 9.0] {
            let p = GearParams {
                alpha,
                ..GearParams::paper()
            };
            let law = ContactLaw::new(&p);
            for xi in [-3e-6, -0.7e-6, -0.2e-6, 10e-6, p.G + 0.4e-6, p.G + 3e-6] {
                let region = law.classify(xi);
                let (v, h) = (0.02, 1e-12);
                let f = |x: f64, v: f64| law.force(region, x, v).total();
                let slopes = law.slopes(region, xi, v);
                let d_xi = (f(xi + h, v) - f(xi - h, v)) / (2.0 * h);
                let d_v = (f(xi, v + 1e-6) - f(xi, v - 1e-6)) / 2e-6;
                assert!(
                    (slopes.d_xi - d_xi).abs() <= 1e-4 * d_xi.abs().max(1.0),
                    "{alpha} {xi:e}"
                );
                assert!((slopes.d_xi_dot - d_v).abs() <= 1e-6 * d_v.abs().max(1.0));
                let fc = |x: f64| law.force(region, x, v).dissipative;
                let dc = law.dissipative_slopes(region, xi, v);
                let dc_xi = (fc(xi + h) - fc(xi - h)) / (2.0 * h);
                assert!(
                    (dc.d_xi - dc_xi).abs() <= 1e-4 * dc_xi.abs().max(1.0),
                    "{alpha} {xi:e}"
                );
                assert_eq!(dc.d_xi_dot, law.force(region, xi, 1.0).dissipative);
            }
        }
    }

    /// Rough onsets: contacts without a band whose law is a non-integer power below 3.
    #[test]
    fn rough_onsets_are_contacts_without_band_and_non_integer_powers() {
        let rough = |epsilon: f64, alpha: f64, region: Region| {
            ContactLaw::new(&GearParams {
                epsilon,
                alpha,
                ..GearParams::paper()
            })
            .rough_at_onset(region)
        };
        for alpha in [10.0 / 9.0, 4.0 / 3.0, 1.5, 2.5] {
            assert!(rough(0.0, alpha, Region::ContactPlus), "{alpha}");
            assert!(rough(0.0, alpha, Region::ContactMinus), "{alpha}");
            assert!(!rough(1e-6, alpha, Region::ContactPlus), "{alpha}");
            assert!(!rough(1e-6, alpha, Region::BandPlus), "{alpha}");
            assert!(!rough(0.0, alpha, Region::Gap), "{alpha}");
        }
        for alpha in [1.0, 2.0, 3.5] {
            assert!(!rough(0.0, alpha, Region::ContactPlus), "{alpha}");
        }
    }

    #[test]
    fn neighbours_skip_empty_bands() {
        let law = ContactLaw::new(&GearParams {
            epsilon: 0.0,
            ..GearParams::paper()
        });
        assert_eq!(law.below(Region::Gap), Region::ContactPlus);
        assert_eq!(law.above(Region::Gap), Region::ContactMinus);
        assert_eq!(law.above(Region::ContactPlus), Region::Gap);
    }
}
