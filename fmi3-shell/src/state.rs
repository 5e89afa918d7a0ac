//! The FMI 3.0 state machine over fmi2-shell's states: for each function, in one table, the
//! states in which it may be called (as the Reference-FMUs' masks). FMI 3.0's Step Mode is
//! [`FmiState::StepComplete`](fmi2_shell::FmiState::StepComplete); Co-Simulation never enters
//! event mode (hasEventMode is false), so Event Mode and Continuous-Time Mode are Model
//! Exchange's. Configuration, clock activation and intermediate update modes are never
//! entered: their functions have no state to be called in.

pub mod allowed {
    use fmi2_shell::state::{
        ANY, CONTINUOUS, ERROR, EVENT, INITIALIZATION, INSTANTIATED, RUNNING, STEP_COMPLETE,
        TERMINATED,
    };
    pub const SET_DEBUG_LOGGING: u8 = ANY;
    /// fmi3EnterInitializationMode, which takes FMI 2.0's experiment set-up.
    pub const ENTER_INITIALIZATION_MODE: u8 = INSTANTIATED;
    pub const EXIT_INITIALIZATION_MODE: u8 = INITIALIZATION;
    /// Model Exchange only: Co-Simulation's event mode is not offered.
    pub const ENTER_EVENT_MODE: u8 = CONTINUOUS;
    pub const TERMINATE: u8 = RUNNING | ERROR;
    pub const RESET: u8 = ANY;
    pub const GET: u8 = INITIALIZATION | RUNNING | TERMINATED | ERROR;
    pub const SET: u8 = INSTANTIATED | INITIALIZATION | RUNNING;
    pub const FMU_STATE: u8 = ANY;
    pub const DERIVATIVES: u8 = INITIALIZATION | RUNNING | TERMINATED;
    /// Configuration mode, clocks, model partitions, Co-Simulation's event mode and early
    /// return: never in a state to be called.
    pub const NOT_OFFERED: u8 = 0;
    // Model Exchange.
    pub const UPDATE_DISCRETE_STATES: u8 = EVENT;
    pub const EVALUATE_DISCRETE_STATES: u8 = EVENT | CONTINUOUS;
    pub const ENTER_CONTINUOUS_TIME_MODE: u8 = EVENT;
    pub const COMPLETED_INTEGRATOR_STEP: u8 = CONTINUOUS;
    pub const SET_TIME: u8 = EVENT | CONTINUOUS;
    pub const SET_CONTINUOUS_STATES: u8 = CONTINUOUS;
    pub const GET_CONTINUOUS: u8 = INITIALIZATION | EVENT | CONTINUOUS | TERMINATED | ERROR;
    /// fmi3GetNumberOf{ContinuousStates,EventIndicators}: constants of the model.
    pub const GET_NUMBER_OF: u8 = ANY;
    // Co-Simulation.
    pub const DO_STEP: u8 = STEP_COMPLETE;
    pub const GET_OUTPUT_DERIVATIVES: u8 = STEP_COMPLETE | TERMINATED | ERROR;
}

#[cfg(test)]
mod tests {
    use super::allowed::*;
    use fmi2_shell::FmiState::{self, *};

    /// The table admits each function in FMI 3.0's states and refuses it elsewhere.
    #[test]
    fn the_table_follows_fmi3s_state_machine() {
        let admits = |mask: u8| -> Vec<FmiState> {
            [
                Instantiated,
                InitializationMode,
                StepComplete,
                EventMode,
                ContinuousTimeMode,
                Terminated,
                Error,
            ]
            .into_iter()
            .filter(|s| s.allows(mask))
            .collect()
        };
        assert_eq!(admits(ENTER_INITIALIZATION_MODE), [Instantiated]);
        assert_eq!(admits(DO_STEP), [StepComplete]);
        assert_eq!(admits(ENTER_EVENT_MODE), [ContinuousTimeMode]);
        assert_eq!(admits(UPDATE_DISCRETE_STATES), [EventMode]);
        assert_eq!(admits(NOT_OFFERED), []);
        assert_eq!(
            admits(SET),
            [
                Instantiated,
                InitializationMode,
                StepComplete,
                EventMode,
                ContinuousTimeMode
            ]
        );
        assert!(!admits(TERMINATE).contains(&Instantiated));
        assert_eq!(admits(RESET).len(), 7);
    }
}
