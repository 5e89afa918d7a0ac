//! The drivetrain at idle: engine flywheel, clutch torsional damper, gearbox main shaft.
//! One table of variables ([`VARIABLES`]) gives the value references, the start values and
//! the model description (`model_description`), so that the XML and the binary cannot drift.
//!
//! Equations (θ_E = θ_M + φ, φ the damper twist; τ_M the input):
//!
//! ```text
//! T_E = T_mean + T_2 sin(2 θ_E)                  gas torque, 2nd engine order (4-cyl. 4-stroke)
//! T_d = k_d φ + c_d (ω_E − ω_M)                  clutch torsional damper
//! I_E ω_E' = T_E − d_E ω_E − T_d                 d_E = T_mean / omega_idle (engine losses)
//! I_M ω_M' = T_d + τ_M                           τ_M: the gear contact's torque on the main shaft
//! θ_M' = ω_M,  φ' = ω_E − ω_M
//! ```
//!
//! The state integrates θ_M itself (what the gear pair needs to the micrometre on its pitch
//! line) and the twist φ, never θ_E − θ_M as a difference of two large angles.
#![allow(non_snake_case)]

use std::fmt::Write as _;

pub const MODEL_NAME: &str = "Flywheel";
pub const VERSION: &str = "0.1.0";

/// Value references (named as the variables).
#[allow(non_upper_case_globals)]
pub mod vr {
    pub const I_E: u32 = 1;
    pub const I_M: u32 = 2;
    pub const k_d: u32 = 3;
    pub const c_d: u32 = 4;
    pub const T_mean: u32 = 5;
    pub const T_2: u32 = 6;
    pub const omega_idle: u32 = 7;
    pub const h_max: u32 = 8;
    pub const tau_M: u32 = 10;
    pub const theta_M: u32 = 20;
    pub const omega_M: u32 = 21;
    pub const alpha_M: u32 = 22;
    pub const theta_E: u32 = 23;
    pub const omega_E: u32 = 24;
    pub const T_E: u32 = 25;
    pub const T_d: u32 = 26;
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    Input,
    Output,
}

/// One Real variable of the model description.
pub struct Variable {
    pub name: &'static str,
    pub vr: u32,
    pub causality: Causality,
    /// Start value (parameters and inputs).
    pub start: f64,
    pub unit: &'static str,
    pub display_unit: Option<&'static str>,
    /// Outputs only: whether the output depends on the input τ_M at once.
    pub feedthrough: bool,
    pub description: &'static str,
}

const fn var(
    name: &'static str,
    vr: u32,
    causality: Causality,
    start: f64,
    unit: &'static str,
    description: &'static str,
) -> Variable {
    Variable {
        name,
        vr,
        causality,
        start,
        unit,
        display_unit: None,
        feedthrough: false,
        description,
    }
}

use Causality::{Input, Output, Parameter};

