//! Build-time generator (feature "build"), for the FMUs' build scripts: turns a contract
//! TOML (the one source of truth for a model's variables, units and capabilities) into
//!   - `$OUT_DIR/modelDescription.xml`, the FMI 2.0 model description packaged in the FMU;
//!   - `$OUT_DIR/contract.rs`, the value references, start values, causalities, log
//!     categories and GUID the model uses (included by its `contract` module after
//!     `use fmi2_shell::contract::*`);
//!
//! and restricts the cdylib's exports to the `fmi2*` functions ([`restrict_exports`]).
//!
//! The GUID is a hash of the contract file, so the XML and the binary always carry the same
//! one and any change of the contract changes it.

use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::{env, fs};

#[derive(Deserialize)]
struct Contract {
    model: Model,
    capabilities: BTreeMap<String, toml::Value>,
    /// Model Exchange's capabilities, where the model offers it.
    model_exchange: Option<BTreeMap<String, toml::Value>>,
    experiment: BTreeMap<String, f64>,
    log_categories: Vec<(String, String)>,
    unit: Vec<Unit>,
    variable: Vec<Variable>,
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
    #[serde(default)]
    display: Vec<DisplayUnit>,
}

#[derive(Deserialize)]
struct DisplayUnit {
    name: String,
    factor: f64,
}

#[derive(Deserialize)]
struct Variable {
    name: String,
    vr: u32,
    #[serde(rename = "type")]
    ty: String,
    causality: String,
    description: String,
    start: Option<toml::Value>,
    unit: Option<String>,
    display_unit: Option<String>,
    min: Option<toml::Value>,
    max: Option<toml::Value>,
    depends_on: Option<Vec<String>>,
    /// The FMU gives this output's first time derivative (fmi2GetRealOutputDerivatives).
    #[serde(default)]
    derivative: bool,
    /// Model Exchange: this variable is the time derivative of the continuous state named
    /// here; the order of these variables is the order of the state vector.
    derivative_of: Option<String>,
}

impl Variable {
    fn variability(&self) -> &'static str {
        match (self.causality.as_str(), self.ty.as_str()) {
            ("parameter", _) => "fixed",
            (_, "Integer") => "discrete",
            _ => "continuous",
        }
    }
}

/// Generates the model description and the Rust constants of the contract at `path`
/// (relative to the crate's manifest directory), and asks cargo to rerun when it changes.
pub fn generate(path: &str) {
    generate_in(path, &PathBuf::from(env::var("OUT_DIR").unwrap()));
}

/// [`generate`] into the directory `out`: the packaging crate's build script writes each
/// model's files into a folder of its own.
pub fn generate_in(path: &str, out: &Path) {
    println!("cargo:rerun-if-changed={path}");
    let text = fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let contract: Contract = toml::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"));
    check(&contract);
    let guid = guid_of(&text);
    fs::write(out.join("modelDescription.xml"), xml(&contract, &guid)).unwrap();
    fs::write(out.join("contract.rs"), rust(&contract, &guid)).unwrap();
}

