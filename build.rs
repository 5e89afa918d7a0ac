//! Build script: the contract `modelDescription/GearRattle.toml` (the one source of truth for
//! the FMU's variables) becomes the model description and the Rust constants the instance
//! uses (fmi2-shell's generator). The FMU's binary (fmus/GearRattle) keeps its exports to the
//! `fmi2*` and `fmi3*` functions.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    fmi2_shell::build::generate("modelDescription/GearRattle.toml");
}
