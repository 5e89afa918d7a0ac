//! What a model gives the shell: a typed Rust value, free of C types and of FMI's rules, for
//! Co-Simulation and, where the model offers it, Model Exchange. The shell's C exports check
//! the state machine, unpack the arguments, apply FMI's rules ([`crate::fmu`]), call these
//! methods, and turn their results into statuses and log lines.

use crate::contract::fmi3::Array;
use crate::contract::{Kind, Variable, no_variables};
use crate::log::{Categories, Log};
use crate::state::FmiState;
use crate::status::{FmiError, FmiResult};
use crate::stepping::Grid;
use crate::vectors::{Continuous, NoContinuous};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// Who a model is: what fmi2Instantiate checks, what tags its FMU states, where its
/// variables are looked up.
pub struct Identity {
    /// The GUID of the model description the binary was built with.
    pub guid: &'static str,
    pub model_identifier: &'static str,
    /// Log categories, errors first, then warnings ([`Log`]).
    pub log_categories: Categories,
    /// First bytes of a serialized FMU state, and its format's version (raised whenever the
    /// serialized shape of the instance, the shell's part or the slave's, changes).
    pub state_magic: [u8; 4],
    pub state_version: u16,
    /// Whether the model offers Model Exchange besides Co-Simulation.
    pub model_exchange: bool,
    /// The contract's variable of a kind and value reference, or the error for an unknown
    /// one (the generated `contract::variable`): the shell checks fmi2Set* against it.
    pub variable: fn(Kind, u32) -> FmiResult<&'static Variable>,
    /// Every variable of the contract, in the model description's order (the generated
    /// `contract::VARIABLES`): a packed model description is checked against it
    /// ([`crate::packed`]).
    pub variables: &'static [Variable],
    /// The contract's arrays as FMI 3.0 declares them (the generated `FMI3_ARRAYS`): a packed
    /// FMI 3.0 model description declares each of their variables once.
    pub arrays: &'static [Array],
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

/// How an instance is made, set up, initialised and stepped. The shell implements it for
/// every model that keeps its experiment and simulation in a [`Core`]; a model without
/// either (a partner whose simulation is its parameters) implements it itself.
///
/// [`Core`]: crate::instance::Core
pub trait Lifecycle: Sized {
    /// A fresh instance for `interface` (start values), logging as `logging_on` says.
    fn new(logging_on: bool, interface: Interface) -> Self;

    /// The interface it was instantiated for.
    fn interface(&self) -> Interface {
        Interface::CoSimulation
    }

    fn log(&mut self) -> &mut Log;

    /// fmi2SetupExperiment, after the shell's checks (finite start time, tolerance in (0, 1)).
    fn setup_experiment(&mut self, _tolerance: Option<f64>, _start_time: f64) {}

    /// fmi2EnterInitializationMode, before the shell enters that state.
    fn enter_initialization_mode(&mut self) {}

    /// fmi2ExitInitializationMode: validates the parameters and builds the initial state at
    /// the start time. On an error the shell keeps the instance in initialisation mode.
    fn exit_initialization_mode(&mut self) -> FmiResult;

    /// One communication step from `t` (the importer's communication point, checked against
    /// the instance's time) to `t + h` (h finite, > 0 and resolved there). On an error the
    /// shell moves the instance into [`FmiState::Error`]; on success its time is `t + h`.
    fn step(&mut self, t: f64, h: f64) -> FmiResult;

    /// Whether [`step_to_event`](Lifecycle::step_to_event) may end a step early: the model's
    /// events in Co-Simulation (FMI 3.0's early return and event mode, `hasEventMode` in its
    /// model description).
    const STEPS_TO_EVENTS: bool = false;

    /// A step as [`step`](Lifecycle::step) from `t` (the importer's communication point, or
    /// an event a step stopped at) to `t_end` (the end of the importer's step, t + h at its
    /// point), ended at the model's first event inside it where
    /// [`STEPS_TO_EVENTS`](Lifecycle::STEPS_TO_EVENTS) (FMI 3.0's early return); returns the
    /// time reached, t_end if no event came first. The shell calls it only where
    /// STEPS_TO_EVENTS.
    fn step_to_event(&mut self, t: f64, t_end: f64) -> FmiResult<f64> {
        self.step(t, t_end - t).map(|()| t_end)
    }

