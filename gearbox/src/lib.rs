//! GearboxRattle: the manual gearbox of docs/GEARBOX.md (up to 8 loose gears rattling behind
//! a two-stage clutch damper) as an FMI 2.0 and FMI 3.0 FMU for Co-Simulation and Model
//! Exchange. The model is gear_rattle's [`gear_rattle::gearbox`]; this crate is its FMU:
//! - [`contract`]: value references and the model description, generated from
//!   `modelDescription/GearboxRattle.toml`;
//! - [`windowed`]: the gearbox with the statistics window's quadratures per gear;
//! - [`simulation`]: the running model (parameters, drive, stepping with rollback);
//! - [`outputs`]: every output of the contract, computed when read;
//! - [`model_exchange`]: the states, derivatives and event indicators of Model Exchange;
//! - [`instance`]: the slave of fmi2-shell, whose C exports are written here: FMI 2.0's
//!   (fmi2-shell's) and FMI 3.0's beside them (fmi3-shell's, around the same instance).

pub mod contract;
pub mod instance;
pub mod model_exchange;
pub mod outputs;
pub mod simulation;
pub mod windowed;

// One cargo call that builds gear_rattle with its default features too (`cargo build
// --workspace`, or `-p gear_rattle -p gearbox_rattle`) unifies them: GearRattle's fmi2*
// exports would then be linked beside these. Build this crate alone (`-p gearbox_rattle`).
const _: () = assert!(
    !gear_rattle::FMU_EXPORTS,
    "gear_rattle is built with its fmi2* exports (feature `fmu`): build gearbox_rattle in a cargo call of its own"
);

fmi2_shell::export_co_simulation!(crate::instance::Instance);
fmi2_shell::export_model_exchange!(crate::instance::Instance);
fmi3_shell::export_fmi3!(crate::instance::Instance, crate::contract);
