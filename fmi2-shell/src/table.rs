//! A model's variable tables for its documentation, formatted from its contract: HTML for the
//! FMU's `documentation/index.html`, Markdown for the repository's docs/PARAMETERS.md. One
//! row per variable of a causality, in the contract's order, with its range as the instance
//! checks it.

use crate::contract::{Causality, Start, Variable, number};

/// A start value as written in the tables ("" for none).
fn start(s: &Start) -> String {
    match s {
        Start::Real(x) => number(*x),
        Start::Integer(i) => i.to_string(),
        Start::None => String::new(),
    }
}

fn rows(variables: &[Variable], causality: Causality) -> impl Iterator<Item = &Variable> {
    variables.iter().filter(move |v| v.causality == causality)
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// An HTML table with a heading: name, value reference, type, start, unit, range,
/// description.
pub fn html(title: &str, variables: &[Variable], causality: Causality) -> String {
    let mut html = format!(
        "<h2>{title}</h2>\n<table><tr><th>name</th><th>value reference</th><th>type</th><th>start</th><th>unit</th><th>range</th><th>description</th></tr>\n"
    );
    for v in rows(variables, causality) {
        html += &format!(
            "<tr><td><code>{}</code></td><td>{}</td><td>{:?}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
            v.name,
            v.vr,
            v.kind,
            start(&v.start),
            v.unit,
            html_escape(&v.range.statement(v.name)),
            html_escape(v.description)
        );
    }
    html + "</table>\n"
}

/// A Markdown table: name, unit, default, range, description.
pub fn markdown(variables: &[Variable], causality: Causality) -> String {
    let mut md =
        String::from("| name | unit | default | range | description |\n|---|---|---|---|---|\n");
    let code = |s: String| {
        if s.is_empty() { s } else { format!("`{s}`") }
    };
    for v in rows(variables, causality) {
        md += &format!(
            "| `{}` | {} | {} | {} | {} |\n",
            v.name,
            v.unit,
            start(&v.start),
            code(v.range.statement(v.name)),
            v.description.replace('|', "\\|")
        );
    }
    md
}