/// Idle of a 4-cylinder 4-stroke petrol engine of about 1.6-2 L with a conventional
/// (single-mass) clutch damper: see partners/flywheel/README.md for the choice of values.
pub const VARIABLES: &[Variable] = &[
    var(
        "I_E",
        vr::I_E,
        Parameter,
        0.15,
        "kg.m2",
        "Inertia of the engine side: crankshaft, flywheel, clutch cover and pressure plate (> 0)",
    ),
    var(
        "I_M",
        vr::I_M,
        Parameter,
        0.008,
        "kg.m2",
        "Inertia of the main shaft: clutch disc hub, gearbox input shaft and its fixed gears (> 0)",
    ),
    var(
        "k_d",
        vr::k_d,
        Parameter,
        150.0,
        "N.m/rad",
        "Torsional stiffness of the clutch damper, idle stage (> 0)",
    ),
    var(
        "c_d",
        vr::c_d,
        Parameter,
        0.3,
        "N.m.s",
        "Viscous damping of the clutch damper, its hysteresis lumped (>= 0)",
    ),
    var(
        "T_mean",
        vr::T_mean,
        Parameter,
        15.0,
        "N.m",
        "Mean engine torque at idle, balanced by the engine losses d_E omega_E with d_E = T_mean / omega_idle (>= 0)",
    ),
    var(
        "T_2",
        vr::T_2,
        Parameter,
        80.0,
        "N.m",
        "Amplitude of the 2nd engine order of the gas torque: T_E = T_mean + T_2 sin(2 theta_E)",
    ),
    Variable {
        display_unit: Some("rpm"),
        ..var(
            "omega_idle",
            vr::omega_idle,
            Parameter,
            800.0 * std::f64::consts::PI / 30.0,
            "rad/s",
            "Idle speed: the start speed of both shafts and the speed at which T_mean balances the losses (> 0)",
        )
    },
    var(
        "h_max",
        vr::h_max,
        Parameter,
        1e-4,
        "s",
        "Largest internal RK4 sub-step; a communication step is cut into equal sub-steps no longer than this (> 0)",
    ),
    var(
        "tau_M",
        vr::tau_M,
        Input,
        0.0,
        "N.m",
        "Torque the gear contact exerts on the main shaft (GearRattle's tau_M): held over the communication step, or a ramp with its first derivative from fmi2SetRealInputDerivatives",
    ),
    var(
        "theta_M",
        vr::theta_M,
        Output,
        0.0,
        "rad",
        "Main-shaft angle (to GearRattle's theta_M)",
    ),
    Variable {
        display_unit: Some("rpm"),
        ..var(
            "omega_M",
            vr::omega_M,
            Output,
            0.0,
            "rad/s",
            "Main-shaft speed (to GearRattle's omega_M)",
        )
    },
    Variable {
        feedthrough: true,
        ..var(
            "alpha_M",
            vr::alpha_M,
            Output,
            0.0,
            "rad/s2",
            "Main-shaft angular acceleration, (T_d + tau_M) / I_M (to GearRattle's alpha_M)",
        )
    },
    var("theta_E", vr::theta_E, Output, 0.0, "rad", "Engine angle"),
    Variable {
        display_unit: Some("rpm"),
        ..var("omega_E", vr::omega_E, Output, 0.0, "rad/s", "Engine speed")
    },
    var(
        "T_E",
        vr::T_E,
        Output,
        0.0,
        "N.m",
        "Gas torque of the engine, T_mean + T_2 sin(2 theta_E)",
    ),
    var(
        "T_d",
        vr::T_d,
        Output,
        0.0,
        "N.m",
        "Torque of the clutch damper on the main shaft, k_d (theta_E - theta_M) + c_d (omega_E - omega_M)",
    ),
];

pub fn variable(vr: u32) -> Option<&'static Variable> {
    VARIABLES.iter().find(|v| v.vr == vr)
}

/// Parameters, validated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    pub I_E: f64,
    pub I_M: f64,
    pub k_d: f64,
    pub c_d: f64,
    pub T_mean: f64,
    pub T_2: f64,
    pub omega_idle: f64,
    pub h_max: f64,
}

/// State: θ_M, ω_M, φ = θ_E − θ_M, ω_E.
pub type State = [f64; 4];
const TH_M: usize = 0;
const OM_M: usize = 1;
const PHI: usize = 2;
const OM_E: usize = 3;

impl Params {
    /// Reads the parameters through `get` (value reference -> value) and checks them.
    pub fn from(get: impl Fn(u32) -> f64) -> Result<Self, String> {
        let p = Params {
            I_E: get(vr::I_E),
            I_M: get(vr::I_M),
            k_d: get(vr::k_d),
            c_d: get(vr::c_d),
            T_mean: get(vr::T_mean),
            T_2: get(vr::T_2),
            omega_idle: get(vr::omega_idle),
            h_max: get(vr::h_max),
        };
        let checks = [
            ("I_E", p.I_E, p.I_E > 0.0, "> 0"),
            ("I_M", p.I_M, p.I_M > 0.0, "> 0"),
            ("k_d", p.k_d, p.k_d > 0.0, "> 0"),
            ("c_d", p.c_d, p.c_d >= 0.0, ">= 0"),
            ("T_mean", p.T_mean, p.T_mean >= 0.0, ">= 0"),
            ("T_2", p.T_2, true, "finite"),
            ("omega_idle", p.omega_idle, p.omega_idle > 0.0, "> 0"),
            ("h_max", p.h_max, p.h_max > 0.0, "> 0"),
        ];
        for (name, value, ok, allowed) in checks {
            if !(ok && value.is_finite()) {
                return Err(format!(
                    "parameter {name} = {value:e} is invalid: allowed {allowed}"
                ));
            }
        }
        Ok(p)
    }

    /// Engine losses per unit speed.
    pub fn d_E(&self) -> f64 {
        self.T_mean / self.omega_idle
    }

    /// Both shafts at idle speed, no twist, θ = 0.
    pub fn initial_state(&self) -> State {
        [0.0, self.omega_idle, 0.0, self.omega_idle]
    }

    pub fn engine_torque(&self, y: &State) -> f64 {
        self.T_mean + self.T_2 * (2.0 * (y[TH_M] + y[PHI])).sin()
    }

    pub fn damper_torque(&self, y: &State) -> f64 {
        self.k_d * y[PHI] + self.c_d * (y[OM_E] - y[OM_M])
    }

