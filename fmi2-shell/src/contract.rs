//! The types of a model's contract, as the generated constants use them
//! ([`build`](crate::build) writes them from the contract TOML).

/// FMI 2.0 base type of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Real,
    Integer,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    /// Fixed parameter: set before or during initialisation only.
    Parameter,
    /// Continuous input, set at communication points.
    Input,
    /// Computed by the FMU, read-only.
    Output,
    /// Computed by the FMU, read-only, not meant for connections: the continuous states
    /// and their derivatives of Model Exchange that are not outputs.
    Local,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Start {
    None,
    Real(f64),
    Integer(i64),
}

/// One scalar variable of the model description.
#[derive(Debug)]
pub struct Variable {
    pub name: &'static str,
    pub vr: u32,
    pub kind: Kind,
    pub causality: Causality,
    pub start: Start,
    /// SI unit as named in UnitDefinitions ("" for dimensionless).
    pub unit: &'static str,
    /// Outputs: the inputs it depends on at once (ModelStructure's dependencies).
    pub depends_on: &'static [&'static str],
    /// Outputs: whether fmi2GetRealOutputDerivatives gives its first derivative.
    pub derivative: bool,
    pub description: &'static str,
}
