//! The oil's viscosity against temperature, Vogel's law (docs/GEARBOX.md §5), and the factor by
//! which it scales the drags given at 40 °C.

use serde::{Deserialize, Serialize};

/// Vogel's constant c [°C]: ν(T) = A exp(b / (T + c)).
pub const VOGEL_C: f64 = 95.0;

/// A gear oil known by its kinematic viscosities at 40 °C and 100 °C [mm²/s].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Oil {
    pub nu_40: f64,
    pub nu_100: f64,
}

impl Oil {
    /// A 75W-80 gear oil (docs/GEARBOX.md §5).
    pub fn gear_75w80() -> Self {
        Oil {
            nu_40: 55.0,
            nu_100: 9.5,
        }
    }

    /// b = ln(ν_40/ν_100) / (1/(40 + c) − 1/(100 + c)) [K].
    fn b(&self) -> f64 {
        (self.nu_40 / self.nu_100).ln() / (1.0 / (40.0 + VOGEL_C) - 1.0 / (100.0 + VOGEL_C))
    }

    /// ν(T) [mm²/s] at T [°C] (> −c): ν_40 exp(b (1/(T + c) − 1/(40 + c))).
    pub fn viscosity(&self, temperature: f64) -> f64 {
        self.nu_40 * self.drag_factor(temperature)
    }

    /// ν(T)/ν_40: the factor on the drags C_i and c_I given at 40 °C (exactly 1 at 40 °C).
    pub fn drag_factor(&self, temperature: f64) -> f64 {
        let exponent = 1.0 / (temperature + VOGEL_C) - 1.0 / (40.0 + VOGEL_C);
        (self.b() * exponent).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// docs/GEARBOX.md §5's hand values for ν_40 = 55, ν_100 = 9.5: 29× at −10 °C, 0.27× at
    /// 80 °C; exactly 1 at 40 °C and ν_100 at 100 °C.
    #[test]
    fn vogel_gives_the_hand_values() {
        let oil = Oil::gear_75w80();
        assert_eq!(oil.drag_factor(40.0), 1.0);
        assert!(
            (oil.viscosity(100.0) - 9.5).abs() < 1e-12,
            "{}",
            oil.viscosity(100.0)
        );
        // b = ln(55/9.5)/(1/135 − 1/195) = 770.48; at −10 °C exp(b (1/85 − 1/135)) = 28.7.
        let cold = oil.drag_factor(-10.0);
        assert!((cold - 28.7).abs() < 0.1, "{cold}");
        assert_eq!(cold.round(), 29.0);
        // At 80 °C exp(b (1/175 − 1/135)) = 0.2713.
        let warm = oil.drag_factor(80.0);
        assert!((warm - 0.2713).abs() < 5e-4, "{warm}");
    }
}