    pub fn rhs(&self, y: &State, tau_M: f64) -> State {
        let t_d = self.damper_torque(y);
        [
            y[OM_M],
            (t_d + tau_M) / self.I_M,
            y[OM_E] - y[OM_M],
            (self.engine_torque(y) - self.d_E() * y[OM_E] - t_d) / self.I_E,
        ]
    }

    /// One classical Runge-Kutta step of size h, τ_M = tau_M + tau_dot (t − t_start).
    pub fn rk4(&self, y: &State, tau_M: f64, tau_dot: f64, h: f64) -> State {
        let add = |a: &State, k: &State, c: f64| std::array::from_fn(|i| a[i] + c * k[i]);
        let tau_mid = tau_M + 0.5 * h * tau_dot;
        let k1 = self.rhs(y, tau_M);
        let k2 = self.rhs(&add(y, &k1, 0.5 * h), tau_mid);
        let k3 = self.rhs(&add(y, &k2, 0.5 * h), tau_mid);
        let k4 = self.rhs(&add(y, &k3, h), tau_M + h * tau_dot);
        std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
    }

    /// Advances over h in equal RK4 sub-steps no longer than h_max, with the input
    /// τ_M(t_start + s) = tau_M + tau_dot s (tau_dot = 0 without input derivatives).
    pub fn advance(&self, y: &State, tau_M: f64, tau_dot: f64, h: f64) -> State {
        let n = (h / self.h_max * (1.0 - 1e-12)).ceil().max(1.0) as u64;
        let dt = h / n as f64;
        (0..n).fold(*y, |y, i| {
            self.rk4(&y, tau_M + tau_dot * (i as f64 * dt), tau_dot, dt)
        })
    }

    /// The value of an output at state y and input τ_M; None if `vr` is not an output.
    pub fn output(&self, vr: u32, y: &State, tau_M: f64) -> Option<f64> {
        let dy = || self.rhs(y, tau_M);
        Some(match vr {
            vr::theta_M => y[TH_M],
            vr::omega_M => y[OM_M],
            vr::alpha_M => dy()[OM_M],
            vr::theta_E => y[TH_M] + y[PHI],
            vr::omega_E => y[OM_E],
            vr::T_E => self.engine_torque(y),
            vr::T_d => self.damper_torque(y),
            _ => return None,
        })
    }

    /// First time derivative of an output, with τ_M' = tau_dot (fmi2GetRealOutputDerivatives).
    pub fn output_derivative(&self, vr: u32, y: &State, tau_M: f64, tau_dot: f64) -> Option<f64> {
        let dy = self.rhs(y, tau_M);
        // d/dt T_d = k_d φ' + c_d (ω_E' − ω_M')
        let dt_d = self.k_d * dy[PHI] + self.c_d * (dy[OM_E] - dy[OM_M]);
        Some(match vr {
            vr::theta_M => dy[TH_M],
            vr::omega_M => dy[OM_M],
            vr::alpha_M => (dt_d + tau_dot) / self.I_M,
            vr::theta_E => y[OM_E],
            vr::omega_E => dy[OM_E],
            vr::T_E => 2.0 * self.T_2 * (2.0 * (y[TH_M] + y[PHI])).cos() * y[OM_E],
            vr::T_d => dt_d,
            _ => return None,
        })
    }
}

// ---------------------------------------------------------------------------------------
// Model description
// ---------------------------------------------------------------------------------------

pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    (
        "logStatusError",
        "Refused calls and failed steps (always on)",
    ),
    ("logStatusWarning", "Warnings"),
];

/// A unit: name, SI base-unit exponents (XML attributes), display units (name, factor).
type Unit = (&'static str, &'static str, &'static [(&'static str, f64)]);

