//! The gearbox's parameters (GEARBOX.md §1-§6) as one plain struct, its defaults (§6) and
//! its validation, each error naming the parameter (and the gear) at fault.
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

use crate::physics::{DamperParams, EngineParams, GearParams, Oil, ParamError};

/// The most loose gears a box has.
pub const MAX_GEARS: usize = 8;

/// One loose gear: its pair's parameters (MODEL.md §4, the drag C given at 40 °C) and the
/// ratio ρ at which its driving gear turns with the input shaft (GEARBOX.md §1).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LooseGear {
    pub pair: GearParams,
    pub rho: f64,
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

/// A parameter outside its range: of the box, or of gear `gear` (numbered from 1).
#[derive(Clone, Debug, PartialEq)]
pub struct GearboxParamError {
    pub gear: Option<usize>,
    pub error: ParamError,
}

impl std::fmt::Display for GearboxParamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.gear {
            Some(i) => write!(f, "gear {i}: {}", self.error),
            None => write!(f, "{}", self.error),
        }
    }
}

impl GearboxParams {
    /// GEARBOX.md §6: the five-speed box in neutral at idle, oil at 40 °C.
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

    /// Checks every parameter; the first invalid one is reported.
    pub fn validate(&self) -> Result<(), GearboxParamError> {
        let n = self.gears.len();
        if !(1..=MAX_GEARS).contains(&n) {
            return Err(box_error("n_gears", n as f64, "1 to 8"));
        }
        let positive = "finite and > 0";
        let non_negative = "finite and >= 0";
        let (d, e) = (&self.damper, &self.engine);
        let checks: [(&'static str, f64, bool, &'static str); 18] = [
            ("I_I", self.I_I, self.I_I > 0.0, positive),
            ("c_I", self.c_I, self.c_I >= 0.0, non_negative),
            ("k_1", d.k_1, d.k_1 > 0.0, positive),
            ("k_2", d.k_2, d.k_2 >= d.k_1, "finite and >= k_1"),
            ("phi_1", d.phi_1, d.phi_1 > 0.0, positive),
            ("H_1", d.H_1, d.H_1 >= 0.0, non_negative),
            ("H_2", d.H_2, d.H_2 >= 0.0, non_negative),
            ("c_cl", d.c_cl, d.c_cl >= 0.0, non_negative),
            ("omega_h", d.omega_h, d.omega_h > 0.0, positive),
            ("rpm", e.rpm, e.rpm > 0.0, positive),
            ("rpm_rate", e.rpm_rate, true, "finite"),
            ("n_1", e.orders[0].n, e.orders[0].n > 0.0, positive),
            ("n_2", e.orders[1].n, e.orders[1].n > 0.0, positive),
            ("a_1", e.orders[0].a, true, "finite"),
            ("a_2", e.orders[1].a, true, "finite"),
            ("nu_40", self.oil.nu_40, self.oil.nu_40 > 0.0, positive),
            (
                "nu_100",
                self.oil.nu_100,
                self.oil.nu_100 > 0.0 && self.oil.nu_100 < self.oil.nu_40,
                "finite, > 0 and < nu_40",
            ),
            (
                "T_oil",
                self.T_oil,
                self.T_oil > -crate::physics::oil::VOGEL_C,
                "finite and > -95 degC",
            ),
        ];
        if let Some(&(name, value, _, allowed)) = checks
            .iter()
            .find(|(_, value, ok, _)| !(value.is_finite() && *ok))
        {
            return Err(box_error(name, value, allowed));
        }
        for (i, gear) in self.gears.iter().enumerate() {
            let in_gear = |error| GearboxParamError {
                gear: Some(i + 1),
                error,
            };
            gear.pair.validate().map_err(in_gear)?;
            if !(gear.rho.is_finite() && gear.rho > 0.0) {
                return Err(in_gear(ParamError {
                    name: "rho",
                    value: gear.rho,
                    allowed: positive,
                }));
            }
        }
        Ok(())
    }
}

fn box_error(name: &'static str, value: f64, allowed: &'static str) -> GearboxParamError {
    GearboxParamError {
        gear: None,
        error: ParamError {
            name,
            value,
            allowed,
        },
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
        assert!(message(&p).contains("n_gears"), "{}", message(&p));
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
        let mut p = ok.clone();
        p.T_oil = -100.0;
        assert!(message(&p).contains("T_oil"));
        let mut p = ok.clone();
        p.gears[2].pair.G = -1.0;
        assert!(
            message(&p).starts_with("gear 3: parameter G"),
            "{}",
            message(&p)
        );
        let mut p = ok;
        p.gears[4].rho = 0.0;
        assert!(message(&p).starts_with("gear 5: parameter rho"));
    }
}
