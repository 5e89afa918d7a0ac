//! GearboxRattle.fmu's binary: [`gearbox_rattle`]'s instance behind the `fmi2*` and `fmi3*` C
//! exports (fmi2-shell's and fmi3-shell's), nothing else.

// Built in one cargo call with gear_rattle's default features (`-p gear_rattle` beside this
// crate), the gear pair's exports would be linked beside these.
const _: () = assert!(
    !gear_rattle::FMU_EXPORTS,
    "gear_rattle is built with its exports (feature `fmu`): build gearbox_rattle_fmu without -p gear_rattle"
);

fmi2_shell::export_co_simulation!(gearbox_rattle::instance::Instance);
fmi2_shell::export_model_exchange!(gearbox_rattle::instance::Instance);
fmi3_shell::export_fmi3!(gearbox_rattle::instance::Instance, gearbox_rattle::contract);
