//! The FMI 3.0 state machine over fmi2-shell's states: for each function, in one table, the
//! states in which it may be called (as the Reference-FMUs' masks). FMI 3.0's Step Mode is
//! [`FmiState::StepComplete`](fmi2_shell::FmiState::StepComplete); Event Mode is both
//! interfaces' (Co-Simulation's where the importer set eventModeUsed, which the functions
//! check), Continuous-Time Mode Model Exchange's. Configuration Mode is fmi2-shell's
//! [`ConfigurationMode`](fmi2_shell::FmiState::ConfigurationMode), entered from Instantiated
//! where the model has structural parameters (only fmi3GetUInt64 and fmi3SetUInt64 among the
//! getters and setters admit it). Reconfiguration and clock activation modes are never
//! entered: their functions have no state to be called in. Intermediate update mode is the
//! time of the intermediateUpdate callback inside fmi3DoStep, which allows the importer no
//! call (no intermediate variable to get or set).

pub mod allowed {
    /// The functions FMI 3.0 keeps, in the same states as FMI 2.0 (fmi3EnterInitializationMode
    /// takes fmi2SetupExperiment's arguments in fmi2EnterInitializationMode's state).
    pub use fmi2_shell::state::allowed::{
        COMPLETED_INTEGRATOR_STEP, DO_STEP, ENTER_CONTINUOUS_TIME_MODE, ENTER_INITIALIZATION_MODE,
        EXIT_INITIALIZATION_MODE, FMU_STATE, GET, GET_CONTINUOUS,
        NEW_DISCRETE_STATES as UPDATE_DISCRETE_STATES, RESET, SET, SET_CONTINUOUS_STATES,
        SET_DEBUG_LOGGING, SET_TIME, TERMINATE,
    };
    use fmi2_shell::state::{
        ANY, CONFIGURATION, CONTINUOUS, ERROR, EVENT, STEP_COMPLETE, TERMINATED,
    };
    /// From Model Exchange's continuous-time mode, or Co-Simulation's step mode.
    pub const ENTER_EVENT_MODE: u8 = CONTINUOUS | STEP_COMPLETE;
    /// fmi3EnterStepMode: from Co-Simulation's event mode.
    pub const ENTER_STEP_MODE: u8 = EVENT;
    /// fmi3GetDirectionalDerivative, fmi3GetAdjointDerivative.
    pub const DERIVATIVES: u8 = GET & !ERROR;
    /// Without clocks there is nothing to evaluate, wherever the importer asks.
    pub const EVALUATE_DISCRETE_STATES: u8 = SET_TIME;
    /// The functions of clocks and configuration mode: admitted in every state, so that their
    /// body says what is not offered (and configuration mode's, where it is, which state it
    /// needs).
    pub const EXPLAINED_REFUSAL: u8 = ANY;
    /// fmi3GetUInt64 (the structural parameters): wherever values are read, and in
    /// configuration mode.
    pub const GET_STRUCTURAL: u8 = GET | CONFIGURATION;
    /// fmi3SetUInt64: admitted wherever values are set, so that its body says that a
    /// structural parameter needs configuration mode.
    pub const SET_STRUCTURAL: u8 = SET | CONFIGURATION;
    /// fmi3GetNumberOf{ContinuousStates,EventIndicators}: constants of the model.
    pub const GET_NUMBER_OF: u8 = ANY;
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
            FmiState::ALL
                .into_iter()
                .filter(|s| s.allows(mask))
                .collect()
        };
        assert_eq!(admits(ENTER_INITIALIZATION_MODE), [Instantiated]);
        assert_eq!(admits(DO_STEP), [StepComplete]);
        assert_eq!(admits(ENTER_EVENT_MODE), [StepComplete, ContinuousTimeMode]);
        assert_eq!(admits(UPDATE_DISCRETE_STATES), [EventMode]);
        assert_eq!(admits(ENTER_STEP_MODE), [EventMode]);
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
        assert_eq!(admits(RESET).len(), 8);
        assert!(!admits(SET).contains(&ConfigurationMode));
        assert!(!admits(GET).contains(&ConfigurationMode));
        assert!(admits(SET_STRUCTURAL).contains(&ConfigurationMode));
        assert!(admits(GET_STRUCTURAL).contains(&ConfigurationMode));
        assert!(!admits(ENTER_INITIALIZATION_MODE).contains(&ConfigurationMode));
    }
}
