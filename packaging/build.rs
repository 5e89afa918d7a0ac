//! Build script: the model description and the variables of each FMU the packaging binary
//! knows, from its contract by fmi2-shell's generator (the one the FMU's own build script
//! runs, so that the XML packaged is the one its binary was built with), each into a folder of
//! its own in OUT_DIR.

use std::fs;
use std::path::PathBuf;

/// The models' identifiers and contracts, relative to this crate.
const CONTRACTS: [(&str, &str); 3] = [
    ("GearRattle", "../modelDescription/GearRattle.toml"),
    ("GearboxRattle", "../modelDescription/GearboxRattle.toml"),
    (
        "Flywheel",
        "../partners/flywheel/modelDescription/Flywheel.toml",
    ),
];

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    for (model, contract) in CONTRACTS {
        println!("cargo:rerun-if-changed={contract}");
        let text = fs::read_to_string(contract).unwrap_or_else(|e| panic!("{contract}: {e}"));
        let (xml, rust) =
            fmi2_shell::build::outputs(&text).unwrap_or_else(|e| panic!("{contract}: {e}"));
        let dir = out.join(model);
        fs::create_dir_all(&dir).unwrap();
        fs::write(dir.join("modelDescription.xml"), xml).unwrap();
        fs::write(dir.join("contract.rs"), rust).unwrap();
    }
}
