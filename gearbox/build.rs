//! Build script: the contract `modelDescription/GearboxRattle.toml` becomes the model
//! description and the Rust constants the instance uses (fmi2-shell's generator).

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    fmi2_shell::build::generate("../modelDescription/GearboxRattle.toml");
}
