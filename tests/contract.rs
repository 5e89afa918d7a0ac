//! The contract (modelDescription/GearRattle.toml) against what the simulation computes:
//! every output is computed in every coupling, each output's derivative is given exactly
//! where the contract says so, each Real output moves with an input at once exactly where
//! its `depends_on` (the model description's ModelStructure) says so, and each Model
//! Exchange state derivative with the states and inputs its `depends_on` names.

use fmi2_shell::Continuous;
use fmi2_shell::values::Values;
use gear_rattle::contract::{Causality, Kind, STATES, VARIABLES, Variable, vr};
use gear_rattle::instance::model_exchange::column;
use gear_rattle::instance::{Carry, Simulation};
use std::collections::BTreeSet;

/// A simulation in contact on F+ and moving (so that the contact's stiffness and damping
/// both act), with the main shaft driven by `excitation`.
fn in_contact(excitation: i64) -> Simulation {
    starting_at(excitation, -0.2)
}

/// A simulation starting at ξ = gap_start G and moving, with the main shaft driven by
/// `excitation`.
fn starting_at(excitation: i64, gap_start: f64) -> Simulation {
    let mut values = Values::start(gear_rattle::contract::VARIABLES);
    values.set_integer(vr::excitation, excitation);
    values.set_real(vr::gap_start, gap_start);
    values.set_real(vr::xi_dot_start, 0.01);
    values.set_real(vr::omega_M, 3.0);
    values.set_real(vr::alpha_M, 40.0);
    values.set_real(vr::tau_in, 0.5);
    values.set_real(vr::stats_from, 0.0);
    Simulation::new(&values, 0.0, 0.0, 1e-6, Carry::Asked).expect("valid parameters")
}

fn outputs(kind: Kind) -> impl Iterator<Item = &'static Variable> {
    VARIABLES
        .iter()
        .filter(move |v| v.causality == Causality::Output && v.kind == kind)
}

const COUPLINGS: [i64; 3] = [0, 1, 2];
/// ξ / G at the start: in each region of the contact law (both contacts, both bands, the gap).
const GAP_STARTS: [f64; 5] = [-0.2, -0.02, 0.5, 1.02, 1.2];

#[test]
fn every_output_is_computed_in_every_coupling() {
    for excitation in COUPLINGS {
        let mut sim = in_contact(excitation);
        for t in [0.0, 0.01] {
            sim.step_to(t).unwrap();
            for v in outputs(Kind::Real) {
                let value = sim.real_output(v.vr);
                assert!(
                    value.is_some_and(f64::is_finite),
                    "{} ({excitation}): {value:?}",
                    v.name
                );
            }
            for v in outputs(Kind::Integer) {
                assert!(
                    sim.integer_output(v.vr).is_some(),
                    "{} ({excitation})",
                    v.name
                );
            }
        }
    }
}

#[test]
fn derivatives_are_given_exactly_where_the_contract_says() {
    let sim = in_contact(0);
    for v in outputs(Kind::Real) {
        assert_eq!(
            sim.real_output_derivative(v.vr).is_some(),
            v.derivative,
            "{}: derivative given, against the contract",
            v.name
        );
    }
}

/// Real outputs that an input moves only by a jump (a new input that puts ξ into contact
/// counts an impact at once): `depends_on` names the inputs, their partials are zero.
const PIECEWISE_CONSTANT: [u32; 1] = [vr::impact_speed];

/// An output moves at once with an input, in the coupling that uses the input, exactly for
/// the inputs `depends_on` names (θ_M, ω_M, α_M in the inputs mode; τ_in in the torque mode):
/// in co-simulation (∂output/∂input non-zero: ξ follows θ_M, θ_L holds) or in Model
/// Exchange (the states held: θ_L follows θ_M).
#[test]
fn partials_are_non_zero_exactly_where_depends_on_says() {
    let (inputs_mode, torque_mode) = (in_contact(0), in_contact(2));
    let mut model_exchange = model_exchange_points();
    let inputs: Vec<&Variable> = VARIABLES
        .iter()
        .filter(|v| v.causality == Causality::Input)
        .collect();
    for v in outputs(Kind::Real) {
        let moved: Vec<&str> = inputs
            .iter()
            .filter(|u| {
                let sim = if u.vr == vr::tau_in {
                    &torque_mode
                } else {
                    &inputs_mode
                };
                sim.partial(v.vr, u.vr) != 0.0
                    || SHAFT_INPUTS.contains(&u.vr)
                        && model_exchange.iter_mut().any(|sim| moves(sim, v, u.vr))
            })
            .map(|u| u.name)
            .collect();
        if PIECEWISE_CONSTANT.contains(&v.vr) {
            assert!(moved.is_empty() && !v.depends_on.is_empty(), "{}", v.name);
            continue;
        }
        let mut declared: Vec<&str> = v
            .depends_on
            .iter()
            .copied()
            .filter(|d| inputs.iter().any(|u| u.name == *d))
            .collect();
        declared.sort_by_key(|name| inputs.iter().position(|u| u.name == *name));
        assert_eq!(
            moved, declared,
            "{}: inputs it moves with, against depends_on",
            v.name
        );
    }
}

