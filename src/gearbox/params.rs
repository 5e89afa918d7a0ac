//! The gearbox's parameters (docs/GEARBOX.md §1-§6) as one plain struct, its defaults (§6) and
//! the checks the model needs, each error naming the parameter at fault.
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

use crate::physics::oil::VOGEL_C;
use crate::physics::{DamperParams, EngineParams, GearParams, Oil};

/// The most loose gears a box has.
pub const MAX_GEARS: usize = 8;

/// One loose gear: its pair's parameters (docs/MODEL.md §4, the drag C given at 40 °C), the
/// ratio ρ at which its driving gear turns with the input shaft (docs/GEARBOX.md §1) and its
/// carrier's ratio σ to the output shaft.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LooseGear {
    pub pair: GearParams,
    pub rho: f64,
    /// Speed ratio σ of the shaft carrying the gear to the output shaft: ω_S = σ ω_out
    /// ([`super::Gearbox::set_output_speed`]; the pair's ω_S until then).
    pub sigma: f64,
}

/// Everything that defines a gearbox run but the drive of the flywheel by inputs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GearboxParams {
    /// The loose gears, 1 to [`MAX_GEARS`].
    pub gears: Vec<LooseGear>,
    /// Inertia of the input side I_I [kg m²] and its drag c_I at 40 °C [N m s].
    pub I_I: f64,
    pub c_I: f64,
    pub damper: DamperParams,
    pub engine: EngineParams,
    pub oil: Oil,
    /// Oil temperature [°C].
    pub T_oil: f64,
}

/// A parameter outside what the model admits.
#[derive(Clone, Debug, PartialEq)]
pub struct GearboxParamError {
    pub name: &'static str,
    pub value: f64,
    pub allowed: &'static str,
}

impl std::fmt::Display for GearboxParamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "parameter {} = {:e} is invalid: allowed {}",
            self.name, self.value, self.allowed
        )
    }
}

impl GearboxParams {
    /// docs/GEARBOX.md §6: the five-speed box in neutral at idle, oil at 40 °C.
    pub fn default_box() -> Self {
        // ratio, r_M, r_L, I_L, G, C_LM of gears 1-5.
        let table = [
            (0.012, 0.042, 0.75e-3, 80e-6, 90.0),
            (0.018, 0.036, 0.40e-3, 80e-6, 80.0),
            (0.023, 0.031, 0.22e-3, 70e-6, 70.0),
            (0.027, 0.027, 0.13e-3, 70e-6, 60.0),
            (0.030, 0.024, 0.08e-3, 60e-6, 52.0),
        ];
        let gears = table
            .iter()
            .map(|&(r_M, r_L, I_L, G, C_LM)| LooseGear {
                pair: GearParams {
                    I_L,
                    r_L,
                    r_M,
                    K_star: 3e6,
                    alpha: 4.0 / 3.0,
                    epsilon: 1e-6,
                    G,
                    C_LM,
                    C: 2e-3,
                    B: 0.0,
                    omega_S: 0.0,
                },
                rho: 1.0,
                sigma: 1.0,
            })
            .collect();
        GearboxParams {
            gears,
            I_I: 0.008,
            c_I: 5e-3,
            damper: DamperParams::default_box(),
            engine: EngineParams::idle(),
            oil: Oil::gear_75w80(),
            T_oil: 40.0,
        }
    }

    /// Checks what the model needs to run: 1 to 8 gears, the damper's stages (φ_1 > 0,
    /// 0 < k_1 ≤ k_2), frictions H ≥ 0, the oil (0 < ν_100 < ν_40, T_oil above Vogel's
    /// −95 °C) and a positive mean engine speed; the first failure is reported by name. The
    /// FMU checks each variable's range against its contract
    /// (modelDescription/GearboxRattle.toml) before; the rules between parameters are here.
    pub fn validate(&self) -> Result<(), GearboxParamError> {
        let n = self.gears.len();
        let (d, oil) = (&self.damper, &self.oil);
        let checks: [(&'static str, f64, bool, &'static str); 9] = [
            ("n_gears", n as f64, (1..=MAX_GEARS).contains(&n), "1 to 8"),
            ("phi_1", d.phi_1, d.phi_1 > 0.0, "> 0"),
            ("k_1", d.k_1, d.k_1 > 0.0, "> 0"),
            ("k_2", d.k_2, d.k_2 >= d.k_1, ">= k_1"),
            ("H_1", d.H_1, d.H_1 >= 0.0, ">= 0"),
            ("H_2", d.H_2, d.H_2 >= 0.0, ">= 0"),
            (
                "nu_100",
                oil.nu_100,
                oil.nu_100 > 0.0 && oil.nu_100 < oil.nu_40,
                "> 0 and < nu_40",
            ),
            ("T_oil", self.T_oil, self.T_oil > -VOGEL_C, "> -95 degC"),
            ("rpm", self.engine.rpm, self.engine.rpm > 0.0, "> 0"),
        ];
        match checks
            .iter()
            .find(|(_, value, ok, _)| !(value.is_finite() && *ok))
        {
            Some(&(name, value, _, allowed)) => Err(GearboxParamError {
                name,
                value,
                allowed,
            }),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_errors_name_the_parameter() {
        let ok = GearboxParams::default_box();
        assert_eq!(ok.validate(), Ok(()));
        let message = |p: &GearboxParams| p.validate().unwrap_err().to_string();
        let mut p = ok.clone();
        p.gears.clear();
        assert_eq!(
            message(&p),
            "parameter n_gears = 0e0 is invalid: allowed 1 to 8"
        );
        p.gears = vec![ok.gears[0]; 9];
        assert!(message(&p).contains("n_gears"));
        let mut p = ok.clone();
        p.damper.k_2 = 0.5 * p.damper.k_1;
        assert!(message(&p).contains("k_2"), "{}", message(&p));
        let mut p = ok.clone();
        p.damper.phi_1 = 0.0;
        assert!(message(&p).contains("phi_1"));
        let mut p = ok.clone();
        p.damper.H_2 = -1.0;
        assert!(message(&p).contains("H_2"));
        let mut p = ok.clone();
        p.oil.nu_100 = 60.0;
        assert!(message(&p).contains("nu_100"));
        let mut p = ok;
        p.T_oil = -95.0;
        assert!(message(&p).contains("T_oil"));
    }
}
