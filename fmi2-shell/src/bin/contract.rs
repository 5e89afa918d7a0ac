//! Writes a contract's model descriptions and Rust constants (what a model's build script
//! generates) to a directory: `contract TOML DIR` gives DIR/modelDescription.xml (FMI 2.0),
//! DIR/fmi3/modelDescription.xml (FMI 3.0) and DIR/contract.rs.

use std::{env, fs, path::PathBuf};

fn main() {
    let args: Vec<String> = env::args().skip(1).collect();
    let [toml, dir] = &args[..] else {
        eprintln!("usage: contract CONTRACT.toml DIR");
        std::process::exit(2);
    };
    let text = fs::read_to_string(toml).unwrap_or_else(|e| panic!("{toml}: {e}"));
    let (xml, rust) = fmi2_shell::build::outputs(&text).unwrap_or_else(|e| panic!("{toml}: {e}"));
    let xml3 = fmi2_shell::build::fmi3_description(&text).unwrap_or_else(|e| panic!("{toml}: {e}"));
    let dir = PathBuf::from(dir);
    fs::create_dir_all(dir.join("fmi3")).unwrap();
    fs::write(dir.join("modelDescription.xml"), xml).unwrap();
    fs::write(dir.join("fmi3/modelDescription.xml"), xml3).unwrap();
    fs::write(dir.join("contract.rs"), rust).unwrap();
}
