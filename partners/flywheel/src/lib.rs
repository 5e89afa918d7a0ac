//! Flywheel: GearRattle's drivetrain partner, an FMI 2.0 Co-Simulation FMU of an engine
//! flywheel with 2nd-order firing acyclism that drives the gearbox main shaft through a
//! clutch torsional damper, and takes back the gear contact's torque τ_M.
//!
//! - [`model`]: equations and parameters;
//! - [`instance`]: the slave for fmi2-shell (its C exports, state machine and FMU state);
//! - [`contract`]: value references and the model description, generated from
//!   `modelDescription/Flywheel.toml`.

pub mod contract;
pub mod instance;
pub mod model;

fmi2_shell::export_co_simulation!(crate::instance::Instance);
