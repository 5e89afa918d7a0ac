//! The FMI 3.0 model description of a contract, beside FMI 2.0's ([`super::xml`]): the same
//! variables, units and capabilities in FMI 3.0's terms.
//!   - Types: Real is Float64; Integer is Int32, or an Enumeration where the contract lists
//!     its `items` (declared under TypeDefinitions, named as the variable, an array's
//!     variable by its declared name: one type for `gear[1].contact` .. `gear[8].contact`).
//!   - Value references: one space for all variables ([`crate::contract::fmi3`]); the
//!     independent variable `time` and Model Exchange's event indicators (Float64 locals
//!     `event_indicator_k`) are declared beside the contract's.
//!   - ModelStructure: Output, ContinuousStateDerivative, InitialUnknown and EventIndicator
//!     elements by value reference.
//!   - Capabilities renamed where FMI 3.0 renamed them, dropped where it has none (and
//!     canInterpolateInputs: FMI 3.0 has no fmi3SetInputDerivatives), and the adjoint
//!     derivatives wherever the directional ones are offered (fmi3-shell computes them from
//!     those). Co-Simulation's `hasEventMode` is the contract's (FMI 3.0 only; absent:
//!     false); no early return after an intermediate update (there is none).

use super::{
    Contract, Variable, attributes, esc, initial_unknowns, log_categories_and_experiment, units,
    value, variable_head,
};
use crate::contract::fmi3::{EVENT_INDICATOR_VR, INTEGER_VR_OFFSET, TIME_VR};
use std::fmt::Write as _;

/// A variable's FMI 3.0 value reference.
fn vr(v: &Variable) -> u32 {
    assert!(
        v.vr < INTEGER_VR_OFFSET,
        "{}: value reference {} is not below {INTEGER_VR_OFFSET} (FMI 3.0's Integer offset)",
        v.name,
        v.vr
    );
    match v.ty.as_str() {
        "Integer" => v.vr + INTEGER_VR_OFFSET,
        _ => v.vr,
    }
}

/// A variable's FMI 3.0 element name.
fn type_name(v: &Variable) -> &'static str {
    match (v.ty.as_str(), &v.items) {
        ("Real", _) => "Float64",
        ("Integer", Some(_)) => "Enumeration",
        ("Integer", None) => "Int32",
        (other, _) => panic!("{}: type {other} has no FMI 3.0 counterpart here", v.name),
    }
}

/// The name of an Enumeration variable's type: the variable's name as the contract declares it.
fn enumeration_type(v: &Variable) -> String {
    esc(v.element.as_ref().map_or(&v.name, |e| &e.declared))
}

/// The FMI 3.0 name and value of a capability of the contract (FMI 2.0's names), if FMI 3.0
/// has it.
fn capability(name: &str, v: &toml::Value) -> Option<(&'static str, String)> {
    let renamed = match name {
        "canGetAndSetFMUstate" => "canGetAndSetFMUState",
        "canSerializeFMUstate" => "canSerializeFMUState",
        "providesDirectionalDerivative" => "providesDirectionalDerivatives",
        "canHandleVariableCommunicationStepSize" => "canHandleVariableCommunicationStepSize",
        "maxOutputDerivativeOrder" => "maxOutputDerivativeOrder",
        "canBeInstantiatedOnlyOncePerProcess" => "canBeInstantiatedOnlyOncePerProcess",
        "needsExecutionTool" => "needsExecutionTool",
        "hasEventMode" => "hasEventMode",
        "completedIntegratorStepNotNeeded" => {
            let needed = !v.as_bool().expect("a boolean");
            return Some(("needsCompletedIntegratorStep", needed.to_string()));
        }
        _ => return None,
    };
    Some((renamed, value(v)))
}

/// An interface's element with its capabilities, `extra` after them.
fn interface(
    x: &mut String,
    element: &str,
    identifier: &str,
    caps: &std::collections::BTreeMap<String, toml::Value>,
    extra: &[(&str, &str)],
) {
    write!(x, "  <{element} modelIdentifier=\"{identifier}\"").unwrap();
    for (name, v) in caps.iter().filter_map(|(k, v)| capability(k, v)) {
        write!(x, " {name}=\"{v}\"").unwrap();
        if name == "providesDirectionalDerivatives" {
            write!(x, " providesAdjointDerivatives=\"{v}\"").unwrap();
        }
    }
    for (name, v) in extra {
        write!(x, " {name}=\"{v}\"").unwrap();
    }
    x.push_str("/>\n");
}