/// Refuses a contract that would give an invalid or ambiguous FMU.
fn check(c: &Contract) {
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

fn xml(c: &Contract, guid: &str) -> String {
    let mut x = String::new();
    let m = &c.model;
    let index_of = |name: &str| 1 + c.variable.iter().position(|w| w.name == name).unwrap();
    x += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    writeln!(
        x,
        "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"{}\" guid=\"{guid}\" description=\"{}\" author=\"{}\" version=\"{}\" generationTool=\"fmi2-shell\" variableNamingConvention=\"flat\" numberOfEventIndicators=\"{}\">",
        esc(&m.name),
        esc(&m.description),
        esc(&m.author),
        esc(&m.version),
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
    for (k, v) in &c.capabilities {
        write!(x, " {k}=\"{}\"", value(v)).unwrap();
    }
    x += "/>\n  <UnitDefinitions>\n";
    for u in &c.unit {
        write!(x, "    <Unit name=\"{}\"><BaseUnit", esc(&u.name)).unwrap();
        for (k, e) in &u.base {
            write!(x, " {k}=\"{e}\"").unwrap();
        }
        x += "/>";
        for d in &u.display {
            write!(
                x,
                "<DisplayUnit name=\"{}\" factor=\"{:?}\"/>",
                esc(&d.name),
                d.factor
            )
            .unwrap();
        }
        x += "</Unit>\n";
    }
    x += "  </UnitDefinitions>\n  <LogCategories>\n";
    for (name, description) in &c.log_categories {
        writeln!(
            x,
            "    <Category name=\"{name}\" description=\"{}\"/>",
            esc(description)
        )
        .unwrap();
    }
    x += "  </LogCategories>\n  <DefaultExperiment";
    for (k, v) in &c.experiment {
        write!(x, " {k}=\"{v:?}\"").unwrap();
    }
    x += "/>\n  <ModelVariables>\n";
    for (i, v) in c.variable.iter().enumerate() {
        writeln!(x, "    <!-- index {} -->", i + 1).unwrap();
        write!(
            x,
            "    <ScalarVariable name=\"{}\" valueReference=\"{}\" description=\"{}\" causality=\"{}\" variability=\"{}\"",
            esc(&v.name),
            v.vr,
            esc(&v.description),
            v.causality,
            v.variability()
        )
        .unwrap();
        if v.causality == "parameter" {
            x += " initial=\"exact\"";
        }
        write!(x, ">\n      <{}", v.ty).unwrap();
        let attributes = [
            ("start", v.start.as_ref().map(value)),
            ("unit", v.unit.as_deref().map(esc)),
            ("displayUnit", v.display_unit.as_deref().map(esc)),
            ("min", v.min.as_ref().map(value)),
            ("max", v.max.as_ref().map(value)),
            (
                "derivative",
                v.derivative_of.as_deref().map(|s| index_of(s).to_string()),
            ),
        ];
        for (name, a) in &attributes {
            if let Some(a) = a {
                write!(x, " {name}=\"{a}\"").unwrap();
            }
        }
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
    // Outputs, and the states and their derivatives (all calculated: none has a start).
    let mut initial: Vec<usize> = outputs.iter().map(|(i, _)| *i).collect();
    initial.extend(derivatives.iter().map(|(i, _)| *i));
    initial.extend(
        c.variable
            .iter()
            .filter_map(|v| v.derivative_of.as_deref())
            .map(index_of),
    );
    initial.sort();
    initial.dedup();
    for i in initial {
        writeln!(x, "      <Unknown index=\"{i}\"/>").unwrap();
    }
    x += "    </InitialUnknowns>\n  </ModelStructure>\n</fmiModelDescription>\n";
    x
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
    for v in &c.variable {
        writeln!(r, "    pub const {}: u32 = {};", ident(&v.name), v.vr).unwrap();
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
            "    Variable {{ name: {:?}, vr: {}, kind: Kind::{}, causality: Causality::{causality}, start: {start}, unit: {:?}, depends_on: &{:?}, derivative: {}, description: {:?} }},",
            v.name,
            v.vr,
            v.ty,
            v.unit.as_deref().unwrap_or(""),
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
    r += "/// Index in VARIABLES of the variable of a kind and value reference (a jump table, not\n/// a search: fmi2GetReal looks every reference up).\npub fn index(kind: Kind, vr: u32) -> Option<usize> {\n    match (kind, vr) {\n";
    for (i, v) in c.variable.iter().enumerate() {
        writeln!(r, "        (Kind::{}, {}) => Some({i}),", v.ty, v.vr).unwrap();
    }
    r += "        _ => None,\n    }\n}\n\n/// Looks a variable up by kind and value reference.\npub fn find(kind: Kind, vr: u32) -> Option<&'static Variable> {\n    index(kind, vr).map(|i| &VARIABLES[i])\n}\n\n/// The variable of a kind and value reference, or the importer's error for an unknown one.\npub fn variable(kind: Kind, vr: u32) -> fmi2_shell::FmiResult<&'static Variable> {\n    find(kind, vr).ok_or_else(|| fmi2_shell::contract::unknown(kind, vr))\n}\n";
    r
}

/// Keeps the shared library's exports to the FMI functions: a cdylib otherwise exports every
/// `#[no_mangle]` symbol of its dependencies too (fmi-sys brings `callback_log`). rustc's own
/// version script names those symbols as global, and GNU ld lets an explicit name win over
/// our wildcard, so the one fmi-sys brings is named here (a test checks the export table).
///
/// Windows (x86_64-pc-windows-gnu): rustc hands GNU ld a .def list of the same symbols, and
/// ld's PE back end can only add to such a list (a second .def is merged into it;
/// --exclude-symbols only affects automatic exports), so nothing here can take a name out.
/// The linker set in .cargo/config.toml, mk/windows-link.sh, links with a copy of rustc's
/// list narrowed to fmi2*; tests/windows/run.sh checks the DLL's export table.
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
        "{\n  global: fmi2*;\n  local: callback_log; *;\n};\n",
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
/// linked at on the build machine. The exports are kept to fmi2* by mk/darwin-link.py and
/// mk/darwin-exports.py: zig's Mach-O linker ignores the exported-symbols list that rustc
/// passes.
fn apple_link_args() {
    println!("cargo:rustc-cdylib-link-arg=-Wl,-dead_strip_dylibs");
    let crate_name = env::var("CARGO_PKG_NAME").unwrap().replace('-', "_");
    println!("cargo:rustc-cdylib-link-arg=-Wl,-install_name,@rpath/lib{crate_name}.dylib");
}
