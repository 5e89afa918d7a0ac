//! What a model gives the shell: an FMU instance as a typed Rust value, free of C types, for
//! Co-Simulation and, where the model offers it, Model Exchange. The shell's C exports check
//! the state machine, unpack the arguments, call these methods, and turn their results into
//! statuses and log lines.

use crate::log::{Categories, Log};
use crate::state::FmiState;
use crate::status::{FmiError, FmiResult};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// Who a model is: what fmi2Instantiate checks and what tags its FMU states.
pub struct Identity {
    /// The GUID of the model description the binary was built with.
    pub guid: &'static str,
    pub model_identifier: &'static str,
    /// Log categories, errors first, then warnings ([`Log`]).
    pub log_categories: Categories,
    /// First bytes of a serialized FMU state, and its format's version (raised whenever the
    /// slave's serialized shape changes).
    pub state_magic: [u8; 4],
    pub state_version: u16,
    /// Whether the model offers Model Exchange besides Co-Simulation.
    pub model_exchange: bool,
}

/// The interface an instance was instantiated for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Interface {
    CoSimulation,
    ModelExchange,
}

/// What fmi2NewDiscreteStates reports.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EventInfo {
    /// Another round of fmi2NewDiscreteStates is needed at this time.
    pub new_discrete_states_needed: bool,
    pub terminate_simulation: bool,
    pub nominals_of_continuous_states_changed: bool,
    pub values_of_continuous_states_changed: bool,
    /// The next time event, if any.
    pub next_event_time: Option<f64>,
}

/// A co-simulation slave. Everything but its [`Log`] is its FMU state (clone and serde).
pub trait Slave: Clone + Serialize + DeserializeOwned {
    const IDENTITY: Identity;

    /// A fresh instance for `interface` (state Instantiated, start values), logging as
    /// `logging_on` says.
    fn new(logging_on: bool, interface: Interface) -> Self;

    /// The interface it was instantiated for.
    fn interface(&self) -> Interface {
        Interface::CoSimulation
    }

    fn log(&mut self) -> &mut Log;

    fn state(&self) -> FmiState;

    /// Sets the state: the shell moves a slave into [`FmiState::Error`] after a panic.
    fn set_state(&mut self, state: FmiState);

    /// fmi2SetupExperiment, with a finite start time (the shell checks it).
    fn setup_experiment(&mut self, tolerance: Option<f64>, start_time: f64) -> FmiResult;

    fn enter_initialization_mode(&mut self) -> FmiResult {
        self.set_state(FmiState::InitializationMode);
        Ok(())
    }

    fn exit_initialization_mode(&mut self) -> FmiResult;

    fn terminate(&mut self) -> FmiResult {
        self.set_state(FmiState::Terminated);
        Ok(())
    }

    fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> FmiResult;
    fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> FmiResult;
    fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> FmiResult;
    fn set_integer(&mut self, vrs: &[u32], values: &[i32]) -> FmiResult;

    fn do_step(&mut self, current: f64, h: f64) -> FmiResult;

    /// Whether a slave decoded by fmi2DeSerializeFMUstate is one this build can run: the
    /// envelope's checksum catches corrupt bytes, not bytes made by hand with a valid one.
    fn check_decoded(&self) -> FmiResult {
        Ok(())
    }

    /// fmi2LastSuccessfulTime.
    fn last_successful_time(&self) -> f64;

    /// fmi2SetRealInputDerivatives (canInterpolateInputs).
    fn set_input_derivatives(
        &mut self,
        _vrs: &[u32],
        _orders: &[i32],
        _values: &[f64],
    ) -> FmiResult {
        Err(unsupported("fmi2SetRealInputDerivatives"))
    }

    /// fmi2GetRealOutputDerivatives: the first derivative of each output (the models of this
    /// shell declare maxOutputDerivativeOrder = 1), from [`output_derivative`].
    ///
    /// [`output_derivative`]: Slave::output_derivative
    fn get_output_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        out: &mut [f64],
    ) -> FmiResult {
        for ((vr, order), out) in vrs.iter().zip(orders).zip(out) {
            if *order != 1 {
                return Err(FmiError::error(format!(
                    "derivative of order {order} of value reference {vr} refused: maxOutputDerivativeOrder is 1"
                )));
            }
            *out = self.output_derivative(*vr)?;
        }
        Ok(())
    }

    /// The first derivative of the output `vr` now.
    fn output_derivative(&mut self, _vr: u32) -> FmiResult<f64> {
        Err(unsupported("fmi2GetRealOutputDerivatives"))
    }

    /// fmi2GetDirectionalDerivative (providesDirectionalDerivative).
    fn directional_derivative(
        &mut self,
        _unknowns: &[u32],
        _knowns: &[u32],
        _dv_known: &[f64],
        _dv_unknown: &mut [f64],
    ) -> FmiResult {
        Err(unsupported("fmi2GetDirectionalDerivative"))
    }

    // Model Exchange (offered where `IDENTITY.model_exchange`).

    fn set_time(&mut self, _t: f64) -> FmiResult {
        Err(unsupported("fmi2SetTime"))
    }

    fn set_continuous_states(&mut self, _x: &[f64]) -> FmiResult {
        Err(unsupported("fmi2SetContinuousStates"))
    }

    fn get_continuous_states(&mut self, _x: &mut [f64]) -> FmiResult {
        Err(unsupported("fmi2GetContinuousStates"))
    }

    fn get_nominals_of_continuous_states(&mut self, _x: &mut [f64]) -> FmiResult {
        Err(unsupported("fmi2GetNominalsOfContinuousStates"))
    }

    fn get_derivatives(&mut self, _dx: &mut [f64]) -> FmiResult {
        Err(unsupported("fmi2GetDerivatives"))
    }

    fn get_event_indicators(&mut self, _z: &mut [f64]) -> FmiResult {
        Err(unsupported("fmi2GetEventIndicators"))
    }

    fn enter_event_mode(&mut self) -> FmiResult {
        Err(unsupported("fmi2EnterEventMode"))
    }

    fn new_discrete_states(&mut self) -> FmiResult<EventInfo> {
        Err(unsupported("fmi2NewDiscreteStates"))
    }

    fn enter_continuous_time_mode(&mut self) -> FmiResult {
        Err(unsupported("fmi2EnterContinuousTimeMode"))
    }

    /// fmi2CompletedIntegratorStep: whether the importer must enter event mode now.
    fn completed_integrator_step(&mut self) -> FmiResult<bool> {
        Err(unsupported("fmi2CompletedIntegratorStep"))
    }
}

/// The error of a function the model's capabilities do not declare.
pub fn unsupported(function: &str) -> FmiError {
    FmiError::error(format!(
        "{function} is not supported: the model description does not declare that capability"
    ))
}

/// A copy of the FMU state: the slave without its queued log lines.
pub fn snapshot<S: Slave>(slave: &S) -> S {
    let mut copy = slave.clone();
    copy.log().messages.clear();
    copy
}

/// Takes over a saved FMU state, keeping the slave's logging settings and lines.
pub fn restore<S: Slave>(slave: &mut S, saved: &S) {
    let log = std::mem::take(slave.log());
    *slave = saved.clone();
    *slave.log() = log;
}

/// fmi2Reset: back to the state after instantiation, the logging settings kept.
pub fn reset<S: Slave>(slave: &mut S) {
    let interface = slave.interface();
    restore(slave, &S::new(false, interface));
}