const UNITS: &[Unit] = &[
    ("s", r#"s="1""#, &[]),
    ("rad", r#"rad="1""#, &[("deg", 57.29577951308232)]),
    ("rad/s", r#"s="-1" rad="1""#, &[("rpm", 9.549296585513721)]),
    ("rad/s2", r#"s="-2" rad="1""#, &[]),
    ("kg.m2", r#"kg="1" m="2""#, &[]),
    ("N.m", r#"kg="1" m="2" s="-2""#, &[]),
    ("N.m/rad", r#"kg="1" m="2" s="-2" rad="-1""#, &[]),
    ("N.m.s", r#"kg="1" m="2" s="-1""#, &[]),
];

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn xml(guid: &str) -> String {
    let mut x = String::new();
    let w = &mut x;
    let _ = writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        w,
        r#"<fmiModelDescription fmiVersion="2.0" modelName="{MODEL_NAME}" guid="{guid}" description="Engine flywheel with 2nd-order firing acyclism driving the gearbox main shaft through a clutch torsional damper (GearRattle's drivetrain partner)" version="{VERSION}" generationTool="flywheel-package" variableNamingConvention="flat" numberOfEventIndicators="0">"#
    );
    let _ = writeln!(
        w,
        r#"  <CoSimulation modelIdentifier="{MODEL_NAME}" needsExecutionTool="false" canHandleVariableCommunicationStepSize="true" canInterpolateInputs="true" maxOutputDerivativeOrder="1" canRunAsynchronuously="false" canBeInstantiatedOnlyOncePerProcess="false" canNotUseMemoryManagementFunctions="true" canGetAndSetFMUstate="true" canSerializeFMUstate="true" providesDirectionalDerivative="false"/>"#
    );
    let _ = writeln!(w, "  <UnitDefinitions>");
    for (name, base, display) in UNITS {
        let _ = writeln!(w, r#"    <Unit name="{name}">"#);
        let _ = writeln!(w, r#"      <BaseUnit {base}/>"#);
        for (d, factor) in *display {
            let _ = writeln!(w, r#"      <DisplayUnit name="{d}" factor="{factor:?}"/>"#);
        }
        let _ = writeln!(w, "    </Unit>");
    }
    let _ = writeln!(w, "  </UnitDefinitions>");
    let _ = writeln!(w, "  <LogCategories>");
    for (name, description) in LOG_CATEGORIES {
        let _ = writeln!(
            w,
            r#"    <Category name="{name}" description="{}"/>"#,
            escape(description)
        );
    }
    let _ = writeln!(w, "  </LogCategories>");
    let _ = writeln!(
        w,
        r#"  <DefaultExperiment startTime="0.0" stopTime="1.0" stepSize="1e-4"/>"#
    );
    let _ = writeln!(w, "  <ModelVariables>");
    for v in VARIABLES {
        let (causality, variability, initial) = match v.causality {
            Parameter => ("parameter", "fixed", ""),
            Input => ("input", "continuous", ""),
            Output => ("output", "continuous", r#" initial="calculated""#),
        };
        let start = match v.causality {
            Output => String::new(),
            _ => format!(r#" start="{:?}""#, v.start),
        };
        let display = v
            .display_unit
            .map(|d| format!(r#" displayUnit="{d}""#))
            .unwrap_or_default();
        let _ = writeln!(
            w,
            r#"    <ScalarVariable name="{}" valueReference="{}" description="{}" causality="{causality}" variability="{variability}"{initial}>"#,
            v.name,
            v.vr,
            escape(v.description)
        );
        let _ = writeln!(w, r#"      <Real unit="{}"{display}{start}/>"#, v.unit);
        let _ = writeln!(w, "    </ScalarVariable>");
    }
    let _ = writeln!(w, "  </ModelVariables>");
    // ModelStructure: indices are 1-based positions in ModelVariables.
    let index = |vr: u32| VARIABLES.iter().position(|v| v.vr == vr).expect("declared") + 1;
    let outputs: Vec<_> = VARIABLES.iter().filter(|v| v.causality == Output).collect();
    let _ = writeln!(w, "  <ModelStructure>");
    let _ = writeln!(w, "    <Outputs>");
    for v in &outputs {
        let deps = if v.feedthrough {
            index(vr::tau_M).to_string()
        } else {
            String::new()
        };
        let kind = if v.feedthrough {
            r#" dependenciesKind="dependent""#
        } else {
            ""
        };
        let _ = writeln!(
            w,
            r#"      <Unknown index="{}" dependencies="{deps}"{kind}/>"#,
            index(v.vr)
        );
    }
    let _ = writeln!(w, "    </Outputs>");
    // At initialisation every output depends on the parameters, alpha_M also on tau_M.
    let _ = writeln!(w, "    <InitialUnknowns>");
    for v in &outputs {
        let _ = writeln!(w, r#"      <Unknown index="{}"/>"#, index(v.vr));
    }
    let _ = writeln!(w, "    </InitialUnknowns>");
    let _ = writeln!(w, "  </ModelStructure>");
    let _ = writeln!(w, "</fmiModelDescription>");
    x
}

/// FNV-1a, 64 bits, from a given offset basis.
fn fnv1a(bytes: &[u8], basis: u64) -> u64 {
    bytes.iter().fold(basis, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x100_0000_01b3)
    })
}

/// The GUID: a hash of the model description written without it, so it changes with
/// every change of the variables or capabilities.
pub fn guid() -> String {
    let body = xml("");
    let a = fnv1a(body.as_bytes(), 0xcbf2_9ce4_8422_2325);
    let b = fnv1a(body.as_bytes(), a ^ 0x9e37_79b9_7f4a_7c15);
    let hex = format!("{a:016x}{b:016x}");
    let part = |r: std::ops::Range<usize>| &hex[r];
    format!(
        "{{{}-{}-{}-{}-{}}}",
        part(0..8),
        part(8..12),
        part(12..16),
        part(16..20),
        part(20..32)
    )
}

/// modelDescription.xml.
pub fn model_description() -> String {
    xml(&guid())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn defaults() -> Params {
        Params::from(|vr| variable(vr).unwrap().start).unwrap()
    }

    #[test]
    fn value_references_are_unique() {
        for (i, a) in VARIABLES.iter().enumerate() {
            for b in &VARIABLES[i + 1..] {
                assert_ne!(a.vr, b.vr, "{} and {}", a.name, b.name);
                assert_ne!(a.name, b.name);
            }
        }
    }

    #[test]
    fn guid_is_stable_and_in_the_xml() {
        assert_eq!(guid(), guid());
        assert!(model_description().contains(&format!(r#"guid="{}""#, guid())));
    }

    #[test]
    fn rk4_is_fourth_order() {
        // with tau_M = 0 the error of one RK4 run over 10 ms falls ~16x when h halves
        let p = defaults();
        let y0 = p.initial_state();
        let run = |n: u32| (0..n).fold(y0, |y, _| p.rk4(&y, 0.0, 0.0, 0.01 / f64::from(n)));
        let exact = run(4096);
        let e1 = (run(8)[1] - exact[1]).abs();
        let e2 = (run(16)[1] - exact[1]).abs();
        assert!(e1 / e2 > 12.0 && e1 / e2 < 20.0, "ratio {}", e1 / e2);
    }

    #[test]
    fn energy_balance_without_losses() {
        // T_mean = 0 (no losses), c_d = 0, T_2 = 0: kinetic + damper energy is constant
        let p = Params {
            T_mean: 0.0,
            T_2: 0.0,
            c_d: 0.0,
            ..defaults()
        };
        let y0 = [0.0, 80.0, 0.01, 90.0];
        let energy = |y: &State| {
            0.5 * p.I_M * y[1] * y[1] + 0.5 * p.I_E * y[3] * y[3] + 0.5 * p.k_d * y[2] * y[2]
        };
        let y = p.advance(&y0, 0.0, 0.0, 0.2);
        assert!((energy(&y) / energy(&y0) - 1.0).abs() < 1e-10);
    }

    #[test]
    fn output_derivatives_match_finite_differences() {
        // tau_M(t) = -0.3 + 40 (t - t1) around t1: central differences of the outputs
        let p = defaults();
        let (tau, tau_dot, h) = (-0.3, 40.0, 1e-7);
        let y = p.advance(&p.initial_state(), tau, 0.0, 0.0137);
        let ya = p.advance(&y, tau, tau_dot, h);
        let yb = p.advance(&y, tau, tau_dot, -h);
        for v in VARIABLES.iter().filter(|v| v.causality == Output) {
            let out = |y: &State, dt: f64| p.output(v.vr, y, tau + tau_dot * dt).unwrap();
            let fd = (out(&ya, h) - out(&yb, -h)) / (2.0 * h);
            let d = p.output_derivative(v.vr, &y, tau, tau_dot).unwrap();
            assert!(
                (fd - d).abs() <= 1e-5 * d.abs().max(1.0),
                "{}: {d} vs {fd}",
                v.name
            );
        }
    }

    #[test]
    fn input_derivative_is_integrated_exactly_enough() {
        // a ramp of tau_M over one 1 ms step: 10 sub-steps agree with 1000 of them (RK4 error)
        let p = defaults();
        let y0 = p.initial_state();
        let coarse = p.advance(&y0, -1.0, 500.0, 1e-3);
        let fine = Params { h_max: 1e-6, ..p }.advance(&y0, -1.0, 500.0, 1e-3);
        assert!(
            (coarse[1] - fine[1]).abs() < 1e-9,
            "{} vs {}",
            coarse[1],
            fine[1]
        );
        // and differs from a held tau_M by the ramp's effect, 500 h^2 / (2 I_M), to within the
        // damper's reaction over the step (c_d h / (3 I_M) ~ 1 %)
        let held = p.advance(&y0, -1.0, 0.0, 1e-3);
        let effect = 500.0 * 1e-6 / (2.0 * p.I_M);
        assert!(((coarse[1] - held[1]) / effect - 1.0).abs() < 0.05);
    }
}
