//! A packed FMU: a copy whose model description carries its own GUID and start values
//! (`gearrattle-study pack`, docs/GEARBOX.md §10) beside this binary. When the importer's
//! GUID (FMI 3.0: instantiationToken) is not the built-in one, instantiation reads the model
//! description beside the resources (FMI 2.0's fmuResourceLocation, a file URI, or FMI 3.0's
//! resourcePath, a directory), or its copy inside them, and takes it if it names that GUID,
//! this binary's model identifier and the contract's variables (names, value references,
//! types, causalities, in the contract's order); its parameters' start values then pass the
//! checks of fmi2Set* and the contract's ranges and become the instance's start values.

use crate::contract::fmi3::{INTEGER_VR_OFFSET, TIME_VR};
use crate::contract::{Causality, Kind, Variable, check_parameter};
use crate::slave::Identity;
use crate::state::FmiState;
use crate::status::FmiError;
use crate::values::Starts;
use std::path::{Path, PathBuf};

/// Why a model description beside the binary is not taken.
#[derive(Debug)]
pub enum Refusal {
    /// There is none, or it describes another model or build.
    Mismatch(String),
    /// It matches, but a start value is one the model refuses.
    Invalid(FmiError),
}

/// The directory of a resource location: a file URI (`file:///C:/a%20b/resources`,
/// `file:/tmp/x/resources`, `file://localhost/...`), its escapes decoded, or a plain path.
pub fn resource_dir(location: &str) -> Option<PathBuf> {
    let Some(rest) = location.strip_prefix("file:") else {
        return (!location.is_empty()).then(|| PathBuf::from(location));
    };
    let path = match rest.strip_prefix("//") {
        // An authority: empty or localhost (other hosts are not this machine's files).
        Some(after) => after.strip_prefix("localhost").unwrap_or(after),
        None => rest,
    };
    if !path.starts_with('/') {
        return None;
    }
    let path = decode(path)?;
    // A Windows drive: /C:/dir is C:/dir.
    let b = path.as_bytes();
    let drive = b.len() >= 3 && b[1].is_ascii_alphabetic() && b[2] == b':';
    Some(PathBuf::from(if drive { &path[1..] } else { &path[..] }))
}

/// A URI path's %XX escapes decoded (None for a broken escape or bytes that are not UTF-8).
fn decode(s: &str) -> Option<String> {
    let mut out = Vec::with_capacity(s.len());
    let mut bytes = s.bytes();
    while let Some(b) = bytes.next() {
        if b == b'%' {
            let hex = [bytes.next()?, bytes.next()?];
            out.push(u8::from_str_radix(std::str::from_utf8(&hex).ok()?, 16).ok()?);
        } else {
            out.push(b);
        }
    }
    String::from_utf8(out).ok()
}

/// Where the model description of an FMU unpacked with its resources in `resources` may be:
/// beside the resources directory, and its copy inside it (which `pack` writes, for the
/// importers that unpack only the binaries and resources, as fmpy's simulate_fmu).
pub fn model_descriptions(resources: &Path) -> Vec<PathBuf> {
    let name = "modelDescription.xml";
    let beside = resources.parent().map(|unzipped| unzipped.join(name));
    beside.into_iter().chain([resources.join(name)]).collect()
}

/// The start values of the model description beside the resource `location` if it is this
/// binary's model packed under `token`.
pub fn starts(id: &Identity, token: &str, location: Option<&str>) -> Result<Starts, Refusal> {
    let mismatch = |why: String| Refusal::Mismatch(why);
    let dir = location
        .and_then(resource_dir)
        .ok_or_else(|| mismatch(format!("resource location {location:?} is no local path")))?;
    let paths = model_descriptions(&dir);
    let (path, xml) = paths
        .iter()
        .find_map(|p| Some((p, std::fs::read_to_string(p).ok()?)))
        .ok_or_else(|| {
            let shown: Vec<_> = paths.iter().map(|p| p.display().to_string()).collect();
            mismatch(format!("no file {}", shown.join(" or ")))
        })?;
    read(id, token, &xml).map_err(|r| match r {
        Refusal::Mismatch(why) => mismatch(format!("{}: {why}", path.display())),
        invalid => invalid,
    })
}

