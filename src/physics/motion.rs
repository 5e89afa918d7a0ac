//! Equation of motion of the loose gear (MODEL.md §3, the paper's eq. 1), written for the
//! transmission error ξ = r_L θ_L − r_M θ_M (eq. 2) so that long runs lose no micrometres:
//!
//!   ω_L = (ξ' + r_M ω_M) / r_L
//!   I_L ω_L' = B − r_L F − C (ω_L − ω_S)
//!   ξ'' = r_L ω_L' − r_M a_M
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

use super::{ContactLaw, GearParams, Region, Shaft, contact::ContactForce};

/// Everything the state (ξ, ξ') and the shaft motion determine at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Loads {
    /// Contact force along ξ, split into elastic and dissipative parts [N].
    pub force: ContactForce,
    /// Speed of the loose gear ω_L [rad/s].
    pub omega_L: f64,
    /// Angular acceleration of the loose gear ω_L' [rad/s²].
    pub alpha_L: f64,
    /// ξ'' [m/s²].
    pub xi_ddot: f64,
}

/// The gear pair's dynamics for one set of parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Dynamics {
    pub params: GearParams,
    pub law: ContactLaw,
}

impl Dynamics {
    pub fn new(params: GearParams) -> Self {
        Dynamics {
            law: ContactLaw::new(&params),
            params,
        }
    }

    /// Loads at (ξ, ξ') with the contact formula of `region` and the main shaft at `shaft`.
    #[inline]
    pub fn loads(&self, region: Region, xi: f64, xi_dot: f64, shaft: &Shaft) -> Loads {
        let p = &self.params;
        let force = self.law.force(region, xi, xi_dot);
        let omega_L = (xi_dot + p.r_M * shaft.omega) / p.r_L;
        let alpha_L = (p.B - p.r_L * force.total() - p.C * (omega_L - p.omega_S)) / p.I_L;
        Loads {
            force,
            omega_L,
            alpha_L,
            xi_ddot: p.r_L * alpha_L - p.r_M * shaft.alpha,
        }
    }

    /// Angle of the loose gear from ξ and θ_M: θ_L = (ξ + r_M θ_M) / r_L.
    pub fn theta_L(&self, xi: f64, shaft: &Shaft) -> f64 {
        (xi + self.params.r_M * shaft.theta) / self.params.r_L
    }

    /// Torque the contact exerts on the main shaft, τ_M = r_M F.
    pub fn tau_M(&self, loads: &Loads) -> f64 {
        self.params.r_M * loads.force.total()
    }
}
