//! The values of a model's parameters and inputs as last set, indexed by value reference,
//! starting from the contract's start values.

use crate::contract::{Causality, Kind, Start, Variable};
use crate::status::{FmiError, FmiResult};
use serde::{Deserialize, Serialize};

/// Start values other than the contract's, by value reference: a packed model description's
/// ([`crate::packed`]), which an instance applies at instantiation and again at fmi2Reset.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Starts {
    pub real: Vec<(u32, f64)>,
    pub integer: Vec<(u32, i32)>,
}

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

    /// Values decoded from a serialized FMU state: one per variable of the contract, each
    /// finite, as fmi2SetReal leaves them.
    pub fn check(&self, variables: &[Variable]) -> FmiResult {
        let start = Values::start(variables);
        if self.real.len() != start.real.len() || self.integer.len() != start.integer.len() {
            return Err(FmiError::error(format!(
                "{} Real and {} Integer values, the model has {} and {}",
                self.real.len(),
                self.integer.len(),
                start.real.len(),
                start.integer.len()
            )));
        }
        match self.real.iter().find(|x| !x.is_finite()) {
            Some(x) => Err(FmiError::error(format!("a value is {x}"))),
            None => Ok(()),
        }
    }

    /// `vr` must be a Real variable of the contract.
    pub fn real(&self, vr: u32) -> f64 {
        self.real[vr as usize]
    }

    /// `vr` must be an Integer variable of the contract.
    pub fn integer(&self, vr: u32) -> i64 {
        self.integer[vr as usize]
    }

    /// fmi2GetInteger of a model whose Integer variables are parameters, kept here, and
    /// outputs, which `output` computes (each of the contract's): every value saturated to
    /// fmi2Integer's range. `variable` is the contract's look-up ([`Identity`]).
    ///
    /// [`Identity`]: crate::slave::Identity
    pub fn get_integer(
        &self,
        variable: fn(Kind, u32) -> FmiResult<&'static Variable>,
        vrs: &[u32],
        out: &mut [i32],
        output: impl Fn(u32) -> Option<i64>,
    ) -> FmiResult {
        for (vr, out) in vrs.iter().zip(out) {
            let value = match variable(Kind::Integer, *vr)?.causality {
                Causality::Output => {
                    output(*vr).expect("every Integer output of the contract is computed")
                }
                _ => self.integer(*vr),
            };
            *out = i32::try_from(value).unwrap_or(i32::MAX);
        }
        Ok(())
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
