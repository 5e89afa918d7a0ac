//! Build script: the contract `modelDescription/Flywheel.toml` becomes the model description
//! and the Rust constants (fmi2-shell's generator), and the cdylib exports only `fmi2*`.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    fmi2_shell::build::generate("modelDescription/Flywheel.toml");
    fmi2_shell::build::restrict_exports();
}
