//! Writes the .fmu of one of the workspace's FMUs from its built shared library.
//!
//! Usage: `package --model ID [--lib PATH] [--darwin64 PATH] [--win64 PATH] [--out PATH]`,
//! ID one of the models of `packaging::models` (GearRattle, GearboxRattle, Flywheel); by default the
//! model's release library of this workspace and `target/fmu/ID.fmu`. Run by `make fmu`
//! with the stripped portable binaries (mk/portable.mk, mk/windows.mk) and by
//! `make flywheel-fmu` (mk/masters.mk).

use packaging::{Binary, Model, models, write_fmu};
use std::path::PathBuf;
use std::process::ExitCode;

fn usage() -> ExitCode {
    let ids: Vec<_> = models::all().iter().map(|m| m.identifier).collect();
    eprintln!(
        "usage: package --model {} [--lib PATH] [--darwin64 PATH] [--win64 PATH] [--out PATH]",
        ids.join("|")
    );
    ExitCode::FAILURE
}

fn main() -> ExitCode {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut model: Option<Model> = None;
    let mut lib = None;
    let mut darwin64 = None;
    let mut win64 = None;
    let mut out = None;
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        let value = args.next();
        match (flag.as_str(), value) {
            ("--model", Some(id)) => match models::all().into_iter().find(|m| m.identifier == id) {
                Some(m) => model = Some(m),
                None => return usage(),
            },
            ("--lib", Some(v)) => lib = Some(PathBuf::from(v)),
            ("--darwin64", Some(v)) => darwin64 = Some(PathBuf::from(v)),
            ("--win64", Some(v)) => win64 = Some(PathBuf::from(v)),
            ("--out", Some(v)) => out = Some(PathBuf::from(v)),
            _ => return usage(),
        }
    }
    let Some(model) = model else {
        return usage();
    };
    let lib = lib.unwrap_or_else(|| root.join(format!("target/release/lib{}.so", model.library)));
    let out = out.unwrap_or_else(|| root.join(format!("target/fmu/{}.fmu", model.identifier)));
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
    match write_fmu(&out, &model, &binaries) {
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
