//! fmi3-shell: the FMI 3.0 exports of a model written once as fmi2-shell's [`Slave`], beside
//! its FMI 2.0 exports in the same library (the function names differ).
//!
//! What FMI 3.0 shares with FMI 2.0 is fmi2-shell's and used as it is: the instance and its
//! rules ([`Fmu`]: transitions, time checks, checks of the values set), the guard that
//! checks a state table and catches panics, FMU states and their serialized form, the log
//! queue and the importer's logger (FMI 3.0's callback). This crate adds
//! - the FMI 3.0 state table ([`state`]), over fmi2-shell's states (FMI 3.0's Step Mode is
//!   its step-complete state);
//! - the arguments FMI 3.0 passes otherwise ([`export`]): one value-reference space
//!   ([`fmi2_shell::contract::fmi3`]), the time and event indicators as variables,
//!   Enumerations as Int64, the adjoint derivatives from the directional ones, the
//!   instantiation of each interface, Co-Simulation's early return at the model's events
//!   ([`Lifecycle::step_to_event`]), its event mode and its intermediate update at each of
//!   those events, as the importer allows and asks for them;
//! - a contract's arrays as FMI 3.0's array variables sized by structural parameters, set in
//!   configuration mode ([`arrays`]);
//! - the exports themselves ([`export_fmi3!`]).
//!
//! Not offered: intermediate variables, clocks, scheduled execution, and configuration mode for
//! a model without structural parameters; their functions refuse with a log line.
//!
//! [`Lifecycle::step_to_event`]: fmi2_shell::Lifecycle::step_to_event
//!
//! [`Slave`]: fmi2_shell::Slave
//! [`Fmu`]: fmi2_shell::Fmu

pub mod arrays;
pub mod export;
mod macros;
pub mod state;

pub use fmi_sys::fmi3;
