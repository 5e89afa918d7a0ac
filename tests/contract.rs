//! The contract (modelDescription/GearRattle.toml) against what the simulation computes:
//! every output is computed in every coupling, each output's derivative is given exactly
//! where the contract says so, and each Real output moves with an input at once exactly
//! where its `depends_on` (the model description's ModelStructure) says so.

use fmi2_shell::values::Values;
use gear_rattle::contract::{Causality, Kind, VARIABLES, Variable, vr};
use gear_rattle::instance::Simulation;

/// A simulation in contact on F+ and moving (so that the contact's stiffness and damping
/// both act), with the main shaft driven by `excitation`.
fn in_contact(excitation: i64) -> Simulation {
    let mut values = Values::start(gear_rattle::contract::VARIABLES);
    values.set_integer(vr::excitation, excitation);
    values.set_real(vr::gap_start, -0.2);
    values.set_real(vr::xi_dot_start, 0.01);
    values.set_real(vr::omega_M, 3.0);
    values.set_real(vr::alpha_M, 40.0);
    values.set_real(vr::tau_in, 0.5);
    values.set_real(vr::stats_from, 0.0);
    Simulation::new(&values, 0.0, 0.0, 1e-6).expect("valid parameters")
}

fn outputs(kind: Kind) -> impl Iterator<Item = &'static Variable> {
    VARIABLES
        .iter()
        .filter(move |v| v.causality == Causality::Output && v.kind == kind)
}

const COUPLINGS: [i64; 3] = [0, 1, 2];

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

/// ∂output/∂input is non-zero, in the coupling that uses the input, exactly for the inputs
/// of `depends_on` (θ_M, ω_M, α_M in the inputs mode; τ_in in the torque mode).
#[test]
fn partials_are_non_zero_exactly_where_depends_on_says() {
    let (inputs_mode, torque_mode) = (in_contact(0), in_contact(2));
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
            })
            .map(|u| u.name)
            .collect();
        if PIECEWISE_CONSTANT.contains(&v.vr) {
            assert!(moved.is_empty() && !v.depends_on.is_empty(), "{}", v.name);
            continue;
        }
        let mut declared = v.depends_on.to_vec();
        declared.sort_by_key(|name| inputs.iter().position(|u| u.name == *name));
        assert_eq!(
            moved, declared,
            "{}: inputs it moves with, against depends_on",
            v.name
        );
    }
}
