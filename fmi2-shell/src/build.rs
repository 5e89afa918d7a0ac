//! Build-time generator (feature "build"), for the FMUs' build scripts: turns a contract
//! TOML (the one source of truth for a model's variables, units and capabilities) into
//!   - `$OUT_DIR/modelDescription.xml`, the FMI 2.0 model description packaged in the FMU;
//!   - `$OUT_DIR/contract.rs`, the value references, start values, causalities, log
//!     categories and GUID the model uses (included by its `contract` module after
//!     `use fmi2_shell::contract::*`);
//!
//! and restricts the cdylib's exports to the `fmi2*` and `fmi3*` functions ([`restrict_exports`]).
//!
//! The GUID is a hash of the contract file, so the XML and the binary always carry the same
//! one and any change of the contract changes it.
//!
//! Arrays: a contract may declare `[[array]]` (name, size, vr_base, vr_stride) and variables
//! with `array = NAME`, declared once and expanded for elements i = 1..size as `NAME[i].VAR`
//! (`der(NAME[i].VAR)` for a derivative: FMI 2.0's structured names), value reference
//! vr_base + vr_stride i + vr (the declared `vr` is the offset in the element's block), start
//! one value for all or a list of one per element. In `depends_on` and `derivative_of`, an
//! array's variable named bare means the same element's, and `NAME[*].VAR` every element's.
//! Consecutive declarations of one array expand element by element. The Rust constants give
//! each array a module, `vr::NAME`, with the value references as arrays (`vr::gear::I_L[i - 1]`).
//! FMI 3.0 declares each array variable once, sized by the Integer parameter `n_NAMEs`
//! (`n_gears`, a structural parameter there; [`fmi3`]), and `FMI3_ARRAYS` tells fmi3-shell.

mod fmi3;

use crate::contract::{Bound, Range};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::{env, fs, path::PathBuf};

#[derive(Deserialize)]
struct Contract {
    model: Model,
    capabilities: BTreeMap<String, toml::Value>,
    /// Model Exchange's capabilities, where the model offers it.
    model_exchange: Option<BTreeMap<String, toml::Value>>,
    experiment: BTreeMap<String, f64>,
    log_categories: Vec<(String, String)>,
    unit: Vec<Unit>,
    #[serde(default)]
    array: Vec<Array>,
    variable: Vec<Variable>,
}

/// Elements (gear[1] .. gear[8]) whose variables are declared once.
#[derive(Deserialize)]
struct Array {
    name: String,
    size: usize,
    vr_base: u32,
    vr_stride: u32,
}

impl Array {
    /// The Integer parameter that gives the array's length in FMI 3.0 (its structural
    /// parameter): `n_gears` for `gear`.
    fn size_parameter(&self) -> String {
        format!("n_{}s", self.name)
    }

    /// Element i's variable: `gear[i].xi`, and `der(gear[i].xi)` for `der(xi)`.
    fn element_name(&self, i: usize, name: &str) -> String {
        match name.strip_prefix("der(").and_then(|n| n.strip_suffix(')')) {
            Some(state) => format!("der({}[{i}].{state})", self.name),
            None => format!("{}[{i}].{name}", self.name),
        }
    }
}

/// Where an expanded variable comes from: its array, element (1-based) and declared name.
#[derive(Clone)]
struct Element {
    array: String,
    index: usize,
    declared: String,
}

#[derive(Deserialize)]
struct Model {
    name: String,
    identifier: String,
    description: String,
    version: String,
    author: String,
    /// Number of event indicators (Model Exchange).
    #[serde(default)]
    event_indicators: usize,
}

#[derive(Deserialize)]
struct Unit {
    name: String,
    base: BTreeMap<String, i32>,
    /// A unit that is not SI's: value in SI = factor * value + offset (BaseUnit's attributes).
    factor: Option<f64>,
    offset: Option<f64>,
    #[serde(default)]
    display: Vec<DisplayUnit>,
}

#[derive(Deserialize)]
struct DisplayUnit {
    name: String,
    factor: f64,
}

#[derive(Clone, Deserialize)]
struct Variable {
    name: String,
    vr: u32,
    /// The array this variable is declared once for (its `vr` then an offset).
    array: Option<String>,
    /// Set by the expansion of arrays.
    #[serde(skip)]
    element: Option<Element>,
    #[serde(rename = "type")]
    ty: String,
    causality: String,
    description: String,
    start: Option<toml::Value>,
    unit: Option<String>,
    display_unit: Option<String>,
    /// Inclusive bounds, written to the XML as min and max.
    min: Option<toml::Value>,
    max: Option<toml::Value>,
    /// Exclusive bounds (I_L > 0: `min_exclusive = 0.0`), Real variables only: the XML
    /// carries the nearest double inside the range as min or max.
    min_exclusive: Option<f64>,
    max_exclusive: Option<f64>,
    depends_on: Option<Vec<String>>,
    /// The FMU gives this output's first time derivative (fmi2GetRealOutputDerivatives).
    #[serde(default)]
    derivative: bool,
    /// Model Exchange: this variable is the time derivative of the continuous state named
    /// here; the order of these variables is the order of the state vector.
    derivative_of: Option<String>,
    /// An Integer's values by name and description, numbered from its `min` (0 without
    /// one): an Enumeration in FMI 3.0 (FMI 2.0's description states them).
    items: Option<Vec<(String, String)>>,
}

/// A TOML number as f64 (integers are exact up to 2^53).
fn number(v: &toml::Value) -> f64 {
    v.as_float()
        .or(v.as_integer().map(|i| i as f64))
        .expect("a number")
}

