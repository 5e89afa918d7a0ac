//! Packages target/fmu/Flywheel.fmu: modelDescription.xml (from the contract) and the
//! shared library as binaries/linux64/Flywheel.so.
//!
//!     flywheel-package --lib target/release/libflywheel.so --out target/fmu/Flywheel.fmu

use std::io::Write;
use std::path::PathBuf;

use flywheel::contract::{MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};
use zip::write::SimpleFileOptions;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (mut lib, mut out) = (None, None);
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--lib" => lib = args.next().map(PathBuf::from),
            "--out" => out = args.next().map(PathBuf::from),
            other => {
                return Err(
                    format!("unknown argument {other}; usage: --lib LIB.so --out OUT.fmu").into(),
                );
            }
        }
    }
    let (lib, out) = (lib.ok_or("--lib missing")?, out.ok_or("--out missing")?);
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut zip = zip::ZipWriter::new(std::fs::File::create(&out)?);
    let options = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    zip.start_file("modelDescription.xml", options)?;
    zip.write_all(MODEL_DESCRIPTION_XML.as_bytes())?;
    zip.start_file(
        format!("binaries/linux64/{MODEL_IDENTIFIER}.so"),
        options.unix_permissions(0o755),
    )?;
    zip.write_all(&std::fs::read(&lib)?)?;
    zip.finish()?;
    println!("{}", out.display());
    Ok(())
}
