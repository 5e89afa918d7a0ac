//! Writes `target/fmu/GearRattle.fmu` from the built shared library.
//!
//! Usage: `package [--lib PATH] [--darwin64 PATH] [--win64 PATH] [--out PATH]`; by default
//! the release library of this workspace and `target/fmu/GearRattle.fmu`. Run by `make fmu`
//! with the stripped portable binaries (mk/portable.mk, mk/windows.mk).

use gear_rattle::packaging::{Binary, write_fmu};
use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut lib = root.join("target/release/libgear_rattle.so");
    let mut darwin64 = None;
    let mut win64 = None;
    let mut out = root.join("target/fmu/GearRattle.fmu");
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        let value = args.next().map(PathBuf::from);
        match (flag.as_str(), value) {
            ("--lib", Some(v)) => lib = v,
            ("--darwin64", Some(v)) => darwin64 = Some(v),
            ("--win64", Some(v)) => win64 = Some(v),
            ("--out", Some(v)) => out = v,
            _ => {
                eprintln!(
                    "usage: package [--lib PATH] [--darwin64 PATH] [--win64 PATH] [--out PATH]"
                );
                return ExitCode::FAILURE;
            }
        }
    }
    let mut binaries = vec![Binary {
        platform: "linux64",
        extension: "so",
        path: &lib,
    }];
    if let Some(dylib) = &darwin64 {
        binaries.push(Binary {
            platform: "darwin64",
            extension: "dylib",
            path: dylib,
        });
    }
    if let Some(dll) = &win64 {
        binaries.push(Binary {
            platform: "win64",
            extension: "dll",
            path: dll,
        });
    }
    match write_fmu(&out, &binaries) {
        Ok(()) => {
            println!("wrote {}", out.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!(
                "packaging failed: {e} (is {} built? run `make fmu`)",
                lib.display()
            );
            ExitCode::FAILURE
        }
    }
}
