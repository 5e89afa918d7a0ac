//! The types of a model's contract, as the generated constants use them
//! ([`build`](crate::build) writes them from the contract TOML), and the checks of the
//! fmi2Set* calls against it.

use crate::state::FmiState;
use crate::status::{FmiError, FmiResult};

/// FMI 2.0 base type of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Real,
    Integer,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    /// Fixed parameter: set before or during initialisation only.
    Parameter,
    /// Continuous input, set at communication points.
    Input,
    /// Computed by the FMU, read-only.
    Output,
    /// Computed by the FMU, read-only, not meant for connections: the continuous states
    /// and their derivatives of Model Exchange that are not outputs.
    Local,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Start {
    None,
    Real(f64),
    Integer(i64),
}

/// One scalar variable of the model description.
#[derive(Debug)]
pub struct Variable {
    pub name: &'static str,
    pub vr: u32,
    pub kind: Kind,
    pub causality: Causality,
    pub start: Start,
    /// SI unit as named in UnitDefinitions ("" for dimensionless).
    pub unit: &'static str,
    /// Outputs and state derivatives: the inputs and continuous states it depends on at once
    /// (ModelStructure's dependencies).
    pub depends_on: &'static [&'static str],
    /// Outputs: whether fmi2GetRealOutputDerivatives gives its first derivative.
    pub derivative: bool,
    pub description: &'static str,
}

impl Variable {
    /// Checks that the variable may be set in `state`: not one the FMU computes, and a
    /// parameter only before fmi2ExitInitializationMode.
    pub fn settable(&self, state: FmiState) -> FmiResult {
        let why = match self.causality {
            Causality::Output => "is an output: it cannot be set",
            Causality::Local => "is computed by the FMU: it cannot be set",
            Causality::Parameter if state.is_initialised() => {
                "is a fixed parameter: set it before fmi2ExitInitializationMode"
            }
            _ => return Ok(()),
        };
        Err(FmiError::error(format!("{} {why}", self.name)))
    }

    /// [`settable`](Self::settable) to a finite `value` (fmi2SetReal).
    pub fn settable_to(&self, state: FmiState, value: f64) -> FmiResult {
        self.settable(state)?;
        if value.is_finite() {
            Ok(())
        } else {
            Err(FmiError::error(format!(
                "{} = {value} refused: values must be finite",
                self.name
            )))
        }
    }
}

/// The error of a value reference the contract has no variable of that kind for.
pub fn unknown(kind: Kind, vr: u32) -> FmiError {
    FmiError::error(format!("unknown value reference {vr} for type {kind:?}"))
}

/// The error of any value reference for a kind the contract has no variables of (fmi2Get/Set
/// Boolean and String; Integer in a model without Integer variables).
pub fn no_variables(kind: &str, vrs: &[u32]) -> FmiResult {
    match vrs.first() {
        None => Ok(()),
        Some(vr) => Err(FmiError::error(format!(
            "unknown value reference {vr} for type {kind}: the model has no {kind} variables"
        ))),
    }
}
