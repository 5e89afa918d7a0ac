//! GearRattle.fmu's binary: [`gear_rattle`]'s instance behind the `fmi2*` and `fmi3*` C
//! exports (fmi2-shell's and fmi3-shell's), nothing else.

// Built in one cargo call with gear_rattle's default features (`-p gear_rattle` beside this
// crate), gear_rattle would carry the same exports.
const _: () = assert!(
    !gear_rattle::FMU_EXPORTS,
    "gear_rattle is built with its exports (feature `fmu`): build gear_rattle_fmu without -p gear_rattle"
);

gear_rattle::exports!();
