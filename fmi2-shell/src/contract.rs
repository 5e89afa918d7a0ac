//! The types of a model's contract, as the generated constants use them
//! ([`build`](crate::build) writes them from the contract TOML), the checks of the
//! fmi2Set* calls against it, and of the parameters against their ranges.

use crate::state::FmiState;
use crate::status::{FmiError, FmiResult};
use crate::values::Values;

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

/// One end of a variable's range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bound {
    /// No bound on this side.
    None,
    /// The value may equal the bound (FMI's min/max).
    Inclusive(f64),
    /// The value must stay strictly beyond the bound (I_L > 0). FMI 2.0's XML has no such
    /// attribute: it carries the nearest double inside the range, which admits the same
    /// doubles.
    Exclusive(f64),
}

/// The values a variable may take (besides being finite, for a Real).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    pub min: Bound,
    pub max: Bound,
}

impl Range {
    /// Any value.
    pub const ANY: Range = Range {
        min: Bound::None,
        max: Bound::None,
    };

    pub fn contains(&self, x: f64) -> bool {
        let above = match self.min {
            Bound::None => true,
            Bound::Inclusive(b) => x >= b,
            Bound::Exclusive(b) => x > b,
        };
        let below = match self.max {
            Bound::None => true,
            Bound::Inclusive(b) => x <= b,
            Bound::Exclusive(b) => x < b,
        };
        above && below
    }

    /// The range as a statement on `name`: "I_L > 0", "0 <= excitation <= 2", "x < 1";
    /// empty without bounds. The model description's descriptions end with it, in
    /// parentheses after "range: ", and the study runner reads it there.
    pub fn statement(&self, name: &str) -> String {
        let op = |b: &Bound| match b {
            Bound::Inclusive(x) => Some(("<=", *x)),
            Bound::Exclusive(x) => Some(("<", *x)),
            Bound::None => None,
        };
        match (op(&self.min), op(&self.max)) {
            (None, None) => String::new(),
            (Some((o, lo)), None) => format!("{name} {} {}", o.replace('<', ">"), number(lo)),
            (None, Some((o, hi))) => format!("{name} {o} {}", number(hi)),
            (Some((o1, lo)), Some((o2, hi))) => {
                format!("{} {o1} {name} {o2} {}", number(lo), number(hi))
            }
        }
    }
}

/// A number as the statements and the documentation's tables write it: whole numbers without
/// a fraction, others in Rust's shortest round-trip form (0.05236, 1e-6), which Python's
/// float() reads back exactly.
pub fn number(x: f64) -> String {
    if x.fract() == 0.0 && x.abs() < 1e15 {
        format!("{x:.0}")
    } else {
        format!("{x:?}")
    }
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
    /// Parameters: the values the model accepts (checked by [`check_parameters`]).
    pub range: Range,
    /// Outputs and state derivatives: the inputs and continuous states it depends on at once
    /// (ModelStructure's dependencies).
    pub depends_on: &'static [&'static str],
    /// Outputs: whether fmi2GetRealOutputDerivatives gives its first derivative.
    pub derivative: bool,
    pub description: &'static str,
}

impl Variable {
    /// Checks that the variable may be set in `state`: not one the FMU computes, and a
    /// parameter only before fmi2ExitInitializationMode.
    pub fn settable(&self, state: FmiState) -> FmiResult {
        let why = match self.causality {
            Causality::Output => "is an output: it cannot be set",
            Causality::Local => "is computed by the FMU: it cannot be set",
            Causality::Parameter if state.is_initialised() => {
                "is a fixed parameter: set it before fmi2ExitInitializationMode"
            }
            _ => return Ok(()),
        };
        Err(FmiError::error(format!("{} {why}", self.name)))
    }

    /// [`settable`](Self::settable) to a finite `value` (fmi2SetReal).
    pub fn settable_to(&self, state: FmiState, value: f64) -> FmiResult {
        self.settable(state)?;
        if value.is_finite() {
            Ok(())
        } else {
            Err(FmiError::error(format!(
                "{} = {value} refused: values must be finite",
                self.name
            )))
        }
    }
}

/// Checks every parameter against its range, in the contract's order: the first one outside
/// is refused with a message naming it, its value and its range.
pub fn check_parameters(variables: &[Variable], values: &Values) -> FmiResult {
    for v in variables
        .iter()
        .filter(|v| v.causality == Causality::Parameter)
    {
        let value = match v.kind {
            Kind::Real => values.real(v.vr),
            Kind::Integer => values.integer(v.vr) as f64,
        };
        check_parameter(v, value)?;
    }
    Ok(())
}

