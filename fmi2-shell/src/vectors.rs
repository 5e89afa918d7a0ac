//! Model Exchange's vectors between the importer and a model: the states it sets, the
//! states, nominals, derivatives and event indicators it reads. A model supplies them as
//! arrays of its own lengths ([`Continuous`]); the shell checks the importer's arrays against
//! those lengths and the values for finiteness in the terms of FMI 2.0 §3.2, for both
//! shells' exports.

use crate::fmu::Fmu;
use crate::slave::Slave;
use crate::status::{FmiError, FmiResult};

/// A model's continuous part as Model Exchange sees it: NX continuous states (`States`,
/// `[f64; NX]`) with their nominals and derivatives, and NZ event indicators
/// (`Indicators`, `[f64; NZ]`), at the current time.
pub trait Continuous {
    type States: Vector;
    type Indicators: Vector;

    fn continuous_states(&self) -> Self::States;

    /// Takes the importer's states, NX finite values.
    fn set_continuous_states(&mut self, x: &Self::States);

    fn nominals(&self) -> Self::States;

    fn derivatives(&self) -> Self::States;

    fn event_indicators(&self) -> Self::Indicators;

    /// fmi2CompletedIntegratorStep: the importer has accepted its step up to now.
    fn completed_integrator_step(&mut self) {}
}

/// A model's vector: an array of a fixed length.
pub trait Vector: AsRef<[f64]> + for<'a> TryFrom<&'a [f64]> {
    const LEN: usize;
}

impl<const N: usize> Vector for [f64; N] {
    const LEN: usize = N;
}

/// The continuous part of a model without Model Exchange: it has none to give.
pub enum NoContinuous {}

impl Continuous for NoContinuous {
    type States = [f64; 0];
    type Indicators = [f64; 0];

    fn continuous_states(&self) -> [f64; 0] {
        match *self {}
    }

    fn set_continuous_states(&mut self, _x: &[f64; 0]) {
        match *self {}
    }

    fn nominals(&self) -> [f64; 0] {
        match *self {}
    }

    fn derivatives(&self) -> [f64; 0] {
        match *self {}
    }

    fn event_indicators(&self) -> [f64; 0] {
        match *self {}
    }
}

impl<S: Slave> Fmu<S> {
    /// fmi2SetContinuousStates: `x` of the model's length, every value finite.
    pub fn set_continuous_states(&mut self, x: &[f64]) -> FmiResult {
        let x = states(x)?;
        self.slave.continuous()?.set_continuous_states(&x);
        Ok(())
    }

    /// fmi2GetContinuousStates.
    pub fn get_continuous_states(&mut self, x: &mut [f64]) -> FmiResult {
        fill("x", x, self.slave.continuous()?.continuous_states())
    }

    /// fmi2GetNominalsOfContinuousStates.
    pub fn get_nominals_of_continuous_states(&mut self, x_nominal: &mut [f64]) -> FmiResult {
        fill("x_nominal", x_nominal, self.slave.continuous()?.nominals())
    }

    /// fmi2GetDerivatives.
    pub fn get_derivatives(&mut self, dx: &mut [f64]) -> FmiResult {
        fill("derivatives", dx, self.slave.continuous()?.derivatives())
    }

    /// fmi2GetEventIndicators.
    pub fn get_event_indicators(&mut self, z: &mut [f64]) -> FmiResult {
        fill(
            "eventIndicators",
            z,
            self.slave.continuous()?.event_indicators(),
        )
    }
}

/// The importer's vector `x` as the model's states: refused if its length is not the
/// model's or a value is not finite.
pub fn states<V: Vector>(x: &[f64]) -> FmiResult<V> {
    let Ok(states) = V::try_from(x) else {
        return Err(length_error("x", x.len(), V::LEN));
    };
    match x.iter().position(|v| !v.is_finite()) {
        Some(bad) => Err(FmiError::error(format!(
            "x[{bad}] = {} refused: the continuous states must be finite",
            x[bad]
        ))),
        None => Ok(states),
    }
}

/// Copies a vector of the model into the importer's array, refused if the lengths differ.
/// A value that overflowed (states or a time beyond what the model can represent) is
/// fmi2Discard, which asks the importer's solver for a smaller step (FMI 2.0 §2.1.3).
pub fn fill<V: Vector>(what: &str, out: &mut [f64], value: V) -> FmiResult {
    let value = value.as_ref();
    if out.len() != V::LEN {
        return Err(length_error(what, out.len(), V::LEN));
    }
    if let Some(bad) = value.iter().position(|v| !v.is_finite()) {
        return Err(FmiError::discard(format!(
            "{what}[{bad}] = {} at these states and time: they are beyond what the model can represent; take a smaller step",
            value[bad]
        )));
    }
    out.copy_from_slice(value);
    Ok(())
}

fn length_error(what: &str, n: usize, expected: usize) -> FmiError {
    FmiError::error(format!("{what} has {n} elements: the model has {expected}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths_and_values_are_checked() {
        assert_eq!(states::<[f64; 2]>(&[1.0, 2.0]).unwrap(), [1.0, 2.0]);
        assert!(
            states::<[f64; 2]>(&[1.0])
                .unwrap_err()
                .message
                .contains("1 elements")
        );
        assert!(
            states::<[f64; 2]>(&[1.0, f64::NAN])
                .unwrap_err()
                .message
                .contains("x[1]")
        );
        let mut out = [0.0; 2];
        fill("z", &mut out, [3.0, 4.0]).unwrap();
        assert_eq!(out, [3.0, 4.0]);
        assert!(fill("z", &mut [0.0; 3], [3.0, 4.0]).is_err());
        assert!(fill("z", &mut out, [f64::INFINITY, 4.0]).is_err());
    }
}
