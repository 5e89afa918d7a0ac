//! Equation of motion of the loose gear (docs/MODEL.md §3, the paper's eq. 1), written for the
//! transmission error ξ = r_L θ_L − r_M θ_M (eq. 2) so that long runs lose no micrometres:
//!
//!   ω_L = (ξ' + r_M ω_M) / r_L
//!   I_L ω_L' = B − r_L F − C (ω_L − ω_S)
//!   ξ'' = r_L ω_L' − r_M a_M
//!
//! The main shaft's motion θ_M, ω_M, a_M is imposed (docs/MODEL.md §5) or, in torque mode, follows
//! from its own equation of motion ([`MainShaft`]).
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

/// Torque mode: the main shaft as a rigid inertia I_M, driven by the drivetrain's torque τ_in
/// and by the contact. docs/MODEL.md imposes the shaft; this completes its §3 with the reaction
/// it states there, τ_M = + r_M F being the torque the contact exerts on the main shaft:
///
///   I_M ω_M' = τ_in + r_M F
///   θ_M'     = ω_M
///
/// so that ξ'' = r_L ω_L' − r_M ω_M' couples both equations through F. Energy: with
/// V(ξ) = ∫ F_k dξ, dV/dt = F_k ξ' = F_k (r_L ω_L − r_M ω_M), and the contact's power on the
/// two gears, −r_L F ω_L + r_M F ω_M, cancels it when F = F_k; hence with B = C = C_LM = 0
///
///   ½ I_L ω_L² + ½ I_M ω_M² + V(ξ) − ∫ τ_in ω_M dt   is constant
///
/// (tests/energy.rs checks it).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MainShaft {
    /// Moment of inertia of the main shaft [kg m²].
    pub I_M: f64,
}

impl MainShaft {
    /// ω_M' = (τ_in + r_M F) / I_M for the drivetrain's torque τ_in and the contact force F.
    #[inline]
    pub fn alpha(&self, r_M: f64, tau_in: f64, force: f64) -> f64 {
        (tau_in + r_M * force) / self.I_M
    }
}

/// The gear pair's dynamics for one set of parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Dynamics {
    pub params: GearParams,
    pub law: ContactLaw,
    /// 1/r_L and 1/I_L: the right-hand side multiplies by them, keeping two chained divisions
    /// off the path of every stage (docs/DECISIONS.md, D16).
    inv_r_L: f64,
    inv_I_L: f64,
}

impl Dynamics {
    pub fn new(params: GearParams) -> Self {
        Dynamics {
            law: ContactLaw::new(&params),
            params,
            inv_r_L: 1.0 / params.r_L,
            inv_I_L: 1.0 / params.I_L,
        }
    }

    /// Loads at (ξ, ξ') with the contact formula of `region` and the main shaft at `shaft`.
    #[inline]
    pub fn loads(&self, region: Region, xi: f64, xi_dot: f64, shaft: &Shaft) -> Loads {
        let force = self.law.force(region, xi, xi_dot);
        self.respond(force, xi_dot, shaft)
    }

    /// Torque mode: loads at (ξ, ξ') with the main shaft at angle θ_M and speed ω_M, its
    /// acceleration following from τ_in and the contact ([`MainShaft`]); also returns the
    /// shaft's motion with that acceleration.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn driven_loads(
        &self,
        region: Region,
        xi: f64,
        xi_dot: f64,
        main: &MainShaft,
        theta_M: f64,
        omega_M: f64,
        tau_in: f64,
    ) -> (Loads, Shaft) {
        let force = self.law.force(region, xi, xi_dot);
        let shaft = Shaft {
            theta: theta_M,
            omega: omega_M,
            alpha: main.alpha(self.params.r_M, tau_in, force.total()),
        };
        (self.respond(force, xi_dot, &shaft), shaft)
    }

    /// The loose gear's response to the contact force and the shaft's motion (docs/MODEL.md §3).
    #[inline]
    pub fn respond(&self, force: ContactForce, xi_dot: f64, shaft: &Shaft) -> Loads {
        let p = &self.params;
        let omega_L = (xi_dot + p.r_M * shaft.omega) * self.inv_r_L;
        let alpha_L = (p.B - p.r_L * force.total() - p.C * (omega_L - p.omega_S)) * self.inv_I_L;
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
