//! Packaging: the .fmu archive (a zip with the model description, the binaries and the
//! documentation), written with the `zip` crate.

pub mod documentation;

use crate::contract::{MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};
use std::io::Write;
use std::path::Path;
use zip::write::SimpleFileOptions;

/// A binary to put into the FMU, with the platform folder it goes to.
pub struct Binary<'a> {
    /// FMI platform folder: "linux64", "darwin64", "win64".
    pub platform: &'static str,
    /// File extension on that platform: "so", "dylib", "dll".
    pub extension: &'static str,
    pub path: &'a Path,
}

/// Writes the FMU at `out` with the given binaries.
pub fn write_fmu(out: &Path, binaries: &[Binary]) -> std::io::Result<()> {
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut zip = zip::ZipWriter::new(std::fs::File::create(out)?);
    let options = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    zip.start_file("modelDescription.xml", options)?;
    zip.write_all(MODEL_DESCRIPTION_XML.as_bytes())?;
    zip.start_file("documentation/index.html", options)?;
    zip.write_all(documentation::index_html().as_bytes())?;
    zip.start_file("documentation/work_precision.png", options)?;
    zip.write_all(documentation::WORK_PRECISION_PNG)?;
    for b in binaries {
        let name = format!("binaries/{}/{MODEL_IDENTIFIER}.{}", b.platform, b.extension);
        zip.start_file(name, options.unix_permissions(0o755))?;
        zip.write_all(&std::fs::read(b.path)?)?;
    }
    zip.finish()?;
    Ok(())
}