    /// The first steps of the sampling entry's `grid` that the model takes without stepping,
    /// the Real variables `vrs` read after each into `out` (rows of vrs.len() values), each
    /// to the bit as [`step`](Lifecycle::step) and fmi2GetReal: how many (see
    /// [`Stepping::serve`]). None by default: each step is taken the ordinary way.
    ///
    /// [`Stepping::serve`]: crate::stepping::Stepping::serve
    fn sample(&mut self, _grid: &Grid, _vrs: &[u32], _out: &mut [f64]) -> usize {
        0
    }
}

/// What a model supplies to the shell: its variables, its equations and stepping (its
/// [`Lifecycle`]), its own validation. The FMI rules (the state machine's transitions, the
/// time checks, which variables may be set in which state, the instance's time and last
/// successful time) are the shell's ([`Fmu`]), which calls these methods only where those
/// rules admit the call. Everything but its [`Log`] is part of the FMU state (clone and
/// serde).
///
/// [`Fmu`]: crate::fmu::Fmu
pub trait Slave: Lifecycle + Clone + Serialize + DeserializeOwned {
    const IDENTITY: Identity;

    fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> FmiResult;

    fn get_integer(&mut self, vrs: &[u32], _out: &mut [i32]) -> FmiResult {
        no_variables("Integer", vrs)
    }

    /// fmi2SetReal in `state`, after the shell has checked every value reference against the
    /// contract (known, settable in `state`, finite): the whole call is admitted.
    fn set_real(&mut self, state: FmiState, vrs: &[u32], values: &[f64]) -> FmiResult;

    /// fmi2SetInteger in `state`, checked as [`set_real`](Slave::set_real).
    fn set_integer(&mut self, _state: FmiState, vrs: &[u32], _values: &[i32]) -> FmiResult {
        no_variables("Integer", vrs)
    }

    /// Whether a slave decoded by fmi2DeSerializeFMUstate in `state` is one this build can
    /// run: the envelope's checksum catches corrupt bytes, not bytes made by hand with a
    /// valid one.
    fn check_decoded(&self, _state: FmiState) -> FmiResult {
        Ok(())
    }

    /// fmi2SetRealInputDerivatives (canInterpolateInputs) in `state`.
    fn set_input_derivatives(
        &mut self,
        _state: FmiState,
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

    // Model Exchange (offered where `IDENTITY.model_exchange`; the shell's state machine
    // admits these calls only in an instance of that interface).

    /// fmi2SetTime with a finite time (the shell checks it and keeps it on success).
    fn set_time(&mut self, _t: f64) -> FmiResult {
        Err(unsupported("fmi2SetTime"))
    }

    /// The continuous part whose states, nominals, derivatives and event indicators the
    /// shell reads and sets ([`Continuous`]; the arrays' checks are the shell's).
    fn continuous(&mut self) -> FmiResult<&mut impl Continuous> {
        Err::<&mut NoContinuous, _>(unsupported("Model Exchange"))
    }

    /// fmi2NewDiscreteStates, in event mode.
    fn new_discrete_states(&mut self) -> FmiResult<EventInfo> {
        Err(unsupported("fmi2NewDiscreteStates"))
    }

    /// fmi2CompletedIntegratorStep: whether the importer must enter event mode now (the
    /// shell then takes the current time as the last successful one). The continuous part
    /// takes the step as done ([`Continuous::completed_integrator_step`]); no event follows.
    fn completed_integrator_step(&mut self) -> FmiResult<bool> {
        self.continuous()?.completed_integrator_step();
        Ok(false)
    }
}

/// The error of a function the model's capabilities do not declare.
pub fn unsupported(function: &str) -> FmiError {
    FmiError::error(format!(
        "{function} is not supported: the model description does not declare that capability"
    ))
}
