//! Packaging: the .fmu archive of each FMU of the workspace (a zip with the model
//! description, the binaries and the documentation), written with the `zip` crate. It lives
//! here, in the packaging binary's crate, so that no FMU's library links `zip`; the model
//! descriptions come from the contracts, not from the FMUs' libraries (whose C exports would
//! clash if one binary linked two of them).

pub mod contracts;
pub mod documentation;
pub mod gearbox_documentation;
pub mod models;

use std::io::Write;
use std::path::Path;
use zip::write::SimpleFileOptions;

/// What an FMU archive holds besides its binaries.
pub struct Model {
    /// The modelIdentifier: the binaries' file name and the FMU's default name.
    pub identifier: &'static str,
    /// The Cargo library target whose shared library is the FMU's binary (`lib<name>.so`).
    pub library: &'static str,
    pub model_description: &'static str,
    /// The files under `documentation/`, by name.
    pub documentation: Vec<(&'static str, Vec<u8>)>,
}

/// A binary to put into the FMU, with the platform folder it goes to.
pub struct Binary<'a> {
    /// FMI platform folder: "linux64", "darwin64", "win64".
    pub platform: &'static str,
    /// File extension on that platform: "so", "dylib", "dll".
    pub extension: &'static str,
    pub path: &'a Path,
}

/// Writes the FMU of `model` at `out` with the given binaries.
pub fn write_fmu(out: &Path, model: &Model, binaries: &[Binary]) -> std::io::Result<()> {
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut zip = zip::ZipWriter::new(std::fs::File::create(out)?);
    let options = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    zip.start_file("modelDescription.xml", options)?;
    zip.write_all(model.model_description.as_bytes())?;
    for (name, bytes) in &model.documentation {
        zip.start_file(format!("documentation/{name}"), options)?;
        zip.write_all(bytes)?;
    }
    for b in binaries {
        let name = format!(
            "binaries/{}/{}.{}",
            b.platform, model.identifier, b.extension
        );
        zip.start_file(name, options.unix_permissions(0o755))?;
        zip.write_all(&std::fs::read(b.path)?)?;
    }
    zip.finish()?;
    Ok(())
}