impl Variable {
    /// The range the contract gives, inclusive and exclusive bounds together.
    fn range(&self) -> Range {
        let bound = |inclusive: &Option<toml::Value>, exclusive: Option<f64>| match (
            inclusive, exclusive,
        ) {
            (Some(b), None) => Bound::Inclusive(number(b)),
            (None, Some(b)) => Bound::Exclusive(b),
            (None, None) => Bound::None,
            (Some(_), Some(_)) => panic!(
                "{}: an inclusive and an exclusive bound on one side",
                self.name
            ),
        };
        Range {
            min: bound(&self.min, self.min_exclusive),
            max: bound(&self.max, self.max_exclusive),
        }
    }

    /// The description in the model description: the contract's, with the range stated.
    fn full_description(&self) -> String {
        let statement = self.range().statement(&self.name);
        if statement.is_empty() {
            self.description.clone()
        } else {
            format!("{} (range: {statement})", self.description)
        }
    }

    /// The value of the first of the `items`: the `min`, else 0.
    fn first_item(&self) -> i64 {
        self.min
            .as_ref()
            .map_or(0, |m| m.as_integer().expect("an Integer's min"))
    }

    fn variability(&self) -> &'static str {
        match (self.causality.as_str(), self.ty.as_str()) {
            ("parameter" | "structuralParameter", _) => "fixed",
            (_, "Integer") => "discrete",
            _ => "continuous",
        }
    }
}

/// Generates the model description and the Rust constants of the contract at `path`
/// (relative to the crate's manifest directory), and asks cargo to rerun when it changes.
pub fn generate(path: &str) {
    println!("cargo:rerun-if-changed={path}");
    let text = fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let out = PathBuf::from(env::var("OUT_DIR").unwrap());
    let (xml, rust) = outputs(&text).unwrap_or_else(|e| panic!("{path}: {e}"));
    fs::write(out.join("modelDescription.xml"), xml).unwrap();
    fs::write(out.join("contract.rs"), rust).unwrap();
}

/// The model description and the Rust constants of a contract's text.
pub fn outputs(text: &str) -> Result<(String, String), toml::de::Error> {
    let mut contract: Contract = toml::from_str(text)?;
    expand(&mut contract);
    check(&contract);
    let guid = guid_of(text);
    Ok((xml(&contract, &guid), rust(&contract, &guid)))
}

/// The FMI 3.0 model description of a contract's text, with the same GUID as its
/// instantiationToken.
pub fn fmi3_description(text: &str) -> Result<String, toml::de::Error> {
    let mut contract: Contract = toml::from_str(text)?;
    expand(&mut contract);
    check(&contract);
    Ok(fmi3::xml(&contract, &guid_of(text)))
}

/// Replaces each array's declarations by its elements' variables, and `NAME[*].VAR` in every
/// `depends_on` by each element's.
fn expand(c: &mut Contract) {
    let declared = std::mem::take(&mut c.variable);
    let mut expanded = Vec::new();
    let mut k = 0;
    while k < declared.len() {
        let Some(name) = &declared[k].array else {
            let mut v = declared[k].clone();
            v.depends_on = v.depends_on.map(|d| resolve(&c.array, &d));
            expanded.push(v);
            k += 1;
            continue;
        };
        let array = c
            .array
            .iter()
            .find(|a| &a.name == name)
            .unwrap_or_else(|| panic!("{}: no [[array]] named {name}", declared[k].name));
        let members: Vec<&str> = declared
            .iter()
            .filter(|v| v.array.as_ref() == Some(name))
            .map(|v| v.name.as_str())
            .collect();
        let block = declared[k..]
            .iter()
            .take_while(|v| v.array.as_ref() == Some(name))
            .count();
        for i in 1..=array.size {
            for v in &declared[k..k + block] {
                expanded.push(element(v, array, i, &members, &c.array));
            }
        }
        k += block;
    }
    c.variable = expanded;
}

/// Element i of an array variable.
fn element(v: &Variable, array: &Array, i: usize, members: &[&str], arrays: &[Array]) -> Variable {
    assert!(
        v.vr < array.vr_stride,
        "{}: offset {} is not below the array's vr_stride {}",
        v.name,
        v.vr,
        array.vr_stride
    );
    let own = |name: &String| {
        if members.contains(&name.as_str()) {
            array.element_name(i, name)
        } else {
            name.clone()
        }
    };
    let start = match &v.start {
        Some(toml::Value::Array(values)) => {
            assert!(
                values.len() == array.size,
                "{}: {} start values for {} elements",
                v.name,
                values.len(),
                array.size
            );
            Some(values[i - 1].clone())
        }
        other => other.clone(),
    };
    Variable {
        name: array.element_name(i, &v.name),
        vr: array.vr_base + array.vr_stride * i as u32 + v.vr,
        array: None,
        element: Some(Element {
            array: array.name.clone(),
            index: i,
            declared: v.name.clone(),
        }),
        start,
        description: v.description.replace("{i}", &i.to_string()),
        depends_on: v
            .depends_on
            .as_ref()
            .map(|d| resolve(arrays, &d.iter().map(own).collect::<Vec<_>>())),
        derivative_of: v.derivative_of.as_ref().map(own),
        ..v.clone()
    }
}

/// `depends_on` with each `NAME[*].VAR` replaced by every element's variable.
fn resolve(arrays: &[Array], names: &[String]) -> Vec<String> {
    names
        .iter()
        .flat_map(|d| {
            let every = arrays.iter().find_map(|a| {
                d.strip_prefix(&format!("{}[*].", a.name))
                    .map(|var| (1..=a.size).map(|i| a.element_name(i, var)).collect())
            });
            every.unwrap_or_else(|| vec![d.clone()])
        })
        .collect()
}

