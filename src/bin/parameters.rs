//! Writes docs/PARAMETERS.md (or the path given) from the contract: the parameter and input
//! tables with units, defaults and ranges (`make docs-parameters`).

fn main() {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "docs/PARAMETERS.md".to_string());
    std::fs::write(&path, gear_rattle::contract::parameters_markdown())
        .unwrap_or_else(|e| panic!("{path}: {e}"));
}
