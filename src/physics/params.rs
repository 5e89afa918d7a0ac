//! The nine parameters of the paper (docs/MODEL.md §4) plus the external torque B and the
//! carrier-shaft speed ω_S of the equation of motion (§3). Their ranges are the contract's
//! (modelDescription/GearRattle.toml), checked by the instance before it builds them.
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

/// Parameters of the gear pair, in SI units, named after the paper's symbols.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GearParams {
    /// Moment of inertia of the loose gear [kg m²].
    pub I_L: f64,
    /// Pitch radius of the loose gear [m].
    pub r_L: f64,
    /// Pitch radius of the main-shaft gear [m].
    pub r_M: f64,
    /// Reduced contact stiffness K* = K_LM G^(α−1) [N/m].
    pub K_star: f64,
    /// Contact-type exponent α (10/9 line, 3/2 point contact).
    pub alpha: f64,
    /// Width ε of the smoothing band (size of manufacturing errors) [m]; 0 = no band.
    pub epsilon: f64,
    /// Backlash on the pitch line G [m].
    pub G: f64,
    /// Contact damping C_LM [N s/m].
    pub C_LM: f64,
    /// Lubricant viscous coefficient C [N m s].
    pub C: f64,
    /// External torque on the loose gear B [N m].
    pub B: f64,
    /// Speed of the shaft that carries the loose gear ω_S [rad/s].
    pub omega_S: f64,
}

impl GearParams {
    /// The studied gearbox of the paper (§7), docs/MODEL.md §4.
    pub fn paper() -> Self {
        GearParams {
            I_L: 0.32e-3,
            r_L: 0.037,
            r_M: 0.02825,
            K_star: 3e6,
            alpha: 4.0 / 3.0,
            epsilon: 1e-6,
            G: 25e-6,
            C_LM: 67.0,
            C: 0.025,
            B: 0.0,
            omega_S: 0.0,
        }
    }

    /// Angular frequency of ξ in full contact, r_L √(K*/I_L) [rad/s]: the speed scale of ξ'.
    pub fn contact_frequency(&self) -> f64 {
        self.r_L * (self.K_star / self.I_L).sqrt()
    }
}
