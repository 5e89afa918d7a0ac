//! Build script: the contract `modelDescription/GearRattle.toml` (the one source of truth for
//! the FMU's variables) becomes the model description and the Rust constants the instance
//! uses (fmi2-shell's generator), and a cdylib of it (the benchmarks') exports only the `fmi2*`
//! and `fmi3*` functions.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    fmi2_shell::build::generate("modelDescription/GearRattle.toml");
    fmi2_shell::build::restrict_exports();
}