/// One variable as a model description declares it, in the contract's terms.
struct Declared<'a> {
    name: &'a str,
    vr: u32,
    kind: Kind,
    causality: &'a str,
    start: Option<&'a str>,
}

/// The start values of a model description (FMI 2.0 or 3.0) that names `token`, the model
/// identifier and the variables of `id`.
pub fn read(id: &Identity, token: &str, xml: &str) -> Result<Starts, Refusal> {
    let mismatch = |why: String| Refusal::Mismatch(why);
    let doc = roxmltree::Document::parse(xml).map_err(|e| mismatch(e.to_string()))?;
    let root = doc.root_element();
    let fmi3 = root
        .attribute("fmiVersion")
        .is_some_and(|v| v.starts_with('3'));
    let named = root.attribute(if fmi3 { "instantiationToken" } else { "guid" });
    if named != Some(token) {
        return Err(mismatch(format!(
            "it names GUID {}",
            named.unwrap_or("none")
        )));
    }
    let children = |name: &'static str| root.children().filter(move |n| n.has_tag_name(name));
    for interface in children("CoSimulation").chain(children("ModelExchange")) {
        let identifier = interface.attribute("modelIdentifier");
        if identifier != Some(id.model_identifier) {
            return Err(mismatch(format!(
                "its modelIdentifier {identifier:?} is not {}",
                id.model_identifier
            )));
        }
    }
    let declared = children("ModelVariables")
        .flat_map(|m| m.children().filter(|n| n.is_element()))
        .map(|n| declared(n, fmi3))
        .collect::<Result<Vec<_>, String>>()
        .map_err(mismatch)?;
    // FMI 3.0's own variables (time, the event indicators) are not the contract's.
    let declared: Vec<_> = declared
        .into_iter()
        .filter(|d| !(fmi3 && d.vr >= TIME_VR))
        .collect();
    if declared.len() != id.variables.len() {
        return Err(mismatch(format!(
            "it declares {} variables of the contract's kinds, the contract {}",
            declared.len(),
            id.variables.len()
        )));
    }
    let mut starts = Starts::default();
    for (d, v) in declared.iter().zip(id.variables) {
        if (d.name, d.vr, d.kind, d.causality) != (v.name, v.vr, v.kind, causality(v)) {
            return Err(mismatch(format!(
                "variable {} (value reference {}, {:?}, {}) is not the contract's {} ({}, {:?}, {})",
                d.name,
                d.vr,
                d.kind,
                d.causality,
                v.name,
                v.vr,
                v.kind,
                causality(v)
            )));
        }
        if let (Causality::Parameter, Some(start)) = (v.causality, d.start) {
            start_value(v, start, &mut starts).map_err(Refusal::Invalid)?;
        }
    }
    Ok(starts)
}

/// A variable element: FMI 2.0's ScalarVariable with its type element, or FMI 3.0's typed
/// element, its value reference moved back into the contract's space.
fn declared<'a>(n: roxmltree::Node<'a, 'a>, fmi3: bool) -> Result<Declared<'a>, String> {
    let name = n.attribute("name").unwrap_or("");
    let typed = if fmi3 {
        Some(n)
    } else {
        n.children().find(|c| c.is_element())
    };
    let kind = match typed.map(|t| t.tag_name().name()) {
        Some("Real" | "Float64") => Kind::Real,
        Some("Integer" | "Int32" | "Enumeration") => Kind::Integer,
        other => return Err(format!("variable {name} has type {other:?}")),
    };
    let vr = n
        .attribute("valueReference")
        .and_then(|v| v.parse::<u32>().ok())
        .ok_or_else(|| format!("variable {name} has no value reference"))?;
    let vr = match kind {
        Kind::Integer if fmi3 && (INTEGER_VR_OFFSET..TIME_VR).contains(&vr) => {
            vr - INTEGER_VR_OFFSET
        }
        _ => vr,
    };
    Ok(Declared {
        name,
        vr,
        kind,
        causality: n.attribute("causality").unwrap_or("local"),
        start: typed.and_then(|t| t.attribute("start")),
    })
}