/// Refuses a contract that would give an invalid or ambiguous FMU.
fn check(c: &Contract) {
    // The shell's log keeps a model's errors and warnings at these indices.
    for (i, name) in [
        (crate::log::ERRORS, "logStatusError"),
        (crate::log::WARNINGS, "logStatusWarning"),
    ] {
        assert!(
            c.log_categories.get(i).is_some_and(|(n, _)| n == name),
            "log category {i} must be {name}: errors first, then warnings"
        );
    }
    for a in &c.array {
        let n = a.size_parameter();
        assert!(
            c.variable.iter().any(|v| v.name == n
                && v.ty == "Integer"
                && v.causality == "parameter"
                && v.max.as_ref().and_then(toml::Value::as_integer) == Some(a.size as i64)),
            "array {}: FMI 3.0 sizes it by the Integer parameter {n} with max = {}",
            a.name,
            a.size
        );
    }
    let mut seen = BTreeMap::new();
    for v in &c.variable {
        assert!(
            seen.insert((v.ty.clone(), v.vr), &v.name).is_none(),
            "value reference {} used twice for type {}",
            v.vr,
            v.ty
        );
        assert!(
            ["parameter", "input", "output", "local"].contains(&v.causality.as_str()),
            "{}: unknown causality {}",
            v.name,
            v.causality
        );
        assert!(
            ["Real", "Integer"].contains(&v.ty.as_str()),
            "{}: unknown type {}",
            v.name,
            v.ty
        );
        assert!(
            ["output", "local"].contains(&v.causality.as_str()) || v.start.is_some(),
            "{}: parameters and inputs need a start value",
            v.name
        );
        if let Some(u) = &v.unit {
            assert!(
                c.unit.iter().any(|d| &d.name == u),
                "{}: unit {u} is not defined",
                v.name
            );
        }
        assert!(
            v.ty == "Real" || (v.min_exclusive.is_none() && v.max_exclusive.is_none()),
            "{}: exclusive bounds are for Real variables (an Integer's is min or max)",
            v.name
        );
        let range = v.range();
        if let Some(x) = v.start.as_ref().map(number) {
            assert!(
                range.contains(x),
                "{}: start {x} outside its range {}",
                v.name,
                range.statement(&v.name)
            );
        }
        if let Some(items) = &v.items {
            let last = v.first_item() + items.len() as i64 - 1;
            assert!(
                v.ty == "Integer" && v.max.as_ref().is_none_or(|m| m.as_integer() == Some(last)),
                "{}: items are an Integer's values {} to {last}, its min to its max",
                v.name,
                v.first_item()
            );
        }
        assert!(
            !v.derivative || (v.causality == "output" && v.ty == "Real"),
            "{}: only Real outputs have derivatives",
            v.name
        );
        if let Some(state) = &v.derivative_of {
            assert!(
                c.variable
                    .iter()
                    .any(|w| &w.name == state && w.ty == "Real"),
                "{}: derivative of {state}, which is not a Real variable",
                v.name
            );
        }
        // An output or a state derivative depends on inputs and continuous states (FMI 2.0's
        // knowns, the time aside).
        let is_state = |name: &str| {
            c.variable
                .iter()
                .any(|w| w.derivative_of.as_deref() == Some(name))
        };
        for d in v.depends_on.iter().flatten() {
            assert!(
                c.variable
                    .iter()
                    .any(|w| &w.name == d && w.causality == "input")
                    || is_state(d),
                "{}: depends on {d}, which is neither an input nor a continuous state",
                v.name
            );
        }
    }
}

/// FNV-1a over the contract text, twice with different offsets, formatted as a GUID.
fn guid_of(text: &str) -> String {
    let fnv = |offset: u64| {
        text.bytes().fold(offset, |h, b| {
            (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
        })
    };
    let (a, b) = (fnv(0xcbf2_9ce4_8422_2325), fnv(0x6c62_272e_07bb_0142));
    format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        a >> 32,
        (a >> 16) & 0xffff,
        a & 0xffff,
        b >> 48,
        b & 0xffff_ffff_ffff
    )
}