/// Checks one parameter's value (an Integer's as f64) against its range.
pub fn check_parameter(v: &Variable, value: f64) -> FmiResult {
    let finite = v.kind == Kind::Integer || value.is_finite();
    if finite && v.range.contains(value) {
        return Ok(());
    }
    let statement = v.range.statement(v.name);
    let (shown, allowed) = match (v.kind, statement.is_empty()) {
        (Kind::Real, true) => (format!("{value:e}"), "finite values".to_string()),
        (Kind::Real, false) => (format!("{value:e}"), format!("{statement} (finite)")),
        (Kind::Integer, _) => ((value as i64).to_string(), statement),
    };
    Err(FmiError::error(format!(
        "parameter {} = {shown} is invalid: allowed {allowed}",
        v.name
    )))
}

/// Whether any of `vrs` is a variable the model computes (an output or a local), looked up
/// with `variable` (unknown references are not).
pub fn computed(
    variable: fn(Kind, u32) -> FmiResult<&'static Variable>,
    kind: Kind,
    vrs: &[u32],
) -> bool {
    vrs.iter().any(|vr| {
        variable(kind, *vr)
            .is_ok_and(|v| matches!(v.causality, Causality::Output | Causality::Local))
    })
}

/// The error of a value reference the contract has no variable of that kind for.
pub fn unknown(kind: Kind, vr: u32) -> FmiError {
    FmiError::error(format!("unknown value reference {vr} for type {kind:?}"))
}

/// The error of any value reference for a kind the contract has no variables of (fmi2Get/Set
/// Boolean and String; Integer in a model without Integer variables).
pub fn no_variables(kind: &str, vrs: &[u32]) -> FmiResult {
    match vrs.first() {
        None => Ok(()),
        Some(vr) => Err(FmiError::error(format!(
            "unknown value reference {vr} for type {kind}: the model has no {kind} variables"
        ))),
    }
}

/// FMI 3.0's value references: one space for all variables, where FMI 2.0 has one per type.
/// The FMI 3.0 model description and exports keep a Real's reference, move an Integer's by
/// [`INTEGER_VR_OFFSET`](fmi3::INTEGER_VR_OFFSET), and give the variables FMI 3.0 declares
/// beyond the contract's, the independent variable `time` and Model Exchange's event
/// indicators, references from [`TIME_VR`](fmi3::TIME_VR) on. A contract's references stay
/// below the offset (the generator checks).
pub mod fmi3 {
    pub const INTEGER_VR_OFFSET: u32 = 1_000_000;
    pub const TIME_VR: u32 = 2_000_000;
    /// The first event indicator's; the k-th (from 0) is this + k.
    pub const EVENT_INDICATOR_VR: u32 = TIME_VR + 1;

    /// A contract's array (`gear`) as FMI 3.0 declares it: each of its variables one array
    /// of length `n`, the value of the structural parameter `size_vr` (an Integer of the
    /// contract, 1..=`size`). The array variable of offset k has the reference
    /// `vr_base + k` (below element 1's block), its element i (1-based) the contract's
    /// `vr_base + vr_stride i + k`, Real and Integer alike.
    #[derive(Clone, Copy, Debug)]
    pub struct Array {
        pub size_vr: u32,
        pub size: usize,
        pub vr_base: u32,
        pub vr_stride: u32,
    }

    impl Array {
        /// The offset of the array variable with the contract reference `vr`, if it is one.
        pub fn offset(&self, vr: u32) -> Option<u32> {
            vr.checked_sub(self.vr_base).filter(|k| *k < self.vr_stride)
        }

        /// The offset of the element variable `vr` (any element), if it is one.
        pub fn element_offset(&self, vr: u32) -> Option<u32> {
            self.element(vr).map(|(_, k)| k)
        }

        /// The element (1-based) and the offset of the element variable `vr`, if it is one.
        pub fn element(&self, vr: u32) -> Option<(usize, u32)> {
            let k = vr.checked_sub(self.vr_base + self.vr_stride)?;
            (k < self.vr_stride * self.size as u32)
                .then(|| ((k / self.vr_stride) as usize + 1, k % self.vr_stride))
        }

        /// The contract references of the first `n` elements of the array variable of
        /// offset `k`.
        pub fn elements(&self, k: u32, n: usize) -> impl Iterator<Item = u32> + '_ {
            (1..=n as u32).map(move |i| self.vr_base + self.vr_stride * i + k)
        }
    }
}