/// Model Exchange: ∂ẋ_i/∂known of fmi2GetDirectionalDerivative's Jacobian is non-zero, in
/// some region of the contact law (both contacts, both bands, the gap) and some drive mode,
/// exactly for the states and inputs of der(x_i)'s `depends_on` (ModelStructure/Derivatives).
#[test]
fn state_derivatives_move_exactly_with_what_depends_on_says() {
    let knowns: Vec<&Variable> = VARIABLES
        .iter()
        .filter(|v| v.kind == Kind::Real && column(v.vr).is_some())
        .collect();
    let jacobians: Vec<_> = COUPLINGS
        .iter()
        .flat_map(|&excitation| {
            GAP_STARTS.map(|gap_start| starting_at(excitation, gap_start).jacobian())
        })
        .collect();
    let derivatives = VARIABLES
        .iter()
        .filter(|v| gear_rattle::contract::DERIVATIVES.contains(&v.vr));
    for d in derivatives {
        let moved: BTreeSet<&str> = knowns
            .iter()
            .filter(|k| {
                let c = column(k.vr).expect("a known");
                jacobians
                    .iter()
                    .any(|j| j.gradient(d.vr).expect("a derivative").0[c] != 0.0)
            })
            .map(|k| k.name)
            .collect();
        let declared: BTreeSet<&str> = d.depends_on.iter().copied().collect();
        assert_eq!(
            moved, declared,
            "{}: what it moves with, against depends_on",
            d.name
        );
    }
}

/// Model Exchange: an output moves when a continuous state is set to another value
/// (fmi2SetContinuousStates), in some region of the contact law and some drive mode, with
/// the statistics' window open, exactly for the states its `depends_on` names
/// (ModelStructure/Outputs). Outputs that change at events only (the counters, the located
/// extrema) name no state.
#[test]
fn outputs_move_exactly_with_the_states_depends_on_names() {
    let name = |vr: u32| {
        VARIABLES
            .iter()
            .find(|v| v.vr == vr && v.kind == Kind::Real)
            .expect("a state")
            .name
    };
    let mut sims = model_exchange_points();
    let mut wrong = Vec::new();
    for v in VARIABLES
        .iter()
        .filter(|v| v.causality == Causality::Output)
    {
        let moved: BTreeSet<&str> = STATES
            .iter()
            .filter(|&&k| sims.iter_mut().any(|sim| moves(sim, v, k)))
            .map(|&k| name(k))
            .collect();
        let declared: BTreeSet<&str> = v
            .depends_on
            .iter()
            .copied()
            .filter(|d| STATES.iter().any(|&s| name(s) == *d))
            .collect();
        if moved != declared {
            wrong.push(format!(
                "{}: moves with {moved:?}, declared {declared:?}",
                v.name
            ));
        }
    }
    assert!(
        wrong.is_empty(),
        "states the outputs move with:\n{}",
        wrong.join("\n")
    );
}

/// The inputs of the inputs mode, which Model Exchange's importer sets with the states held.
const SHAFT_INPUTS: [u32; 3] = [vr::theta_M, vr::omega_M, vr::alpha_M];

/// Model Exchange's points: in each coupling and region at the start with the time set on,
/// and stepped on (non-zero integrals), the statistics' window open.
fn model_exchange_points() -> Vec<Simulation> {
    let mut sims = Vec::new();
    for excitation in COUPLINGS {
        for gap_start in GAP_STARTS {
            let mut set = starting_at(excitation, gap_start);
            let mut stepped = starting_at(excitation, gap_start);
            set.set_time(0.01).expect("a finite shaft");
            stepped.step_to(0.01).expect("a step");
            sims.extend([set, stepped]);
        }
    }
    sims
}

/// Whether output v changes when a known (a state, or one of SHAFT_INPUTS) is moved by a small
/// step relative to its value, as fmi2SetContinuousStates or fmi2SetReal do.
fn moves(sim: &mut Simulation, v: &Variable, known: u32) -> bool {
    let read = |sim: &Simulation| match v.kind {
        Kind::Real => sim.real_output(v.vr).map(f64::to_bits),
        _ => sim.integer_output(v.vr).map(|i| i as u64),
    };
    let step = |value: f64| 1e-6 * value.abs().max(1e-6);
    let (x, shaft, before) = (sim.continuous_states(), sim.shaft(), read(sim));
    if let Some(k) = STATES.iter().position(|&s| s == known) {
        let mut moved = x;
        moved[k] += step(x[k]);
        sim.set_continuous_states(&moved);
    } else {
        let mut moved = shaft;
        match known {
            vr::theta_M => moved.theta += step(shaft.theta),
            vr::omega_M => moved.omega += step(shaft.omega),
            _ => moved.alpha += step(shaft.alpha),
        }
        sim.set_shaft_inputs(moved);
    }
    let after = read(sim);
    if STATES.contains(&known) {
        sim.set_continuous_states(&x);
    } else {
        sim.set_shaft_inputs(shaft);
    }
    assert_eq!(read(sim), before, "{}: known {known} set back", v.name);
    before != after
}

