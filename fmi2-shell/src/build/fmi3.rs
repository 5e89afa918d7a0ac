//! The FMI 3.0 model description of a contract, beside FMI 2.0's ([`super::xml`]): the same
//! variables, units and capabilities in FMI 3.0's terms.
//!   - Types: Real is Float64; Integer is Int32, or an Enumeration where the contract lists
//!     its `items` (declared under TypeDefinitions, named as the variable, an array's
//!     variable by its declared name: one type `contact` for `gear.contact`).
//!   - Arrays: each variable of an `[[array]]` once, named `ARRAY.NAME` (`gear.xi`,
//!     `der(gear.xi)`), with one `<Dimension>` whose length is the structural parameter
//!     `n_ARRAYs` (UInt64, causality structuralParameter, variability fixed: set in
//!     configuration mode), its start the first `n_ARRAYs` elements' starts; reference
//!     `vr_base + offset` ([`crate::contract::fmi3::Array`]).
//!   - Value references: one space for all variables ([`crate::contract::fmi3`]); the
//!     independent variable `time` and Model Exchange's event indicators (Float64 locals
//!     `event_indicator_k`) are declared beside the contract's.
//!   - ModelStructure: Output, ContinuousStateDerivative, InitialUnknown and EventIndicator
//!     elements by value reference (an array's once: the states are phi, x_omega_I,
//!     x_theta_F, x_omega_F, then every gear's xi, then every gear's xi_dot).
//!   - Capabilities renamed where FMI 3.0 renamed them, dropped where it has none (and
//!     canInterpolateInputs: FMI 3.0 has no fmi3SetInputDerivatives), and the adjoint
//!     derivatives wherever the directional ones are offered (fmi3-shell computes them from
//!     those). Co-Simulation's `hasEventMode` is the contract's (FMI 3.0 only; absent:
//!     false), and so is `canReturnEarlyAfterIntermediateUpdate` (fmi3-shell calls the
//!     intermediateUpdate callback at the events where a step may end).

use super::{
    Array, Contract, Variable, attributes, esc, initial_unknowns, log_categories_and_experiment,
    units, value, variable_head,
};
use crate::contract::fmi3::{EVENT_INDICATOR_VR, INTEGER_VR_OFFSET, TIME_VR};
use std::fmt::Write as _;

/// The contract's array named `name`.
fn array<'c>(c: &'c Contract, name: &str) -> &'c Array {
    c.array
        .iter()
        .find(|a| a.name == name)
        .expect("expanded from an array")
}

/// The array whose length the variable gives, if it is a structural parameter.
fn sized_by<'c>(c: &'c Contract, v: &Variable) -> Option<&'c Array> {
    c.array.iter().find(|a| a.size_parameter() == v.name)
}

/// A variable's FMI 3.0 value reference: an array element's is its array variable's.
fn vr(c: &Contract, v: &Variable) -> u32 {
    assert!(
        v.vr < INTEGER_VR_OFFSET,
        "{}: value reference {} is not below {INTEGER_VR_OFFSET} (FMI 3.0's Integer offset)",
        v.name,
        v.vr
    );
    let own = match &v.element {
        Some(e) => v.vr - array(c, &e.array).vr_stride * e.index as u32,
        None => v.vr,
    };
    match v.ty.as_str() {
        "Integer" => own + INTEGER_VR_OFFSET,
        _ => own,
    }
}

/// The variables as FMI 3.0 declares them: an array's once (its element 1 renamed, without
/// start: [`array_start`]), a structural parameter as such.
fn declared(c: &Contract) -> Vec<Variable> {
    c.variable
        .iter()
        .filter(|v| v.element.as_ref().is_none_or(|e| e.index == 1))
        .map(|v| match (&v.element, sized_by(c, v)) {
            (Some(e), _) => {
                let name = match e.declared.strip_prefix("der(").and_then(|n| n.strip_suffix(')')) {
                    Some(state) => format!("der({}.{state})", e.array),
                    None => format!("{}.{}", e.array, e.declared),
                };
                Variable {
                    name,
                    start: None,
                    ..v.clone()
                }
            }
            (None, Some(a)) => Variable {
                causality: "structuralParameter".into(),
                description: format!(
                    "Length of the {0}.* arrays: {0}s 1..{1} (structural parameter, set in configuration mode)",
                    a.name,
                    a.size_parameter()
                ),
                ..v.clone()
            },
            (None, None) => v.clone(),
        })
        .collect()
}

/// An array variable's start: its first elements' starts (as many as the structural
/// parameter's start), where the contract gives them.
fn array_start(c: &Contract, v: &Variable) -> Option<String> {
    let e = v.element.as_ref()?;
    let n = c
        .variable
        .iter()
        .find(|w| w.name == array(c, &e.array).size_parameter())
        .and_then(|w| w.start.as_ref())
        .and_then(toml::Value::as_integer)
        .expect("an Integer start") as usize;
    let starts: Option<Vec<String>> = c
        .variable
        .iter()
        .filter(|w| {
            w.element
                .as_ref()
                .is_some_and(|f| f.array == e.array && f.declared == e.declared && f.index <= n)
        })
        .map(|w| w.start.as_ref().map(value))
        .collect();
    starts.map(|s| s.join(" "))
}

/// A variable's FMI 3.0 element name.
fn type_name(c: &Contract, v: &Variable) -> &'static str {
    if sized_by(c, v).is_some() {
        return "UInt64";
    }
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
        vr(
            c,
            c.variable
                .iter()
                .find(|w| w.name == name)
                .unwrap_or_else(|| panic!("no variable {name}")),
        )
    };
    let variables = declared(c);
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
        &[(
            "canReturnEarlyAfterIntermediateUpdate",
            &c.capabilities
                .get("hasEventMode")
                .map_or("false".into(), value),
        )],
    );
    units(&mut x, c);
    let mut declared = std::collections::BTreeSet::new();
    let enumerations: Vec<&Variable> = variables
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
    for v in &variables {
        let element = type_name(c, v);
        variable_head(&mut x, element, v, vr(c, v));
        if let Some(name) = v.items.as_ref().map(|_| enumeration_type(v)) {
            write!(x, " declaredType=\"{name}\"").unwrap();
        }
        // An enumeration's range is its items.
        let derivative = v.derivative_of.as_deref().map(|s| by_name(s).to_string());
        attributes(&mut x, v, v.items.is_none(), derivative);
        match &v.element {
            None => x += "/>\n",
            Some(e) => {
                if let Some(start) = array_start(c, v) {
                    write!(x, " start=\"{start}\"").unwrap();
                }
                let n = by_name(&array(c, &e.array).size_parameter());
                writeln!(
                    x,
                    ">\n      <Dimension valueReference=\"{n}\"/>\n    </{element}>"
                )
                .unwrap();
            }
        }
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
        deps.dedup();
        let deps: Vec<String> = deps.iter().map(u32::to_string).collect();
        write!(
            x,
            "    <{element} valueReference=\"{}\" dependencies=\"{}\"",
            vr(c, v),
            deps.join(" ")
        )
        .unwrap();
        if !deps.is_empty() {
            let kinds = vec!["dependent"; deps.len()].join(" ");
            write!(x, " dependenciesKind=\"{kinds}\"").unwrap();
        }
        x.push_str("/>\n");
    };
    let outputs: Vec<&Variable> = variables
        .iter()
        .filter(|v| v.causality == "output")
        .collect();
    let derivatives: Vec<&Variable> = variables
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
