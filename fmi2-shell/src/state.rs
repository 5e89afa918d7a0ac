//! The FMI 2.0 state machines of Co-Simulation and Model Exchange: the states an instance can
//! be in, and for each function, in one table, the states in which it may be called (as in
//! the Reference-FMUs). A call outside them is refused with "illegal call sequence" and not
//! executed.

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum FmiState {
    Instantiated,
    InitializationMode,
    /// Co-Simulation: initialised and ready for fmi2DoStep (FMI's "stepComplete").
    StepComplete,
    /// Model Exchange: discrete states may change (after initialisation and at events).
    EventMode,
    /// Model Exchange: the importer integrates the continuous states.
    ContinuousTimeMode,
    Terminated,
    /// A step failed (or a panic was caught): only inspection, reset and free remain.
    Error,
    /// FMI 3.0's configuration mode: the structural parameters may be set (never entered by
    /// FMI 2.0's functions).
    ConfigurationMode,
}

impl FmiState {
    pub const ALL: [FmiState; 8] = [
        FmiState::Instantiated,
        FmiState::InitializationMode,
        FmiState::StepComplete,
        FmiState::EventMode,
        FmiState::ContinuousTimeMode,
        FmiState::Terminated,
        FmiState::Error,
        FmiState::ConfigurationMode,
    ];

    fn bit(self) -> u8 {
        match self {
            FmiState::Instantiated => INSTANTIATED,
            FmiState::InitializationMode => INITIALIZATION,
            FmiState::StepComplete => STEP_COMPLETE,
            FmiState::EventMode => EVENT,
            FmiState::ContinuousTimeMode => CONTINUOUS,
            FmiState::Terminated => TERMINATED,
            FmiState::Error => ERROR,
            FmiState::ConfigurationMode => CONFIGURATION,
        }
    }

    /// Whether a function with this mask may be called in this state.
    pub fn allows(self, mask: u8) -> bool {
        mask & self.bit() != 0
    }

    /// Whether fmi2ExitInitializationMode has passed (the parameters are fixed).
    pub fn is_initialised(self) -> bool {
        !matches!(
            self,
            FmiState::Instantiated | FmiState::InitializationMode | FmiState::ConfigurationMode
        )
    }
}

// Each state's bit, for the tables of either edition (fmi3-shell's too).
pub const INSTANTIATED: u8 = 1;
pub const INITIALIZATION: u8 = 2;
pub const STEP_COMPLETE: u8 = 4;
pub const EVENT: u8 = 8;
pub const CONTINUOUS: u8 = 16;
pub const TERMINATED: u8 = 32;
pub const ERROR: u8 = 64;
pub const CONFIGURATION: u8 = 128;
pub const RUNNING: u8 = STEP_COMPLETE | EVENT | CONTINUOUS;
pub const ANY: u8 = INSTANTIATED | INITIALIZATION | RUNNING | TERMINATED | ERROR | CONFIGURATION;

/// States in which each FMI function may be called.
pub mod allowed {
    use super::*;
    pub const SET_DEBUG_LOGGING: u8 = ANY;
    pub const SETUP_EXPERIMENT: u8 = INSTANTIATED;
    pub const ENTER_INITIALIZATION_MODE: u8 = INSTANTIATED;
    pub const EXIT_INITIALIZATION_MODE: u8 = INITIALIZATION;
    pub const TERMINATE: u8 = RUNNING | ERROR;
    pub const RESET: u8 = ANY;
    pub const GET: u8 = INITIALIZATION | RUNNING | TERMINATED | ERROR;
    pub const SET: u8 = INSTANTIATED | INITIALIZATION | RUNNING;
    pub const DO_STEP: u8 = STEP_COMPLETE;
    pub const GET_STATUS: u8 = STEP_COMPLETE | TERMINATED | ERROR;
    /// No asynchronous step is ever pending, so there is never one to cancel.
    pub const CANCEL_STEP: u8 = 0;
    /// fmi2Get/Set/Free/(De)SerializeFMUstate: in every state after instantiation.
    pub const FMU_STATE: u8 = ANY;
    // Model Exchange.
    pub const SET_TIME: u8 = EVENT | CONTINUOUS;
    pub const SET_CONTINUOUS_STATES: u8 = CONTINUOUS;
    /// fmi2GetDerivatives, fmi2GetEventIndicators, fmi2GetContinuousStates,
    /// fmi2GetNominalsOfContinuousStates.
    pub const GET_CONTINUOUS: u8 = INITIALIZATION | EVENT | CONTINUOUS | TERMINATED | ERROR;
    pub const ENTER_EVENT_MODE: u8 = EVENT | CONTINUOUS;
    pub const NEW_DISCRETE_STATES: u8 = EVENT;
    pub const ENTER_CONTINUOUS_TIME_MODE: u8 = EVENT;
    pub const COMPLETED_INTEGRATOR_STEP: u8 = CONTINUOUS;
}
