//! The FMI 2.0 Co-Simulation state machine: the states an instance can be in, and for each
//! function, in one table, the states in which it may be called (as in the Reference-FMUs).
//! A call outside them is refused with "illegal call sequence" and not executed.

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum FmiState {
    Instantiated,
    InitializationMode,
    /// Initialised and ready for fmi2DoStep (FMI's "stepComplete").
    StepComplete,
    Terminated,
    /// A step failed (or a panic was caught): only inspection, reset and free remain.
    Error,
}

impl FmiState {
    fn bit(self) -> u8 {
        match self {
            FmiState::Instantiated => 1,
            FmiState::InitializationMode => 2,
            FmiState::StepComplete => 4,
            FmiState::Terminated => 8,
            FmiState::Error => 16,
        }
    }

    /// Whether a function with this mask may be called in this state.
    pub fn allows(self, mask: u8) -> bool {
        mask & self.bit() != 0
    }
}

const INSTANTIATED: u8 = 1;
const INITIALIZATION: u8 = 2;
const STEP_COMPLETE: u8 = 4;
const TERMINATED: u8 = 8;
const ERROR: u8 = 16;
const ANY: u8 = INSTANTIATED | INITIALIZATION | STEP_COMPLETE | TERMINATED | ERROR;

/// States in which each FMI function may be called.
pub mod allowed {
    use super::*;
    pub const SET_DEBUG_LOGGING: u8 = ANY;
    pub const SETUP_EXPERIMENT: u8 = INSTANTIATED;
    pub const ENTER_INITIALIZATION_MODE: u8 = INSTANTIATED;
    pub const EXIT_INITIALIZATION_MODE: u8 = INITIALIZATION;
    pub const TERMINATE: u8 = STEP_COMPLETE | ERROR;
    pub const RESET: u8 = ANY;
    pub const GET: u8 = INITIALIZATION | STEP_COMPLETE | TERMINATED | ERROR;
    pub const SET: u8 = INSTANTIATED | INITIALIZATION | STEP_COMPLETE;
    pub const DO_STEP: u8 = STEP_COMPLETE;
    pub const GET_STATUS: u8 = STEP_COMPLETE | TERMINATED | ERROR;
    /// No asynchronous step is ever pending, so there is never one to cancel.
    pub const CANCEL_STEP: u8 = 0;
    /// fmi2Get/Set/Free/(De)SerializeFMUstate: in every state after instantiation.
    pub const FMU_STATE: u8 = ANY;
}
