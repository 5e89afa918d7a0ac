//! Flywheel: GearRattle's drivetrain partner, an FMI 2.0 Co-Simulation FMU of an engine
//! flywheel with 2nd-order firing acyclism that drives the gearbox main shaft through a
//! clutch torsional damper, and takes back the gear contact's torque τ_M.
//!
//! - [`model`]: equations, parameters, the variable table, the model description;
//! - [`instance`]: the slave's state machine and FMU state, free of C types;
//! - `fmi2`: the C exports.

pub mod fmi2;
pub mod instance;
pub mod model;
