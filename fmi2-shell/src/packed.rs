//! A packed FMU: a copy whose model description carries its own GUID and start values
//! (`gearrattle-study pack`, docs/GEARBOX.md §10) beside this binary. When the importer's
//! GUID (FMI 3.0: instantiationToken) is not the built-in one, instantiation reads the model
//! description beside the resources (FMI 2.0's fmuResourceLocation, a file URI, or FMI 3.0's
//! resourcePath, a directory), or its copy inside them, and takes it if it names that GUID,
//! this binary's model identifier and the contract's variables (names, value references,
//! types, causalities, in the contract's order); its parameters' start values then pass the
//! checks of fmi2Set* and the contract's ranges and become the instance's start values.
//! FMI 3.0 declares each variable of an array once (`gear.I_L`, docs/DECISIONS.md D46): its
//! start lists elements 1..n, n the start of its structural parameter (`n_gears`, a UInt64),
//! and each element's value is taken as that element's start value.

use crate::contract::fmi3::{Array, INTEGER_VR_OFFSET, TIME_VR};
use crate::contract::{Causality, Kind, Start, Variable, check_parameter};
use crate::slave::Identity;
use crate::state::FmiState;
use crate::status::{FmiError, FmiResult};
use crate::values::Starts;
use std::borrow::Cow;
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
    /// Declared as FMI 3.0's UInt64 (a structural parameter).
    size: bool,
    causality: &'a str,
    start: Option<&'a str>,
}

/// A contract variable as a model description declares it: in FMI 2.0 as it is; in FMI 3.0
/// an array's variable once, as its element 1 renamed (`gear[1].I_L` is `gear.I_L`) at the
/// array's reference, its other elements not at all, and an array's size as a structural
/// parameter.
struct Expected<'c> {
    var: &'c Variable,
    name: Cow<'c, str>,
    vr: u32,
    size: bool,
    causality: &'static str,
    /// The array and the offset of an FMI 3.0 array variable.
    array: Option<(&'c Array, u32)>,
}

/// `v` as a model description (FMI 3.0 if `fmi3`) declares it, if it does.
fn expected<'c>(v: &'c Variable, fmi3: bool, arrays: &'c [Array]) -> Option<Expected<'c>> {
    let mut e = Expected {
        var: v,
        name: Cow::Borrowed(v.name),
        vr: v.vr,
        size: false,
        causality: causality(v),
        array: None,
    };
    if !fmi3 {
        return Some(e);
    }
    if v.kind == Kind::Integer && arrays.iter().any(|a| a.size_vr == v.vr) {
        e.size = true;
        e.causality = "structuralParameter";
    }
    if let Some((a, (i, k))) = arrays.iter().find_map(|a| Some((a, a.element(v.vr)?))) {
        if i > 1 {
            return None;
        }
        e.name = Cow::Owned(v.name.replacen("[1].", ".", 1));
        e.vr = a.vr_base + k;
        e.array = Some((a, k));
    }
    Some(e)
}

