//! The contract (modelDescription/GearboxRattle.toml) against what the FMU computes: an
//! output that moves at once with an input (co-simulation's direct feedthrough), or with a
//! continuous state or an input in Model Exchange, names it in its `depends_on` (the model
//! description's ModelStructure); so does each state derivative.

use fmi2_shell::values::Values;
use fmi2_shell::{Continuous, Fmu, Interface, Slave};
use gear_rattle::physics::Shaft;
use gearbox_rattle::contract::{self, Causality, Kind, STATES, VARIABLES, Variable, vr};
use gearbox_rattle::instance::Instance;
use gearbox_rattle::simulation::{self, Simulation};

/// The variables whose dependencies the contract declares: the outputs, and in Model
/// Exchange the state derivatives.
fn dependents(derivatives: bool) -> impl Iterator<Item = &'static Variable> {
    VARIABLES.iter().filter(move |v| {
        v.causality == Causality::Output
            || (derivatives && v.causality == Causality::Local && v.name.starts_with("der("))
    })
}

fn read(sim: &Simulation, v: &Variable) -> u64 {
    match v.kind {
        Kind::Real => sim.real_output(v.vr).expect("computed").to_bits(),
        _ => sim.integer_output(v.vr).expect("computed") as u64,
    }
}

/// The shaft's motion with its angle (k = 0), speed (1) or acceleration (2) moved by 1e-3.
fn bumped(mut shaft: Shaft, k: usize) -> Shaft {
    match k {
        0 => shaft.theta += 1e-3,
        1 => shaft.omega += 1e-3,
        _ => shaft.alpha += 1e-3,
    }
    shaft
}

/// Every dependent that `change` moves declares `known`; returns how many moved.
fn moved_only_where_declared(
    sim: &Simulation,
    known: &str,
    change: impl Fn(&mut Simulation),
) -> usize {
    let mut moved = sim.clone();
    change(&mut moved);
    let mut count = 0;
    for v in dependents(sim.model_exchange) {
        if read(sim, v) != read(&moved, v) {
            count += 1;
            assert!(
                v.depends_on.contains(&known),
                "{} moves with {known}, which its depends_on {:?} does not name",
                v.name,
                v.depends_on
            );
        }
    }
    count
}

const INPUTS: [&str; 7] = [
    "theta_F",
    "omega_F",
    "alpha_F",
    "theta_I",
    "omega_I",
    "alpha_I",
    "omega_out",
];

fn input_vr(name: &str) -> u32 {
    VARIABLES
        .iter()
        .find(|v| v.name == name && v.causality == Causality::Input)
        .expect("an input")
        .vr
}

/// Co-simulation after 30 ms with every gear in contact at the start, for each drive: each
/// input set anew at a communication point moves only the outputs that name it.
#[test]
fn outputs_move_with_inputs_only_where_declared() {
    std::thread::Builder::new()
        .stack_size(8 << 20)
        .spawn(|| {
            for excitation in [0, 1, 2] {
                let mut i = Fmu::<Instance>::new(false, Interface::CoSimulation);
                i.enter_initialization_mode().unwrap();
                i.set_integer(&[vr::excitation], &[excitation]).unwrap();
                let gap_starts = vr::gear::gap_start.map(|_| -0.2);
                i.set_real(&vr::gear::gap_start, &gap_starts).unwrap();
                i.set_real(
                    &[vr::omega_F, vr::omega_I, vr::alpha_I],
                    &[84.0, 84.0, 300.0],
                )
                .unwrap();
                i.exit_initialization_mode().unwrap();
                for k in 0..30 {
                    i.do_step(k as f64 * 1e-3, 1e-3).unwrap();
                }
                for name in INPUTS {
                    let sim = i.slave.simulation().unwrap().clone();
                    let mut j = Fmu::<Instance>::new(false, Interface::CoSimulation);
                    j.restore(&i).unwrap();
                    let mut value = [0.0f64];
                    j.slave.get_real(&[input_vr(name)], &mut value).unwrap();
                    j.set_real(
                        &[input_vr(name)],
                        &[value[0] + 1e-3 * value[0].abs().max(1.0)],
                    )
                    .unwrap();
                    let after = j.slave.simulation().unwrap().clone();
                    let moved = moved_only_where_declared(&sim, name, |s| *s = after.clone());
                    // The inputs of the drive and the output shaft's speed move something.
                    let used = match excitation {
                        0 => ["theta_F", "omega_F", "omega_out"].contains(&name),
                        2 => ["theta_I", "omega_I", "alpha_I", "omega_out"].contains(&name),
                        _ => name == "omega_out",
                    };
                    assert_eq!(
                        moved > 0,
                        used,
                        "{name} ({excitation}) moved {moved} outputs"
                    );
                }
            }
        })
        .unwrap()
        .join()
        .unwrap();
}

/// Model Exchange at the start with every gear in contact, for each drive and the engine
/// ramped, before the statistics window opens and 1 ms into it: each continuous state, and
/// each input of the drive, moves only the outputs and derivatives that name it; the states
/// of the slots beyond the box's five gears are 0, and so are their derivatives.
#[test]
fn model_exchange_moves_only_where_declared() {
    let drives = [(0, 0.0), (1, 0.0), (1, -150.0), (2, 0.0)];
    for ((excitation, rpm_rate), stats_from) in drives.into_iter().zip([0.5, 0.0, 0.0, 0.0]) {
        let mut values = Values::start(VARIABLES);
        values.set_integer(vr::excitation, excitation);
        values.set_real(vr::rpm_rate, rpm_rate);
        values.set_real(vr::stats_from, stats_from);
        for g in vr::gear::gap_start {
            values.set_real(g, -0.2);
        }
        for (input, value) in [
            (vr::omega_F, 84.0),
            (vr::omega_I, 84.0),
            (vr::alpha_I, 300.0),
        ] {
            values.set_real(input, value);
        }
        let flywheel = simulation::flywheel_inputs(&values);
        let input_side = simulation::input_side_inputs(&values);
        let mut sim = Simulation::new(&values, 0.0, 1e-6, true).unwrap();
        sim.set_time(1e-3);
        sim.set_drive_inputs(flywheel, input_side);
        let x = sim.continuous_states();
        let dx = sim.derivatives();
        for (k, state) in STATES.iter().enumerate() {
            let name = contract::find(Kind::Real, *state).unwrap().name;
            if ["gear[6]", "gear[7]", "gear[8]"]
                .iter()
                .any(|g| name.starts_with(g))
            {
                assert_eq!(
                    (x[k], dx[k]),
                    (0.0, 0.0),
                    "{name} of a slot beyond the five gears"
                );
            }
        }
        for (k, state) in STATES.iter().enumerate() {
            let name = contract::find(Kind::Real, *state).unwrap().name;
            let _ = moved_only_where_declared(&sim, name, |s| {
                let mut moved = x;
                moved[k] += 1e-6 * x[k].abs().max(1e-6);
                s.set_continuous_states(&moved);
            });
        }
        for (k, motion) in ["theta", "omega", "alpha"].into_iter().enumerate() {
            let _ = moved_only_where_declared(&sim, &format!("{motion}_F"), |s| {
                s.set_drive_inputs(bumped(flywheel, k), input_side)
            });
            let _ = moved_only_where_declared(&sim, &format!("{motion}_I"), |s| {
                s.set_drive_inputs(flywheel, bumped(input_side, k))
            });
        }
        assert!(moved_only_where_declared(&sim, "omega_out", |s| s.set_output_speed(1.0)) > 0);
    }
}
