//! GearboxRattle: the manual gearbox of docs/GEARBOX.md (up to 8 loose gears rattling behind
//! a two-stage clutch damper) as an FMI 2.0 and FMI 3.0 FMU for Co-Simulation and Model
//! Exchange. The model is gear_rattle's [`gear_rattle::gearbox`]; this crate is its FMU slave,
//! whose C exports the FMU's binary (fmus/GearboxRattle) writes around it:
//! - [`contract`]: value references and the model description, generated from
//!   `modelDescription/GearboxRattle.toml`;
//! - [`windowed`]: the gearbox with the statistics window's quadratures per gear;
//! - [`independent`]: the gears stepped apart on an imposed input side;
//! - [`simulation`]: the running model (parameters, drive, stepping with rollback);
//! - [`outputs`]: every output of the contract, computed when read;
//! - [`model_exchange`]: the states, derivatives and event indicators of Model Exchange;
//! - [`instance`]: the slave of fmi2-shell and fmi3-shell.

pub mod contract;
pub mod independent;
pub mod instance;
pub mod model_exchange;
pub mod outputs;
pub mod simulation;
pub mod windowed;