pub(super) fn xml(c: &Contract, token: &str) -> String {
    let mut x = String::new();
    let m = &c.model;
    let by_name = |name: &str| {
        vr(c.variable
            .iter()
            .find(|w| w.name == name)
            .unwrap_or_else(|| panic!("no variable {name}")))
    };
    x += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    writeln!(
        x,
        "<fmiModelDescription fmiVersion=\"3.0\" modelName=\"{}\" instantiationToken=\"{token}\" description=\"{}\" author=\"{}\" version=\"{}\" generationTool=\"fmi2-shell\" variableNamingConvention=\"{}\">",
        esc(&m.name),
        esc(&m.description),
        esc(&m.author),
        esc(&m.version),
        if c.array.is_empty() { "flat" } else { "structured" },
    )
    .unwrap();
    if let Some(caps) = &c.model_exchange {
        interface(&mut x, "ModelExchange", &m.identifier, caps, &[]);
    }
    interface(
        &mut x,
        "CoSimulation",
        &m.identifier,
        &c.capabilities,
        &[("canReturnEarlyAfterIntermediateUpdate", "false")],
    );
    units(&mut x, c);
    let mut declared = std::collections::BTreeSet::new();
    let enumerations: Vec<&Variable> = c
        .variable
        .iter()
        .filter(|v| v.items.is_some() && declared.insert(enumeration_type(v)))
        .collect();
    if !enumerations.is_empty() {
        x += "  <TypeDefinitions>\n";
        for v in &enumerations {
            writeln!(x, "    <EnumerationType name=\"{}\">", enumeration_type(v)).unwrap();
            for (k, (name, description)) in (v.first_item()..).zip(v.items.iter().flatten()) {
                writeln!(
                    x,
                    "      <Item name=\"{}\" value=\"{k}\" description=\"{}\"/>",
                    esc(name),
                    esc(description)
                )
                .unwrap();
            }
            x += "    </EnumerationType>\n";
        }
        x += "  </TypeDefinitions>\n";
    }
    log_categories_and_experiment(&mut x, c);
    x += "  <ModelVariables>\n";
    writeln!(
        x,
        "    <Float64 name=\"time\" valueReference=\"{TIME_VR}\" description=\"Simulation time\" causality=\"independent\" variability=\"continuous\" unit=\"s\"/>"
    )
    .unwrap();
    for v in &c.variable {
        variable_head(&mut x, type_name(v), v, vr(v));
        if let Some(name) = v.items.as_ref().map(|_| enumeration_type(v)) {
            write!(x, " declaredType=\"{name}\"").unwrap();
        }
        // An enumeration's range is its items.
        let derivative = v.derivative_of.as_deref().map(|s| by_name(s).to_string());
        attributes(&mut x, v, v.items.is_none(), derivative);
        x += "/>\n";
    }
    for k in 0..m.event_indicators {
        writeln!(
            x,
            "    <Float64 name=\"event_indicator_{}\" valueReference=\"{}\" description=\"Model Exchange's event indicator {} (fmi3GetEventIndicators)\" causality=\"local\" variability=\"continuous\"/>",
            k + 1,
            EVENT_INDICATOR_VR + k as u32,
            k + 1
        )
        .unwrap();
    }
    x += "  </ModelVariables>\n  <ModelStructure>\n";
    // An unknown with its dependencies (value references in increasing order), as declared.
    let unknown = |x: &mut String, element: &str, v: &Variable| {
        let mut deps: Vec<u32> = v.depends_on.iter().flatten().map(|d| by_name(d)).collect();
        deps.sort();
        let deps: Vec<String> = deps.iter().map(u32::to_string).collect();
        write!(
            x,
            "    <{element} valueReference=\"{}\" dependencies=\"{}\"",
            vr(v),
            deps.join(" ")
        )
        .unwrap();
        if !deps.is_empty() {
            let kinds = vec!["dependent"; deps.len()].join(" ");
            write!(x, " dependenciesKind=\"{kinds}\"").unwrap();
        }
        x.push_str("/>\n");
    };
    let outputs: Vec<&Variable> = c
        .variable
        .iter()
        .filter(|v| v.causality == "output")
        .collect();
    let derivatives: Vec<&Variable> = c
        .variable
        .iter()
        .filter(|v| v.derivative_of.is_some())
        .collect();
    for v in &outputs {
        unknown(&mut x, "Output", v);
    }
    for v in &derivatives {
        unknown(&mut x, "ContinuousStateDerivative", v);
    }
    for r in initial_unknowns(c, by_name) {
        writeln!(x, "    <InitialUnknown valueReference=\"{r}\"/>").unwrap();
    }
    for k in 0..m.event_indicators {
        writeln!(
            x,
            "    <EventIndicator valueReference=\"{}\"/>",
            EVENT_INDICATOR_VR + k as u32
        )
        .unwrap();
    }
    x += "  </ModelStructure>\n</fmiModelDescription>\n";
    x
}