/// The type a model description gives a variable, as a refusal names it.
fn type_name(kind: Kind, size: bool) -> &'static str {
    match (kind, size) {
        (_, true) => "UInt64",
        (Kind::Real, false) => "Real",
        (Kind::Integer, false) => "Integer",
    }
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
    let expected: Vec<_> = id
        .variables
        .iter()
        .filter_map(|v| expected(v, fmi3, id.arrays))
        .collect();
    if declared.len() != expected.len() {
        return Err(mismatch(format!(
            "it declares {} variables of the contract's kinds, the contract {}",
            declared.len(),
            expected.len()
        )));
    }
    let mut starts = Starts::default();
    let mut lists = Vec::new();
    for (d, e) in declared.iter().zip(&expected) {
        let v = e.var;
        if (d.name, d.vr, d.kind, d.size, d.causality)
            != (&*e.name, e.vr, v.kind, e.size, e.causality)
        {
            return Err(mismatch(format!(
                "variable {} (value reference {}, {}, {}) is not the contract's {} ({}, {}, {})",
                d.name,
                d.vr,
                type_name(d.kind, d.size),
                d.causality,
                e.name,
                e.vr,
                type_name(v.kind, e.size),
                e.causality
            )));
        }
        match (v.causality, d.start, e.array) {
            (Causality::Parameter, Some(start), None) => {
                start_value(v, start, &mut starts).map_err(Refusal::Invalid)?;
            }
            (Causality::Parameter, Some(list), Some((a, k))) => lists.push((e, a, k, list)),
            _ => {}
        }
    }
    // The arrays' lengths are their structural parameters' starts, all read by now.
    for (e, a, k, list) in lists {
        array_start(id, e, a, k, list, &mut starts).map_err(Refusal::Invalid)?;
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
    let (kind, size) = match typed.map(|t| t.tag_name().name()) {
        Some("Real" | "Float64") => (Kind::Real, false),
        Some("Integer" | "Int32" | "Enumeration") => (Kind::Integer, false),
        Some("UInt64") if fmi3 => (Kind::Integer, true),
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
        size,
        causality: n.attribute("causality").unwrap_or("local"),
        start: typed.and_then(|t| t.attribute("start")),
    })
}

