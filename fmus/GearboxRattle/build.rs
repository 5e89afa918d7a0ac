//! Build script: the cdylib exports only the `fmi2*` and `fmi3*` functions.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    fmi2_shell::build::restrict_exports();
}
