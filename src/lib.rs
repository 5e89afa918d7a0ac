//! GearRattle: the gear-pair rattle model of Dion, Le Moyne, Chevallier and Sebbah (MSSP
//! 2009) as an FMI 2.0 FMU for Co-Simulation and Model Exchange.
//!
//! Layers, each knowing nothing of the ones above it:
//! - [`math`]: cheap elementary functions for the right-hand side (cube root, sine);
//! - [`physics`]: contact law, equation of motion, excitation (docs/MODEL.md), and the main
//!   shaft's inertia for the torque mode;
//! - [`integrator`]: adaptive DOPRI5, Taylor-series steps and Radau IIA with error control,
//!   dense outputs, the hand-over between them, and edge location;
//! - [`rattle`]: the gear pair as a piecewise ODE for the integrator, with impact counting
//!   (the shaft's motion imposed; [`rattle::torque`]: driven by a torque, 7 states);
//! - [`gearbox`]: the gearbox of docs/GEARBOX.md (up to 8 loose gears behind a clutch damper) as
//!   a piecewise ODE with one guard per gear and one for the damper;
//! - [`instance`]: the slave of fmi2-shell (variables, co-simulation stepping, Model
//!   Exchange's states and events; the shell applies FMI's rules around it);
//! - [`exports!`]: the `fmi2*` C exports of Co-Simulation and Model Exchange, [`fmi2_shell`]'s,
//!   around [`instance::Instance`], and the `fmi3*` ones of FMI 3.0 beside them
//!   ([`fmi3_shell`]'s), written by GearRattle.fmu's binary (fmus/GearRattle);
//! - [`contract`]: value references and the model description, generated from
//!   `modelDescription/GearRattle.toml` (packaged into the .fmu by the workspace's
//!   `packaging` crate).

pub mod contract;
pub mod gearbox;
pub mod instance;
pub mod integrator;
pub mod math;
pub mod physics;
pub mod rattle;

/// Whether this build carries GearRattle's fmi2* and fmi3* exports (the default feature
/// `fmu`, for the tests, the benchmarks and the fuzzer, which call them): the FMUs' binaries
/// (fmus/) link this crate without them.
pub const FMU_EXPORTS: bool = cfg!(feature = "fmu");

/// GearRattle's `fmi2*` and `fmi3*` C exports around [`instance::Instance`] (fmi2-shell's and
/// fmi3-shell's): written here with the feature `fmu`, and by GearRattle.fmu's binary
/// (fmus/GearRattle), which links this crate without it.
#[macro_export]
macro_rules! exports {
    () => {
        ::fmi2_shell::export_co_simulation!($crate::instance::Instance);
        ::fmi2_shell::export_model_exchange!($crate::instance::Instance);
        ::fmi3_shell::export_fmi3!($crate::instance::Instance, $crate::contract);
    };
}

#[cfg(feature = "fmu")]
exports!();
