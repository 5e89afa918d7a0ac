//! fmi2-shell: the FMI 2.0 layer of GearRattle and its partner FMUs, written once.
//!
//! A model is a [`Slave`]: a typed Rust value with its variables, equations and stepping,
//! free of C types and of FMI's rules; one that runs a simulation built from its parameters
//! is a [`Model`], whose lifecycle (experiment, initialisation, steps) the shell writes
//! once ([`instance`]). The shell gives it
//! - the C exports ([`export_co_simulation!`]), each a guard ([`component`]) that checks the
//!   state table ([`state`]), unpacks the C arguments, catches panics, and hands log
//!   lines ([`log`]) to the importer's logger ([`logger`]);
//! - FMI's rules around the slave ([`fmu`]): the state transitions, the instance's time and
//!   last successful time, the checks of the time arguments ([`time`]) and of fmi2Set*
//!   against the contract;
//! - FMU states ([`fmu_state`]): boxed copies, and their serialized form with the model's
//!   magic, version, GUID and a CRC;
//! - statuses and errors in FMI's terms ([`status`]), and the store of the values set
//!   ([`values`]) with the Integer getter the models share;
//! - a co-simulation step with its errors, input extrapolation and logs ([`stepping`]), on
//!   hooks the model supplies;
//! - a packed FMU's start values, read from the model description beside the binary when
//!   the importer's GUID is not the built-in one ([`packed`]);
//! - the types of the contract and the checks of a variable's setting ([`contract`]) and, for
//!   build scripts, the generator of the model description and of the constants from the
//!   contract TOML (`build`, feature "build"), and the variable tables of the documentation
//!   ([`table`]);
//! - Model Exchange's vectors: a model's continuous part ([`Continuous`]) and the checks of
//!   the importer's arrays against it ([`vectors`]).

#[cfg(feature = "build")]
pub mod build;
#[cfg(feature = "runtime")]
pub mod component;
pub mod contract;
#[cfg(feature = "runtime")]
pub mod export;
pub mod fmu;
#[cfg(feature = "runtime")]
pub mod fmu_state;
pub mod instance;
pub mod log;
#[cfg(feature = "runtime")]
pub mod logger;
#[cfg(feature = "runtime")]
mod macros;
#[cfg(feature = "runtime")]
pub mod packed;
pub mod slave;
pub mod state;
pub mod status;
pub mod stepping;
pub mod table;
pub mod time;
pub mod values;
pub mod vectors;

#[cfg(feature = "runtime")]
pub use fmi_sys::fmi2;
pub use fmu::{CoSimulationEvents, Fmu};
pub use instance::{Core, Model};
pub use log::{Log, Message};
pub use slave::{EventInfo, Identity, Interface, Lifecycle, Slave};
pub use state::FmiState;
pub use status::{FmiError, FmiResult, Status};
pub use stepping::{Grid, Stepping};
pub use vectors::Continuous;
