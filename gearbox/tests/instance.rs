//! The gearbox FMU's instance through the shell's Rust API (the C exports' logic without
//! C): the refusals of invalid boxes, every output of the contract computed, bit-exact replay
//! from a saved and serialized FMU state, and the statistics window's lean start.

use fmi2_shell::fmu_state::{deserialize, serialize};
use fmi2_shell::{FmiState, Fmu, Interface, Slave};
use gearbox_rattle::contract::{Causality, Kind, VARIABLES, vr};
use gearbox_rattle::instance::Instance;

/// Runs `test` on a thread of 8 MB: the unoptimised frames of the windowed gearbox's solver
/// (63 states, Radau IIA's matrices) take more than the test harness's 2 MB; an optimised
/// build runs these tests in 1 MB.
fn with_stack(test: impl FnOnce() + Send + 'static) {
    std::thread::Builder::new()
        .stack_size(8 << 20)
        .spawn(test)
        .unwrap()
        .join()
        .unwrap();
}

fn initialised(reals: &[(u32, f64)]) -> Fmu<Instance> {
    let mut i = Fmu::<Instance>::new(false, Interface::CoSimulation);
    i.setup_experiment(None, 0.0).unwrap();
    i.enter_initialization_mode().unwrap();
    for &(vr, value) in reals {
        i.set_real(&[vr], &[value]).unwrap();
    }
    i.exit_initialization_mode().unwrap();
    i
}

fn run(i: &mut Fmu<Instance>, from: f64, to: f64, h: f64) {
    let steps = ((to - from) / h).round() as usize;
    for k in 0..steps {
        i.do_step(from + k as f64 * h, h).unwrap();
    }
}

fn real(i: &mut Fmu<Instance>, vr: u32) -> f64 {
    let mut out = [0.0];
    i.slave.get_real(&[vr], &mut out).unwrap();
    out[0]
}

fn integer(i: &mut Fmu<Instance>, vr: u32) -> i32 {
    let mut out = [0];
    i.slave.get_integer(&[vr], &mut out).unwrap();
    out[0]
}

/// GEARBOX.md's rules between parameters (k_2 ≥ k_1, ν_100 < ν_40) are refused at
/// fmi2ExitInitializationMode with the parameter's name; the instance stays in
/// initialisation mode, where the value can be corrected.
#[test]
fn invalid_boxes_are_refused_by_name() {
    for (vr, value, name) in [(vr::k_2, 10.0, "k_2"), (vr::nu_100, 6e-5, "nu_100")] {
        let mut i = Fmu::<Instance>::new(false, Interface::CoSimulation);
        i.enter_initialization_mode().unwrap();
        i.set_real(&[vr], &[value]).unwrap();
        let message = i.exit_initialization_mode().unwrap_err().message;
        assert!(message.contains(name), "{message}");
        assert_eq!(i.state, FmiState::InitializationMode);
        i.set_real(&[vr], &[if name == "k_2" { 900.0 } else { 9.5e-6 }])
            .unwrap();
        i.exit_initialization_mode().unwrap();
    }
}

/// Every Real and Integer output and local of the contract is computed and finite, in the
/// window (0.1 s in) and for the three drives.
#[test]
fn every_output_is_computed() {
    with_stack(|| {
        for excitation in [0, 1, 2] {
            let mut i = Fmu::<Instance>::new(false, Interface::CoSimulation);
            i.enter_initialization_mode().unwrap();
            i.set_integer(&[vr::excitation], &[excitation]).unwrap();
            i.set_real(
                &[vr::stats_from, vr::omega_F, vr::omega_I],
                &[0.05, 84.0, 84.0],
            )
            .unwrap();
            i.exit_initialization_mode().unwrap();
            run(&mut i, 0.0, 0.1, 1e-3);
            for v in VARIABLES {
                if !matches!(v.causality, Causality::Output | Causality::Local) {
                    continue;
                }
                match v.kind {
                    Kind::Real => assert!(real(&mut i, v.vr).is_finite(), "{}", v.name),
                    _ => {
                        integer(&mut i, v.vr);
                    }
                }
            }
        }
    });
}

/// A state saved (and serialized) in the window's first part replays the next steps to the
/// last bit, across the window's opening too.
#[test]
fn saved_states_replay_bit_exactly() {
    with_stack(|| {
        let mut i = initialised(&[(vr::stats_from, 0.03)]);
        run(&mut i, 0.0, 0.02, 1e-3);
        let saved: Fmu<Instance> = deserialize(&serialize(&i)).unwrap();
        run(&mut i, 0.02, 0.06, 1e-3);
        let first = serialize(&i);
        let mut j = Fmu::<Instance>::new(false, Interface::CoSimulation);
        j.restore(&saved).unwrap();
        run(&mut j, 0.02, 0.06, 1e-3);
        assert_eq!(serialize(&j), first);
        assert!(real(&mut j, vr::gear::stat_window[0]) > 0.0);
    });
}

/// The gearbox steps without the window's quadratures until the window opens, and with
/// them from then on: up to the opening both runs are the same to the last bit.
#[test]
fn the_window_opens_on_the_way() {
    with_stack(|| {
        use gearbox_rattle::simulation::Run;
        let mut late = initialised(&[(vr::stats_from, 10.0)]);
        let mut early = initialised(&[(vr::stats_from, 0.02)]);
        run(&mut late, 0.0, 0.02, 1e-3);
        run(&mut early, 0.0, 0.02, 1e-3);
        let xi = |i: &mut Fmu<Instance>| real(i, vr::gear::xi[0]).to_bits();
        assert_eq!(xi(&mut late), xi(&mut early));
        run(&mut late, 0.02, 0.04, 1e-3);
        run(&mut early, 0.02, 0.04, 1e-3);
        let sim = |i: &Fmu<Instance>| i.slave.simulation().unwrap().run.clone();
        assert!(matches!(sim(&late), Run::Lean(_)));
        assert!(matches!(sim(&early), Run::Windowed(_)));
        assert_eq!(real(&mut late, vr::gear::stat_window[0]), 0.0);
        assert!((real(&mut early, vr::gear::stat_window[0]) - 0.02).abs() < 1e-12);
    });
}
