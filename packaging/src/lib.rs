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
    /// The FMI 3.0 model description, for a model that offers FMI 3.0 (its library exports
    /// the `fmi3*` functions beside the `fmi2*` ones).
    pub model_description_fmi3: Option<&'static str>,
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

/// The edition of FMI an archive is written for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Edition {
    Fmi2,
    Fmi3,
}

/// The folders under `binaries/` of a binary built for FMI 2.0's `platform`: FMI 3.0 names
/// platforms by architecture and system, and the universal darwin64 binary serves both of
/// its architectures.
fn folders(edition: Edition, platform: &'static str) -> Vec<&'static str> {
    match (edition, platform) {
        (Edition::Fmi2, _) => vec![platform],
        (Edition::Fmi3, "linux64") => vec!["x86_64-linux"],
        (Edition::Fmi3, "win64") => vec!["x86_64-windows"],
        (Edition::Fmi3, "darwin64") => vec!["x86_64-darwin", "aarch64-darwin"],
        (Edition::Fmi3, other) => panic!("no FMI 3.0 platform for {other}"),
    }
}

/// Writes the FMU of `model` at `out` with the given binaries, for FMI 2.0.
pub fn write_fmu(out: &Path, model: &Model, binaries: &[Binary]) -> std::io::Result<()> {
    write_edition(out, model, binaries, Edition::Fmi2)
}

/// Writes the FMU of `model` at `out` with the given binaries, for `edition` (FMI 3.0: the
/// same binaries with FMI 3.0's model description and platform folders).
pub fn write_edition(
    out: &Path,
    model: &Model,
    binaries: &[Binary],
    edition: Edition,
) -> std::io::Result<()> {
    let description = match edition {
        Edition::Fmi2 => model.model_description,
        Edition::Fmi3 => model.model_description_fmi3.ok_or_else(|| {
            std::io::Error::other(format!("{} offers no FMI 3.0", model.identifier))
        })?,
    };
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut zip = zip::ZipWriter::new(std::fs::File::create(out)?);
    let options = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    zip.start_file("modelDescription.xml", options)?;
    zip.write_all(description.as_bytes())?;
    for (name, bytes) in &model.documentation {
        zip.start_file(format!("documentation/{name}"), options)?;
        zip.write_all(bytes)?;
    }
    for b in binaries {
        let bytes = std::fs::read(b.path)?;
        for folder in folders(edition, b.platform) {
            let name = format!("binaries/{folder}/{}.{}", model.identifier, b.extension);
            zip.start_file(name, options.unix_permissions(0o755))?;
            zip.write_all(&bytes)?;
        }
    }
    zip.finish()?;
    Ok(())
}