/// A variable's name as a Rust identifier: "der(xi)" is `der_xi`.
fn ident(name: &str) -> String {
    let mangled: String = name
        .chars()
        .map(|ch| {
            if ch.is_alphanumeric() || ch == '_' {
                ch
            } else {
                '_'
            }
        })
        .collect();
    mangled.trim_end_matches('_').to_string()
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn value(v: &toml::Value) -> String {
    match v {
        toml::Value::Float(f) => format!("{f:?}"),
        toml::Value::Integer(i) => i.to_string(),
        toml::Value::Boolean(b) => b.to_string(),
        toml::Value::String(s) => esc(s),
        other => panic!("unsupported value {other}"),
    }
}

/// An XML min or max: the inclusive bound as written, or the double next to an exclusive
/// one on the side of the range (x >= next_up(0) admits exactly the doubles x > 0).
fn xml_bound(inclusive: &Option<toml::Value>, inside: Option<f64>) -> Option<String> {
    inclusive
        .as_ref()
        .map(value)
        .or(inside.map(|x| format!("{x:?}")))
}

/// A variable's opening tag `element` up to its causality's attributes, with the value
/// reference `vr`.
fn variable_head(x: &mut String, element: &str, v: &Variable, vr: u32) {
    write!(
        x,
        "    <{element} name=\"{}\" valueReference=\"{vr}\" description=\"{}\" causality=\"{}\" variability=\"{}\"",
        esc(&v.name),
        esc(&v.full_description()),
        v.causality,
        v.variability()
    )
    .unwrap();
    if v.causality == "parameter" {
        *x += " initial=\"exact\"";
    }
}

/// A variable's start, unit, display unit, bounds (if `bounded`) and `derivative` (the
/// state's index or reference) as XML attributes, each where it has one.
fn attributes(x: &mut String, v: &Variable, bounded: bool, derivative: Option<String>) {
    let bound = |b: Option<String>| b.filter(|_| bounded);
    let attributes = [
        ("start", v.start.as_ref().map(value)),
        ("unit", v.unit.as_deref().map(esc)),
        ("displayUnit", v.display_unit.as_deref().map(esc)),
        (
            "min",
            bound(xml_bound(&v.min, v.min_exclusive.map(f64::next_up))),
        ),
        (
            "max",
            bound(xml_bound(&v.max, v.max_exclusive.map(f64::next_down))),
        ),
        ("derivative", derivative),
    ];
    for (name, a) in &attributes {
        if let Some(a) = a {
            write!(x, " {name}=\"{a}\"").unwrap();
        }
    }
}

/// The initial unknowns by `key` (of a variable's name), sorted, each once: the outputs, and
/// the states and their derivatives (all calculated: none has a start).
fn initial_unknowns<T: Ord>(c: &Contract, key: impl Fn(&str) -> T) -> Vec<T> {
    let mut initial: Vec<T> = c
        .variable
        .iter()
        .filter(|v| v.causality == "output" || v.derivative_of.is_some())
        .map(|v| key(&v.name))
        .chain(
            c.variable
                .iter()
                .filter_map(|v| v.derivative_of.as_deref())
                .map(&key),
        )
        .collect();
    initial.sort();
    initial.dedup();
    initial
}

/// UnitDefinitions, as both editions write them.
fn units(x: &mut String, c: &Contract) {
    *x += "  <UnitDefinitions>\n";
    for u in &c.unit {
        write!(x, "    <Unit name=\"{}\"><BaseUnit", esc(&u.name)).unwrap();
        for (k, e) in &u.base {
            write!(x, " {k}=\"{e}\"").unwrap();
        }
        for (k, a) in [("factor", u.factor), ("offset", u.offset)] {
            if let Some(a) = a {
                write!(x, " {k}=\"{a:?}\"").unwrap();
            }
        }
        *x += "/>";
        for d in &u.display {
            write!(
                x,
                "<DisplayUnit name=\"{}\" factor=\"{:?}\"/>",
                esc(&d.name),
                d.factor
            )
            .unwrap();
        }
        *x += "</Unit>\n";
    }
    *x += "  </UnitDefinitions>\n";
}

/// LogCategories and DefaultExperiment, as both editions write them.
fn log_categories_and_experiment(x: &mut String, c: &Contract) {
    *x += "  <LogCategories>\n";
    for (name, description) in &c.log_categories {
        writeln!(
            x,
            "    <Category name=\"{name}\" description=\"{}\"/>",
            esc(description)
        )
        .unwrap();
    }
    *x += "  </LogCategories>\n  <DefaultExperiment";
    for (k, v) in &c.experiment {
        write!(x, " {k}=\"{v:?}\"").unwrap();
    }
    *x += "/>\n";
}

/// Capabilities of the contract that FMI 3.0 alone has (FMI 2.0's description leaves them out).
const FMI3_ONLY: [&str; 1] = ["hasEventMode"];

fn xml(c: &Contract, guid: &str) -> String {
    let mut x = String::new();
    let m = &c.model;
    let index_of = |name: &str| 1 + c.variable.iter().position(|w| w.name == name).unwrap();
    x += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    writeln!(
        x,
        "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"{}\" guid=\"{guid}\" description=\"{}\" author=\"{}\" version=\"{}\" generationTool=\"fmi2-shell\" variableNamingConvention=\"{}\" numberOfEventIndicators=\"{}\">",
        esc(&m.name),
        esc(&m.description),
        esc(&m.author),
        esc(&m.version),
        if c.array.is_empty() { "flat" } else { "structured" },
        m.event_indicators
    )
    .unwrap();
    if let Some(caps) = &c.model_exchange {
        write!(x, "  <ModelExchange modelIdentifier=\"{}\"", m.identifier).unwrap();
        for (k, v) in caps {
            write!(x, " {k}=\"{}\"", value(v)).unwrap();
        }
        x += "/>\n";
    }
    write!(x, "  <CoSimulation modelIdentifier=\"{}\"", m.identifier).unwrap();
    for (k, v) in c
        .capabilities
        .iter()
        .filter(|(k, _)| !FMI3_ONLY.contains(&k.as_str()))
    {
        write!(x, " {k}=\"{}\"", value(v)).unwrap();
    }
    x += "/>\n";
    units(&mut x, c);
    log_categories_and_experiment(&mut x, c);
    x += "  <ModelVariables>\n";
    for (i, v) in c.variable.iter().enumerate() {
        writeln!(x, "    <!-- index {} -->", i + 1).unwrap();
        variable_head(&mut x, "ScalarVariable", v, v.vr);
        write!(x, ">\n      <{}", v.ty).unwrap();
        let derivative = v.derivative_of.as_deref().map(|s| index_of(s).to_string());
        attributes(&mut x, v, true, derivative);
        x += "/>\n    </ScalarVariable>\n";
    }
    x += "  </ModelVariables>\n  <ModelStructure>\n    <Outputs>\n";
    let outputs: Vec<_> = (1..)
        .zip(&c.variable)
        .filter(|(_, v)| v.causality == "output")
        .collect();
    // An unknown with its dependencies (indices in increasing order), as declared.
    let unknown = |x: &mut String, i: usize, v: &Variable| {
        let mut deps: Vec<usize> = v.depends_on.iter().flatten().map(|d| index_of(d)).collect();
        deps.sort();
        if deps.is_empty() {
            writeln!(x, "      <Unknown index=\"{i}\" dependencies=\"\"/>").unwrap();
        } else {
            let deps: Vec<String> = deps.iter().map(usize::to_string).collect();
            let kinds = vec!["dependent"; deps.len()].join(" ");
            writeln!(
                x,
                "      <Unknown index=\"{i}\" dependencies=\"{}\" dependenciesKind=\"{kinds}\"/>",
                deps.join(" ")
            )
            .unwrap();
        }
    };
    for (i, v) in &outputs {
        unknown(&mut x, *i, v);
    }
    x += "    </Outputs>\n";
    // Model Exchange: the state derivatives, in the order of the state vector, with the
    // states and inputs each depends on.
    let derivatives: Vec<(usize, &Variable)> = (1..)
        .zip(&c.variable)
        .filter(|(_, v)| v.derivative_of.is_some())
        .collect();
    if !derivatives.is_empty() {
        x += "    <Derivatives>\n";
        for (i, v) in &derivatives {
            unknown(&mut x, *i, v);
        }
        x += "    </Derivatives>\n";
    }
    x += "    <InitialUnknowns>\n";
    for i in initial_unknowns(c, index_of) {
        writeln!(x, "      <Unknown index=\"{i}\"/>").unwrap();
    }
    x += "    </InitialUnknowns>\n  </ModelStructure>\n</fmiModelDescription>\n";
    x
}

/// A range as a Rust expression (paths in full: the including module imports only the
/// contract's older types).
fn rust_range(range: &Range) -> String {
    let bound = |b: &Bound| match b {
        Bound::None => "fmi2_shell::contract::Bound::None".to_string(),
        Bound::Inclusive(x) => format!("fmi2_shell::contract::Bound::Inclusive({x:?})"),
        Bound::Exclusive(x) => format!("fmi2_shell::contract::Bound::Exclusive({x:?})"),
    };
    format!(
        "fmi2_shell::contract::Range {{ min: {}, max: {} }}",
        bound(&range.min),
        bound(&range.max)
    )
}

/// An array's module in `vr`: its elements' value references as arrays (element i at index
/// i - 1), the offsets, and the look-up of a value reference's element and offset.
fn rust_array(c: &Contract, a: &Array) -> String {
    let of_array = |v: &&Variable| v.element.as_ref().is_some_and(|e| e.array == a.name);
    let first: Vec<&Variable> = c
        .variable
        .iter()
        .filter(of_array)
        .filter(|v| v.element.as_ref().unwrap().index == 1)
        .collect();
    let mut r = format!(
        "\n    /// {0}[i]'s value references, i = 1..={1} at index i - 1: {2} + {3} i + the\n    /// variable's offset (Real and Integer numbered apart).\n    pub mod {0} {{\n        pub const SIZE: usize = {1};\n        pub const VR_BASE: u32 = {2};\n        pub const VR_STRIDE: u32 = {3};\n",
        a.name, a.size, a.vr_base, a.vr_stride
    );
    for v in &first {
        let declared = &v.element.as_ref().unwrap().declared;
        let vrs: Vec<u32> = c
            .variable
            .iter()
            .filter(of_array)
            .filter(|w| &w.element.as_ref().unwrap().declared == declared)
            .map(|w| w.vr)
            .collect();
        writeln!(
            r,
            "        pub const {}: [u32; {}] = {vrs:?};",
            ident(declared),
            a.size
        )
        .unwrap();
    }
    r += "        /// Each variable's offset in an element's block.\n        pub mod offset {\n";
    for v in &first {
        let declared = &v.element.as_ref().unwrap().declared;
        writeln!(
            r,
            "            pub const {}: u32 = {};",
            ident(declared),
            v.vr - a.vr_base - a.vr_stride
        )
        .unwrap();
    }
    r += "        }\n        /// The element (its index, i - 1) and the offset of a value reference in the\n        /// array's range, whether or not a variable has it.\n        pub const fn locate(vr: u32) -> Option<(usize, u32)> {\n            if vr < VR_BASE + VR_STRIDE || vr >= VR_BASE + VR_STRIDE * (SIZE as u32 + 1) {\n                return None;\n            }\n            let i = (vr - VR_BASE) / VR_STRIDE;\n            Some((i as usize - 1, (vr - VR_BASE) % VR_STRIDE))\n        }\n    }\n";
    r
}

fn rust(c: &Contract, guid: &str) -> String {
    let mut r =
        String::from("// Generated by fmi2-shell from the model's contract: do not edit.\n");
    writeln!(r, "pub const GUID: &str = {guid:?};").unwrap();
    writeln!(
        r,
        "pub const MODEL_IDENTIFIER: &str = {:?};",
        c.model.identifier
    )
    .unwrap();
    writeln!(r, "pub const MODEL_NAME: &str = {:?};", c.model.name).unwrap();
    if let Some(tolerance) = c.experiment.get("tolerance") {
        writeln!(r, "pub const DEFAULT_TOLERANCE: f64 = {tolerance:?};").unwrap();
    }
    r += "pub const LOG_CATEGORIES: &[(&str, &str)] = &[\n";
    for (n, d) in &c.log_categories {
        writeln!(r, "    ({n:?}, {d:?}),").unwrap();
    }
    r += "];\n\n/// Indices in LOG_CATEGORIES, named as the categories.\n#[allow(non_upper_case_globals)]\npub mod log {\n";
    for (i, (n, _)) in c.log_categories.iter().enumerate() {
        writeln!(r, "    pub const {n}: usize = {i};").unwrap();
    }
    r += "}\n\n/// Value references, named as the variables.\n#[allow(non_upper_case_globals)]\npub mod vr {\n";
    for v in c.variable.iter().filter(|v| v.element.is_none()) {
        writeln!(r, "    pub const {}: u32 = {};", ident(&v.name), v.vr).unwrap();
    }
    for a in &c.array {
        r += &rust_array(c, a);
    }
    r += "}\n\n/// Every variable of the contract, in the order of the model description.\npub static VARIABLES: &[Variable] = &[\n";
    for v in &c.variable {
        let start = match (&v.ty[..], &v.start) {
            (_, None) => "Start::None".to_string(),
            ("Real", Some(s)) => format!(
                "Start::Real({:?})",
                s.as_float()
                    .or(s.as_integer().map(|i| i as f64))
                    .expect("a number")
            ),
            (_, Some(s)) => format!("Start::Integer({})", s.as_integer().expect("an integer")),
        };
        let causality = match &v.causality[..] {
            "parameter" => "Parameter",
            "local" => "Local",
            "input" => "Input",
            _ => "Output",
        };
        writeln!(
            r,
            "    Variable {{ name: {:?}, vr: {}, kind: Kind::{}, causality: Causality::{causality}, start: {start}, unit: {:?}, range: {}, depends_on: &{:?}, derivative: {}, description: {:?} }},",
            v.name,
            v.vr,
            v.ty,
            v.unit.as_deref().unwrap_or(""),
            rust_range(&v.range()),
            v.depends_on.as_deref().unwrap_or_default(),
            v.derivative,
            v.description
        )
        .unwrap();
    }
    r += "];\n\n";
    let derivatives: Vec<&Variable> = c
        .variable
        .iter()
        .filter(|v| v.derivative_of.is_some())
        .collect();
    let vr_of = |name: &str| c.variable.iter().find(|w| w.name == name).unwrap().vr;
    writeln!(
        r,
        "/// Model Exchange: the continuous states' value references, in the state vector's order.\npub const STATES: &[u32] = &{:?};",
        derivatives.iter().map(|v| vr_of(v.derivative_of.as_deref().unwrap())).collect::<Vec<_>>()
    )
    .unwrap();
    writeln!(
        r,
        "/// Model Exchange: their derivatives' value references.\npub const DERIVATIVES: &[u32] = &{:?};",
        derivatives.iter().map(|v| v.vr).collect::<Vec<_>>()
    )
    .unwrap();
    writeln!(
        r,
        "pub const EVENT_INDICATORS: usize = {};\n",
        c.model.event_indicators
    )
    .unwrap();
    r += "/// FMI 3.0: the arrays, each sized by its structural parameter.\npub const FMI3_ARRAYS: &[fmi2_shell::contract::fmi3::Array] = &[\n";
    for a in &c.array {
        writeln!(
            r,
            "    fmi2_shell::contract::fmi3::Array {{ size_vr: {}, size: {}, vr_base: {}, vr_stride: {} }},",
            vr_of(&a.size_parameter()),
            a.size,
            a.vr_base,
            a.vr_stride
        )
        .unwrap();
    }
    r += "];\n\n";
    r += "/// Index in VARIABLES of the variable of a kind and value reference (a jump table, not\n/// a search: fmi2GetReal looks every reference up).\npub fn index(kind: Kind, vr: u32) -> Option<usize> {\n    match (kind, vr) {\n";
    for (i, v) in c.variable.iter().enumerate() {
        writeln!(r, "        (Kind::{}, {}) => Some({i}),", v.ty, v.vr).unwrap();
    }
    r += "        _ => None,\n    }\n}\n\n/// Looks a variable up by kind and value reference.\npub fn find(kind: Kind, vr: u32) -> Option<&'static Variable> {\n    index(kind, vr).map(|i| &VARIABLES[i])\n}\n\n/// The variable of a kind and value reference, or the importer's error for an unknown one.\npub fn variable(kind: Kind, vr: u32) -> fmi2_shell::FmiResult<&'static Variable> {\n    find(kind, vr).ok_or_else(|| fmi2_shell::contract::unknown(kind, vr))\n}\n\n/// Checks every parameter against the range the contract gives it.\npub fn check_parameters(values: &fmi2_shell::values::Values) -> fmi2_shell::FmiResult {\n    fmi2_shell::contract::check_parameters(VARIABLES, values)\n}\n";
    r
}

/// Keeps the shared library's exports to the FMI functions and the sampling entry
/// `gearRattleDoStepSampled` (`fmu::sampled`, outside FMI; the platforms' filters in mk/ keep
/// it too): a cdylib otherwise exports every
/// `#[no_mangle]` symbol of its dependencies too (fmi-sys brings `callback_log`). rustc's own
/// version script names those symbols as global, and GNU ld lets an explicit name win over
/// our wildcard, so the one fmi-sys brings is named here (a test checks the export table).
///
/// Windows (x86_64-pc-windows-gnu): rustc hands GNU ld a .def list of the same symbols, and
/// ld's PE back end can only add to such a list (a second .def is merged into it;
/// --exclude-symbols only affects automatic exports), so nothing here can take a name out.
/// The linker set in .cargo/config.toml, mk/windows-link.sh, links with a copy of rustc's
/// list narrowed to fmi2* and fmi3*; tests/windows/run.sh checks the DLL's export table.
///
/// macOS: see `apple_link_args`.
pub fn restrict_exports() {
    let out = PathBuf::from(env::var("OUT_DIR").unwrap());
    let target_os = env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if target_os == "macos" {
        apple_link_args();
    }
    if target_os != "linux" {
        return;
    }
    let script = out.join("exports.map");
    fs::write(
        &script,
        "{\n  global: fmi2*; fmi3*; gearRattleDoStepSampled;\n  local: callback_log; *;\n};\n",
    )
    .unwrap();
    println!(
        "cargo:rustc-cdylib-link-arg=-Wl,--version-script={}",
        script.display()
    );
}

/// macOS: the dylib links only the libraries it calls into. The `libc` crate asks for
/// libiconv (and cargo-zigbuild adds libcharset with it), which nothing here calls; without
/// -dead_strip_dylibs both would be load commands, and a dylib that needs libSystem alone
/// loads on any macOS. Its install name is `@rpath/lib<crate>.dylib`, not the path it was
/// linked at on the build machine. The exports are kept to fmi2* and fmi3* by mk/darwin-link.py and
/// mk/darwin-exports.py: zig's Mach-O linker ignores the exported-symbols list that rustc
/// passes.
fn apple_link_args() {
    println!("cargo:rustc-cdylib-link-arg=-Wl,-dead_strip_dylibs");
    let crate_name = env::var("CARGO_PKG_NAME").unwrap().replace('-', "_");
    println!("cargo:rustc-cdylib-link-arg=-Wl,-install_name,@rpath/lib{crate_name}.dylib");
}

#[cfg(test)]
mod tests {
    //! The generator on the contracts of the repository: GearboxRattle's arrays expand to the
    //! names, value references and dependencies docs/GEARBOX.md's FMU needs, its Rust constants
    //! compile and behave, and both model descriptions pass fmpy's validation.

    use super::*;
    use std::path::Path;
    use std::process::Command;

    fn contract(name: &str) -> String {
        let path = format!(
            "{}/../modelDescription/{name}.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
    }

    fn scratch(name: &str) -> PathBuf {
        let dir = env::temp_dir().join(format!("fmi2-shell-{name}-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Fails with the command's output unless it succeeded.
    fn succeeded(what: &str, run: &std::process::Output) {
        assert!(
            run.status.success(),
            "{what}:\n{}\n{}",
            String::from_utf8_lossy(&run.stdout),
            String::from_utf8_lossy(&run.stderr)
        );
    }

    /// The element of the model description naming `name`, up to its type's attributes.
    fn scalar<'a>(xml: &'a str, name: &str) -> &'a str {
        let start = xml
            .find(&format!("name=\"{name}\""))
            .unwrap_or_else(|| panic!("no variable {name}"));
        &xml[start..start + xml[start..].find("/>").unwrap()]
    }

    #[test]
    fn gearbox_arrays_expand_to_structured_names_and_regular_value_references() {
        let (xml, rust) = outputs(&contract("GearboxRattle")).unwrap();
        assert!(xml.contains("variableNamingConvention=\"structured\""));
        assert!(xml.contains("numberOfEventIndicators=\"42\""));
        // Gear i's variable of offset k at 1000 + 100 i + k, start from §6's table.
        let e = scalar(&xml, "gear[3].I_L");
        assert!(e.contains("valueReference=\"1301\""), "{e}");
        assert!(e.contains("start=\"0.00022\""), "{e}");
        assert!(e.contains("min=\"5e-324\""), "{e}");
        assert!(e.contains("(range: gear[3].I_L &gt; 0)"), "{e}");
        let e = scalar(&xml, "gear[8].contact");
        assert!(e.contains("valueReference=\"1801\""), "{e}");
        let e = scalar(&xml, "T_oil");
        assert!(e.contains("min=\"-94.99999999999999\""), "{e}");
        assert!(e.contains("unit=\"degC\""), "{e}");
        assert!(xml.contains("<Unit name=\"degC\"><BaseUnit K=\"1\" offset=\"273.15\"/>"));
        let e = scalar(&xml, "n_gears");
        assert!(e.contains("min=\"1\" max=\"8\""), "{e}");
        // The state vector: phi, x_omega_I, x_theta_F, x_omega_F, E_damper, E_input_drag,
        // W_flywheel, then each gear's xi, xi_dot, E_contact, E_lubricant, int_a2, int_F, int_F2.
        assert!(rust.contains(
            "pub const STATES: &[u32] = &[45, 80, 81, 82, 48, 83, 84, 1120, 1121, 1125, 1126, 1170, 1171, 1172, 1220,"
        ));
        assert!(rust.contains("1820, 1821, 1825, 1826, 1870, 1871, 1872];"));
        assert!(rust.contains(
            "pub const I_L: [u32; 8] = [1101, 1201, 1301, 1401, 1501, 1601, 1701, 1801];"
        ));
        // A per-gear derivative depends on its own gear's state; a box output on every gear's.
        let c: Contract = {
            let mut c: Contract = toml::from_str(&contract("GearboxRattle")).unwrap();
            expand(&mut c);
            c
        };
        let deps = |name: &str| {
            c.variable
                .iter()
                .find(|v| v.name == name)
                .unwrap()
                .depends_on
                .clone()
                .unwrap()
        };
        assert_eq!(deps("der(gear[2].xi)"), ["gear[2].xi_dot"]);
        assert_eq!(deps("gear[5].xi"), ["gear[5].xi", "theta_I"]);
        let tau_i = deps("tau_I");
        for i in 1..=8 {
            assert!(tau_i.contains(&format!("gear[{i}].xi")), "{tau_i:?}");
        }
        let derivative = scalar(&xml, "der(gear[4].xi)");
        let index = 1 + c
            .variable
            .iter()
            .position(|v| v.name == "gear[4].xi")
            .unwrap();
        assert!(
            derivative.contains(&format!("derivative=\"{index}\"")),
            "{derivative}"
        );
    }

    /// The generated constants in a crate of their own (with fmi2-shell's runtime types, as a
    /// model crate includes them): they compile, and value references, look-ups and the range
    /// check behave as the contract says.
    #[test]
    fn gearbox_rust_constants_compile_and_check_ranges() {
        let (_, rust) = outputs(&contract("GearboxRattle")).unwrap();
        let dir = scratch("gearbox-crate");
        fs::create_dir_all(dir.join("src")).unwrap();
        fs::write(dir.join("src/contract.rs"), rust).unwrap();
        let shell = env!("CARGO_MANIFEST_DIR");
        fs::write(
            dir.join("Cargo.toml"),
            format!(
                "[package]\nname = \"gearbox-contract\"\nversion = \"0.0.0\"\nedition = \"2024\"\n\n[dependencies]\nfmi2-shell = {{ path = {shell:?}, default-features = false }}\n\n[workspace]\n"
            ),
        )
        .unwrap();
        fs::write(dir.join("src/lib.rs"), GEARBOX_API_TEST).unwrap();
        let target = Path::new(shell).join("../target/generator-check");
        let run = Command::new(env!("CARGO"))
            .args(["test", "--offline", "--quiet"])
            .current_dir(&dir)
            .env("CARGO_TARGET_DIR", target)
            .output()
            .unwrap();
        succeeded("the crate of GearboxRattle's constants", &run);
        let out = String::from_utf8_lossy(&run.stdout);
        assert!(out.contains("1 passed"), "its test did not run: {out}");
        fs::remove_dir_all(dir).unwrap();
    }

    /// The model-crate side: what a gearbox instance writes with the constants.
    const GEARBOX_API_TEST: &str = r#"
pub mod contract {
    pub use fmi2_shell::contract::{Causality, Kind, Start, Variable};
    include!("contract.rs");
}

#[cfg(test)]
mod tests {
    use super::contract::{self, vr, Kind, VARIABLES};
    use fmi2_shell::values::Values;

    #[test]
    fn value_references_look_ups_and_ranges() {
        assert_eq!(vr::gear::SIZE, 8);
        assert_eq!(vr::gear::I_L[2], 1301);
        assert_eq!(vr::gear::locate(vr::gear::xi[4]), Some((4, vr::gear::offset::xi)));
        assert_eq!(vr::gear::locate(vr::n_gears), None);
        assert_eq!(contract::find(Kind::Real, vr::gear::G[0]).unwrap().name, "gear[1].G");
        assert_eq!(contract::find(Kind::Integer, vr::gear::contact[7]).unwrap().name, "gear[8].contact");
        assert_eq!(contract::STATES.len(), 7 + 7 * 8);
        assert_eq!(contract::EVENT_INDICATORS, 42);
        let mut values = Values::start(VARIABLES);
        assert!(contract::check_parameters(&values).is_ok());
        values.set_real(vr::gear::I_L[2], 0.0);
        let e = contract::check_parameters(&values).unwrap_err();
        assert!(e.message.contains("gear[3].I_L = 0e0 is invalid: allowed gear[3].I_L > 0"), "{}", e.message);
        let mut values = Values::start(VARIABLES);
        values.set_real(vr::T_oil, -95.0);
        let e = contract::check_parameters(&values).unwrap_err();
        assert!(e.message.contains("T_oil > -95"), "{}", e.message);
        let mut values = Values::start(VARIABLES);
        values.set_integer(vr::n_gears, 9);
        let e = contract::check_parameters(&values).unwrap_err();
        assert!(e.message.contains("1 <= n_gears <= 8"), "{}", e.message);
    }
}
"#;

    /// Both contracts' model descriptions, FMI 2.0's and FMI 3.0's, through fmpy's
    /// validate_fmu (the schema, variable names, ModelStructure, start values, units). The Python with fmpy is $FMPY_PYTHON, or
    /// the repository's .venv (`make setup`).
    #[test]
    fn model_descriptions_pass_fmpy_validation() {
        let python = env::var("FMPY_PYTHON")
            .unwrap_or_else(|_| format!("{}/../.venv/bin/python", env!("CARGO_MANIFEST_DIR")));
        for name in ["GearRattle", "GearboxRattle"] {
            let text = contract(name);
            for (edition, xml) in [
                ("2.0", outputs(&text).unwrap().0),
                ("3.0", fmi3_description(&text).unwrap()),
            ] {
                let dir = scratch(&format!("{name}-{edition}"));
                fs::write(dir.join("modelDescription.xml"), xml).unwrap();
                let run = Command::new(&python)
                .args([
                    "-c",
                    "import sys; from fmpy.validation import validate_fmu; p = validate_fmu(sys.argv[1]); print(*p, sep='\\n'); sys.exit(len(p) > 0)",
                ])
                .arg(&dir)
                .output()
                .unwrap_or_else(|e| panic!("{python}: {e} (set FMPY_PYTHON or run make setup)"));
                succeeded(&format!("{name} (FMI {edition})"), &run);
                fs::remove_dir_all(dir).unwrap();
            }
        }
    }
}