/// Each parameter's range as docs/MODEL.md §4 and §5 give it, written out here: the contract's
/// ranges must refuse a value just outside and admit the bound itself where it is inclusive.
const RANGES: [(&str, f64, Option<f64>, &str); 12] = [
    // (name, a value outside, the inclusive bound or None, the range the message states)
    ("I_L", 0.0, None, "I_L > 0"),
    ("r_L", -0.037, None, "r_L > 0"),
    ("r_M", 0.0, None, "r_M > 0"),
    ("K_star", -3e6, None, "K_star > 0"),
    ("alpha", 0.9, Some(1.0), "alpha >= 1"),
    ("epsilon", -1e-9, Some(0.0), "epsilon >= 0"),
    ("G", 0.0, None, "G > 0"),
    ("C_LM", -1.0, Some(0.0), "C_LM >= 0"),
    ("C", -1e-3, Some(0.0), "C >= 0"),
    ("f_exc", 0.0, None, "f_exc > 0"),
    ("I_M", 0.0, None, "I_M > 0"),
    ("G", f64::INFINITY, None, "G > 0 (finite)"),
];

fn real_vr(name: &str) -> u32 {
    VARIABLES
        .iter()
        .find(|v| v.name == name && v.kind == Kind::Real)
        .unwrap()
        .vr
}

#[test]
fn parameters_outside_their_range_are_refused_naming_it() {
    for (name, outside, bound, range) in RANGES {
        let mut values = Values::start(VARIABLES);
        values.set_real(real_vr(name), outside);
        let Err(e) = Simulation::new(&values, 0.0, 0.0, 1e-6, Carry::Asked) else {
            panic!("{name} = {outside} accepted");
        };
        let message = e.message;
        let value = format!("{outside:e}");
        for words in [name, &value, range] {
            assert!(message.contains(words), "{name}: {message}");
        }
        if let Some(b) = bound {
            values.set_real(real_vr(name), b);
            assert!(
                Simulation::new(&values, 0.0, 0.0, 1e-6, Carry::Asked).is_ok(),
                "{name} = {b} refused"
            );
        }
    }
    // The smallest positive double is inside I_L > 0.
    let mut values = Values::start(VARIABLES);
    values.set_real(vr::I_L, f64::from_bits(1));
    assert!(Simulation::new(&values, 0.0, 0.0, 1e-6, Carry::Asked).is_ok());
    for (name, value) in [("excitation", 3), ("solver", -1)] {
        let mut values = Values::start(VARIABLES);
        let vr = VARIABLES.iter().find(|v| v.name == name).unwrap().vr;
        values.set_integer(vr, value);
        let Err(e) = Simulation::new(&values, 0.0, 0.0, 1e-6, Carry::Asked) else {
            panic!("{name} = {value} accepted");
        };
        let expected = format!("parameter {name} = {value} is invalid: allowed 0 <= {name} <= 2");
        assert!(e.message.contains(&expected), "{}", e.message);
    }
}

/// The model description carries each range: inclusive bounds as min/max, an exclusive one
/// as the nearest double inside, and the statement at the end of the description.
#[test]
fn the_model_description_states_every_range() {
    let xml = gear_rattle::contract::MODEL_DESCRIPTION_XML;
    let element = |name: &str| {
        let start = xml.find(&format!("name=\"{name}\"")).unwrap();
        let end = start + xml[start..].find("</ScalarVariable>").unwrap();
        &xml[start..end]
    };
    for (name, _, bound, range) in &RANGES[..11] {
        let e = element(name);
        let min = match bound {
            Some(b) => format!("min=\"{b:?}\""),
            None => "min=\"5e-324\"".to_string(),
        };
        assert!(e.contains(&min), "{name}: {e}");
        let escaped = range.replace('<', "&lt;").replace('>', "&gt;");
        assert!(e.contains(&format!("(range: {escaped})\"")), "{name}: {e}");
    }
    assert!(!element("B").contains("min="));
}

#[test]
fn parameters_md_is_generated_from_the_contract() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/PARAMETERS.md");
    let on_disk = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        on_disk == gear_rattle::contract::parameters_markdown(),
        "docs/PARAMETERS.md is not the contract's tables: run `make docs-parameters`"
    );
}
