//! The values of parameters and inputs as last set, indexed by value reference, starting
//! from the contract's start values, and the one input derivative without a variable of its
//! own (dτ_in/dt; the derivatives of θ_M and ω_M are stored as omega_M and alpha_M).

use serde::{Deserialize, Serialize};

use crate::contract::{Kind, Start, VARIABLES};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Values {
    real: Vec<f64>,
    integer: Vec<i64>,
    /// dτ_in/dt from fmi2SetRealInputDerivatives [N m/s] (0 until set: a held torque).
    tau_in_rate: f64,
}

impl Values {
    /// Every parameter and input at its start value.
    pub fn start() -> Self {
        let size = |kind| {
            VARIABLES
                .iter()
                .filter(|v| v.kind == kind)
                .map(|v| v.vr as usize + 1)
                .max()
                .unwrap_or(0)
        };
        let mut values = Values {
            real: vec![0.0; size(Kind::Real)],
            integer: vec![0; size(Kind::Integer)],
            tau_in_rate: 0.0,
        };
        for v in VARIABLES {
            match v.start {
                Start::Real(x) => values.real[v.vr as usize] = x,
                Start::Integer(i) => values.integer[v.vr as usize] = i,
                Start::None => {}
            }
        }
        values
    }

    pub fn real(&self, vr: u32) -> f64 {
        self.real[vr as usize]
    }

    pub fn integer(&self, vr: u32) -> i64 {
        self.integer[vr as usize]
    }

    /// Stores a value; `vr` must be a Real variable of the contract.
    pub fn set_real(&mut self, vr: u32, value: f64) {
        self.real[vr as usize] = value;
    }

    pub fn tau_in_rate(&self) -> f64 {
        self.tau_in_rate
    }

    pub fn set_tau_in_rate(&mut self, rate: f64) {
        self.tau_in_rate = rate;
    }

    /// Stores a value; `vr` must be an Integer variable of the contract.
    pub fn set_integer(&mut self, vr: u32, value: i64) {
        self.integer[vr as usize] = value;
    }
}
