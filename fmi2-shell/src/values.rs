//! The values of a model's parameters and inputs as last set, indexed by value reference,
//! starting from the contract's start values.

use crate::contract::{Kind, Start, Variable};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Values {
    real: Vec<f64>,
    integer: Vec<i64>,
}

impl Values {
    /// Every variable of the contract with a start value at it.
    pub fn start(variables: &[Variable]) -> Self {
        let size = |kind| {
            variables
                .iter()
                .filter(|v| v.kind == kind)
                .map(|v| v.vr as usize + 1)
                .max()
                .unwrap_or(0)
        };
        let mut values = Values {
            real: vec![0.0; size(Kind::Real)],
            integer: vec![0; size(Kind::Integer)],
        };
        for v in variables {
            match v.start {
                Start::Real(x) => values.real[v.vr as usize] = x,
                Start::Integer(i) => values.integer[v.vr as usize] = i,
                Start::None => {}
            }
        }
        values
    }

    /// `vr` must be a Real variable of the contract.
    pub fn real(&self, vr: u32) -> f64 {
        self.real[vr as usize]
    }

    /// `vr` must be an Integer variable of the contract.
    pub fn integer(&self, vr: u32) -> i64 {
        self.integer[vr as usize]
    }

    /// Stores a value; `vr` must be a Real variable of the contract.
    pub fn set_real(&mut self, vr: u32, value: f64) {
        self.real[vr as usize] = value;
    }

    /// Stores a value; `vr` must be an Integer variable of the contract.
    pub fn set_integer(&mut self, vr: u32, value: i64) {
        self.integer[vr as usize] = value;
    }
}