/// A contract variable's causality as model descriptions write it.
fn causality(v: &Variable) -> &'static str {
    match v.causality {
        Causality::Parameter => "parameter",
        Causality::Input => "input",
        Causality::Output => "output",
        Causality::Local => "local",
    }
}

/// A parameter's start value read, checked as fmi2SetReal/SetInteger and the contract's
/// range check it, and kept.
fn start_value(v: &Variable, text: &str, starts: &mut Starts) -> Result<(), FmiError> {
    let refused = || {
        FmiError::error(format!(
            "parameter {}: start value {text:?} is not a {:?}",
            v.name, v.kind
        ))
    };
    match v.kind {
        Kind::Real => {
            let x: f64 = text.trim().parse().map_err(|_| refused())?;
            v.settable_to(FmiState::Instantiated, x)?;
            check_parameter(v, x)?;
            starts.real.push((v.vr, x));
        }
        Kind::Integer => {
            let i: i32 = text.trim().parse().map_err(|_| refused())?;
            check_parameter(v, f64::from(i))?;
            starts.integer.push((v.vr, i));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contract::{Bound, Range, Start, unknown};
    use crate::status::FmiResult;

    const fn var(name: &'static str, vr: u32, kind: Kind, causality: Causality) -> Variable {
        Variable {
            name,
            vr,
            kind,
            causality,
            start: Start::None,
            unit: "",
            range: Range {
                min: Bound::Exclusive(0.0),
                max: Bound::Inclusive(8.0),
            },
            depends_on: &[],
            derivative: false,
            description: "",
        }
    }

    static VARIABLES: [Variable; 3] = [
        var("k", 0, Kind::Real, Causality::Parameter),
        var("n", 0, Kind::Integer, Causality::Parameter),
        var("y", 1, Kind::Real, Causality::Output),
    ];

    fn variable(kind: Kind, vr: u32) -> FmiResult<&'static Variable> {
        Err(unknown(kind, vr))
    }

    const ID: Identity = Identity {
        guid: "{built-in}",
        model_identifier: "Model",
        log_categories: &[],
        state_magic: *b"TEST",
        state_version: 1,
        model_exchange: false,
        variable,
        variables: &VARIABLES,
    };

    /// The model's description, FMI 2.0 or 3.0, packed under {packed} with k = `k`.
    fn xml(fmi3: bool, k: &str) -> String {
        if fmi3 {
            format!(
                r#"<fmiModelDescription fmiVersion="3.0" instantiationToken="{{packed}}">
  <CoSimulation modelIdentifier="Model"/>
  <ModelVariables>
    <Float64 name="time" valueReference="2000000" causality="independent"/>
    <Float64 name="k" valueReference="0" causality="parameter" start="{k}"/>
    <Enumeration name="n" valueReference="1000000" causality="parameter" start="3"/>
    <Float64 name="y" valueReference="1" causality="output"/>
  </ModelVariables>
</fmiModelDescription>"#
            )
        } else {
            format!(
                r#"<fmiModelDescription fmiVersion="2.0" guid="{{packed}}">
  <ModelExchange modelIdentifier="Model"/>
  <ModelVariables>
    <ScalarVariable name="k" valueReference="0" causality="parameter"><Real start="{k}"/></ScalarVariable>
    <ScalarVariable name="n" valueReference="0" causality="parameter"><Integer start="3"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="1" causality="output"><Real/></ScalarVariable>
  </ModelVariables>
</fmiModelDescription>"#
            )
        }
    }

    fn refusal(r: Result<Starts, Refusal>) -> String {
        match r {
            Ok(s) => panic!("taken: {s:?}"),
            Err(Refusal::Mismatch(why)) => format!("mismatch: {why}"),
            Err(Refusal::Invalid(e)) => format!("invalid: {}", e.message),
        }
    }

    #[test]
    fn resource_locations_are_file_uris_or_paths() {
        for (location, dir) in [
            ("file:///tmp/a%20b/resources", "/tmp/a b/resources"),
            ("file:/tmp/x/resources/", "/tmp/x/resources/"),
            ("file://localhost/tmp/x", "/tmp/x"),
            (
                "file:///C:/Users/a%C3%A9/resources",
                "C:/Users/aé/resources",
            ),
            ("/tmp/y/resources/", "/tmp/y/resources/"),
        ] {
            assert_eq!(
                resource_dir(location),
                Some(PathBuf::from(dir)),
                "{location}"
            );
        }
        for location in ["", "file://host/x", "file:x", "file:///a%2", "file:///a%zz"] {
            assert_eq!(resource_dir(location), None, "{location}");
        }
        assert_eq!(
            model_descriptions(Path::new("/u/resources/")),
            [
                PathBuf::from("/u/modelDescription.xml"),
                PathBuf::from("/u/resources/modelDescription.xml")
            ]
        );
    }

    #[test]
    fn a_matching_description_gives_its_start_values() {
        for fmi3 in [false, true] {
            let starts = read(&ID, "{packed}", &xml(fmi3, "2.5")).unwrap();
            assert_eq!(starts.real, [(0, 2.5)], "fmi3 {fmi3}");
            assert_eq!(starts.integer, [(0, 3)], "fmi3 {fmi3}");
        }
    }

    #[test]
    fn other_descriptions_and_invalid_starts_are_refused() {
        let ok = xml(false, "2.5");
        for (text, token, why) in [
            (ok.clone(), "{other}", "mismatch: it names GUID {packed}"),
            (ok.replace("\"k\"", "\"K\""), "{packed}", "variable K"),
            (
                ok.replace("\"y\"", "\"y\" causality=\"input\""),
                "{packed}",
                "mismatch",
            ),
            (
                ok.replace("=\"Model\"", "=\"Other\""),
                "{packed}",
                "modelIdentifier",
            ),
            (
                ok.replace("<Real/>", "<Integer/>"),
                "{packed}",
                "variable y",
            ),
            (
                xml(false, "0"),
                "{packed}",
                "invalid: parameter k = 0e0 is invalid: allowed 0 < k <= 8",
            ),
            (xml(true, "inf"), "{packed}", "invalid: k = inf refused"),
            (
                xml(false, "soft"),
                "{packed}",
                "invalid: parameter k: start value \"soft\"",
            ),
            ("<a".to_string(), "{packed}", "mismatch"),
        ] {
            let refused = refusal(read(&ID, token, &text));
            assert!(refused.contains(why), "{refused}");
        }
        let declared = ok.replace("</ModelVariables>", "<ScalarVariable name=\"z\" valueReference=\"2\"><Real/></ScalarVariable></ModelVariables>");
        assert!(refusal(read(&ID, "{packed}", &declared)).contains("declares 4 variables"));
    }

    #[test]
    fn a_missing_description_is_named() {
        let dir = std::env::temp_dir().join(format!("packed-{}", std::process::id()));
        let resources = dir.join("resources");
        std::fs::create_dir_all(&resources).unwrap();
        let location = format!("file://{}", resources.display());
        let refused = refusal(starts(&ID, "{packed}", Some(&location)));
        assert!(refused.contains("no file") && refused.contains("modelDescription.xml"));
        std::fs::write(resources.join("modelDescription.xml"), xml(false, "4")).unwrap();
        let taken = starts(&ID, "{packed}", Some(&location)).unwrap();
        assert_eq!(taken.real, [(0, 4.0)]);
        std::fs::remove_dir_all(dir).unwrap();
    }
}