/// An FMI 3.0 array parameter's start `list`: one value for each of the array's elements
/// 1..n (n its structural parameter's start, the description's or else the contract's), each
/// the start value of that element's variable ([`start_value`]), as fmi3SetFloat64 sets an
/// array element by element.
fn array_start(
    id: &Identity,
    e: &Expected,
    a: &Array,
    k: u32,
    list: &str,
    starts: &mut Starts,
) -> FmiResult {
    let size = (id.variable)(Kind::Integer, a.size_vr)?;
    let n = match starts.integer.iter().find(|(vr, _)| *vr == a.size_vr) {
        Some(&(_, n)) => i64::from(n),
        None => match size.start {
            Start::Integer(n) => n,
            _ => 0,
        },
    };
    let values: Vec<&str> = list.split_whitespace().collect();
    if values.len() != n as usize {
        return Err(FmiError::error(format!(
            "parameter {}: {} start values for {} = {n}",
            e.name,
            values.len(),
            size.name
        )));
    }
    for (vr, text) in a.elements(k, values.len()).zip(values) {
        start_value((id.variable)(e.var.kind, vr)?, text, starts)?;
    }
    Ok(())
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
        arrays: &[],
    };

    /// A model with an array `g` of two elements sized by `n` (1 <= n <= 2, start 2): g[i].m
    /// at 10 + 10 i.
    static GEARED: [Variable; 5] = [
        var("k", 0, Kind::Real, Causality::Parameter),
        Variable {
            start: Start::Integer(2),
            range: Range {
                min: Bound::Inclusive(1.0),
                max: Bound::Inclusive(2.0),
            },
            ..var("n", 0, Kind::Integer, Causality::Parameter)
        },
        var("g[1].m", 20, Kind::Real, Causality::Parameter),
        var("g[2].m", 30, Kind::Real, Causality::Parameter),
        var("y", 1, Kind::Real, Causality::Output),
    ];

    fn geared(kind: Kind, vr: u32) -> FmiResult<&'static Variable> {
        GEARED
            .iter()
            .find(|v| (v.kind, v.vr) == (kind, vr))
            .ok_or_else(|| unknown(kind, vr))
    }

    const GEARED_ID: Identity = Identity {
        variable: geared,
        variables: &GEARED,
        arrays: &[Array {
            size_vr: 0,
            size: 2,
            vr_base: 10,
            vr_stride: 10,
        }],
        ..ID
    };

    /// An FMI 3.0 description packed under {packed}: the time, then `variables`.
    fn fmi3_xml(variables: &str) -> String {
        format!(
            r#"<fmiModelDescription fmiVersion="3.0" instantiationToken="{{packed}}">
  <CoSimulation modelIdentifier="Model"/>
  <ModelVariables>
    <Float64 name="time" valueReference="2000000" causality="independent"/>
{variables}
  </ModelVariables>
</fmiModelDescription>"#
        )
    }

    /// GEARED's FMI 3.0 description packed under {packed}: `n` the structural parameter's
    /// attributes after its name, `m` the array's start list.
    fn geared_xml(n: &str, m: &str) -> String {
        fmi3_xml(&format!(
            r#"    <Float64 name="k" valueReference="0" causality="parameter" start="1"/>
    <UInt64 name="n" valueReference="1000000" {n}/>
    <Float64 name="g.m" valueReference="10" causality="parameter" start="{m}">
      <Dimension valueReference="1000000"/>
    </Float64>
    <Float64 name="y" valueReference="1" causality="output"/>"#
        ))
    }

    /// The model's description, FMI 2.0 or 3.0, packed under {packed} with k = `k`.
    fn xml(fmi3: bool, k: &str) -> String {
        if fmi3 {
            fmi3_xml(&format!(
                r#"    <Float64 name="k" valueReference="0" causality="parameter" start="{k}"/>
    <Enumeration name="n" valueReference="1000000" causality="parameter" start="3"/>
    <Float64 name="y" valueReference="1" causality="output"/>"#
            ))
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
    fn an_fmi3_array_gives_its_elements_start_values() {
        let structural = |n: &str| format!("causality=\"structuralParameter\" start=\"{n}\"");
        for (n, m, real, integer) in [
            (
                structural("2"),
                "0.5 0.25",
                vec![(20, 0.5), (30, 0.25)],
                vec![(0, 2)],
            ),
            (structural("1"), "0.5", vec![(20, 0.5)], vec![(0, 1)]),
            // Without a start of its own, n is the contract's.
            (
                "causality=\"structuralParameter\"".to_string(),
                "0.5 0.25",
                vec![(20, 0.5), (30, 0.25)],
                vec![],
            ),
        ] {
            let starts = read(&GEARED_ID, "{packed}", &geared_xml(&n, m)).unwrap();
            assert_eq!(starts.real, [vec![(0, 1.0)], real].concat(), "{n} {m}");
            assert_eq!(starts.integer, integer, "{n} {m}");
        }
    }

    #[test]
    fn an_fmi3_array_of_another_length_or_shape_is_refused() {
        let structural = "causality=\"structuralParameter\" start=\"2\"";
        for (text, why) in [
            (
                geared_xml(structural, "0.5"),
                "invalid: parameter g.m: 1 start values for n = 2",
            ),
            (
                geared_xml(
                    "causality=\"structuralParameter\" start=\"3\"",
                    "0.5 0.25 1",
                ),
                "invalid: parameter n = 3 is invalid: allowed 1 <= n <= 2",
            ),
            (
                geared_xml(structural, "0.5 -1"),
                "invalid: parameter g[2].m = -1e0 is invalid",
            ),
            (
                geared_xml(structural, "0.5 soft"),
                "invalid: parameter g[2].m: start value \"soft\"",
            ),
            (
                geared_xml(structural, "0.5 0.25").replace("UInt64", "Int32"),
                "mismatch: variable n (value reference 0, Integer, structuralParameter) is not the contract's n (0, UInt64, structuralParameter)",
            ),
            (
                geared_xml("causality=\"parameter\" start=\"2\"", "0.5 0.25"),
                "mismatch: variable n",
            ),
            // The elements declared one by one, as FMI 2.0 does.
            (
                geared_xml(structural, "0.5 0.25").replace("\"g.m\"", "\"g[1].m\""),
                "mismatch: variable g[1].m",
            ),
        ] {
            let refused = refusal(read(&GEARED_ID, "{packed}", &text));
            assert!(refused.contains(why), "{refused}");
        }
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
