//! The gearbox FMU's instance through the shell's Rust API (the C exports' logic without
//! C): the refusals of invalid boxes, every output of the contract computed, bit-exact replay
//! from a saved and serialized FMU state, and the statistics window's lean start.

use fmi2_shell::fmu_state::{deserialize, serialize};
use fmi2_shell::{FmiState, Fmu, Interface, Slave};
use gear_rattle::instance::Journaled;
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

/// docs/GEARBOX.md's rules between parameters (k_2 ≥ k_1, ν_100 < ν_40) are refused at
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
/// last bit, across the window's opening too: the coupled box (the engine) and the gears
/// stepped apart (the input side imposed).
#[test]
fn saved_states_replay_bit_exactly() {
    with_stack(|| {
        for excitation in [1, 2] {
            let mut i = Fmu::<Instance>::new(false, Interface::CoSimulation);
            i.enter_initialization_mode().unwrap();
            i.set_integer(&[vr::excitation], &[excitation]).unwrap();
            i.set_real(&[vr::stats_from, vr::omega_I], &[0.0305, 84.0])
                .unwrap();
            i.exit_initialization_mode().unwrap();
            run(&mut i, 0.0, 0.02, 1e-3);
            let saved: Fmu<Instance> = deserialize(&serialize(&i)).unwrap();
            run(&mut i, 0.02, 0.06, 1e-3);
            let first = serialize(&i);
            let mut j = Fmu::<Instance>::new(false, Interface::CoSimulation);
            j.restore(&saved).unwrap();
            run(&mut j, 0.02, 0.06, 1e-3);
            assert_eq!(serialize(&j), first, "excitation {excitation}");
            assert!(real(&mut j, vr::gear::stat_window[0]) > 0.0);
        }
    });
}

/// The input side imposed (excitation 2), its motion a 27 Hz oscillation about 84 rad/s, new
/// every millisecond: the gears step apart. Steps that stop at the first impact of any gear
/// stop at one impact each (one gear's count up by one), and together count the impacts of
/// the plain run, gear by gear, and end where it does within the tolerance. A step that fails
/// leaves the simulation as it was.
#[test]
fn gears_stepped_apart_stop_at_each_impact() {
    use gear_rattle::physics::Shaft;
    use gearbox_rattle::simulation::{Run, Simulation};
    with_stack(|| {
        let mut values = fmi2_shell::values::Values::start(VARIABLES);
        values.set_integer(vr::excitation, 2);
        values.set_integer(vr::n_gears, 3);
        values.set_real(vr::omega_I, 84.0);
        let start = Simulation::new(&values, 0.0, 1e-8, false).unwrap();
        assert!(matches!(start.run, Run::Independent(_)));
        let w = 2.0 * std::f64::consts::PI * 26.7;
        let a = 600.0 / (w * w);
        let shaft = |t: f64| Shaft {
            theta: 84.0 * t + a * (w * t).sin(),
            omega: 84.0 + a * w * (w * t).cos(),
            alpha: -600.0 * (w * t).sin(),
        };
        let counts = |s: &Simulation| {
            s.gearbox()
                .0
                .gears
                .map(|g| g.impacts.count[0] + g.impacts.count[1])
        };
        let (mut plain, mut stopping) = (start.clone(), start);
        let mut stops = 0;
        for k in 0..100 {
            let (t, t_end) = (k as f64 * 1e-3, (k + 1) as f64 * 1e-3);
            plain.set_input_side(shaft(t));
            plain.step_until(t_end, false).unwrap();
            stopping.set_input_side(shaft(t));
            loop {
                let before = counts(&stopping);
                let reached = stopping.step_until(t_end, true).unwrap();
                let after = counts(&stopping);
                let new: u64 = after.iter().zip(&before).map(|(a, b)| a - b).sum();
                if reached < t_end {
                    assert_eq!(new, 1, "at {reached}");
                    stops += 1;
                } else {
                    assert!(new <= 1, "at {reached}");
                    stops += new;
                    break;
                }
            }
        }
        assert_eq!(counts(&stopping), counts(&plain));
        assert!(stops > 20, "{stops} impacts");
        // A step below the resolution of time fails and leaves every gear as it was.
        let before = plain.clone();
        let t = plain.t;
        assert!(plain.step_until(t + 4.0 * f64::EPSILON * t, false).is_err());
        assert!(plain == before);
        let (g, y) = (plain.gearbox(), stopping.gearbox().1);
        for i in 0..3 {
            let k = gear_rattle::gearbox::xi(i);
            let gap = g.0.gears[i].dynamics.params.G;
            assert!(
                (g.1[k] - y[k]).abs() < 1e-6 * gap,
                "gear {i}: {} {}",
                g.1[k],
                y[k]
            );
        }
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

/// The flywheel driven by inputs (excitation 0) that carry the built-in engine's exact
/// motion at each communication point follows the run driven by the engine itself
/// (excitation 1): within the step the inputs are extrapolated to second order, so the
/// twist agrees within 1e-4 φ_1 over 0.1 s (8e-6 φ_1 measured; before the chaotic rattle
/// has amplified anything). The torque on the flywheel is the damper's, reversed.
#[test]
fn inputs_drive_the_box_as_the_engine_does() {
    with_stack(|| {
        use gear_rattle::physics::{Engine, EngineParams};
        let engine = Engine::new(&EngineParams::idle());
        let h = 1e-4;
        let mut by_engine = initialised(&[]);
        let mut by_inputs = Fmu::<Instance>::new(false, Interface::CoSimulation);
        by_inputs.enter_initialization_mode().unwrap();
        by_inputs.set_integer(&[vr::excitation], &[0]).unwrap();
        let start = engine.steady_at(0.0).unwrap();
        let flywheel = [vr::theta_F, vr::omega_F, vr::alpha_F];
        by_inputs
            .set_real(&flywheel, &[start.theta, start.omega, start.alpha])
            .unwrap();
        by_inputs.exit_initialization_mode().unwrap();
        for k in 0..1000 {
            let t = k as f64 * h;
            let s = engine.steady_at(t).unwrap();
            by_inputs
                .set_real(&flywheel, &[s.theta, s.omega, s.alpha])
                .unwrap();
            by_inputs.do_step(t, h).unwrap();
            by_engine.do_step(t, h).unwrap();
        }
        let (a, b) = (real(&mut by_engine, vr::phi), real(&mut by_inputs, vr::phi));
        let phi_1 = real(&mut by_engine, vr::phi_1);
        assert!(
            (a - b).abs() < 1e-4 * phi_1,
            "phi {a} (engine) vs {b} (inputs)"
        );
        let tau = real(&mut by_inputs, vr::tau_F);
        assert_eq!(tau, -real(&mut by_inputs, vr::T_clutch));
        assert!(tau != 0.0);
    });
}

/// Corrupt bytes are refused by the envelope's checksum; a state made by hand with a valid
/// checksum is refused when the instance could not run (here: in a state of the other
/// interface).
#[test]
fn corrupt_or_inconsistent_states_are_refused() {
    with_stack(|| {
        let mut i = initialised(&[]);
        run(&mut i, 0.0, 0.002, 1e-3);
        let mut bytes = serialize(&i);
        bytes[20] ^= 1;
        let refused = deserialize::<Instance>(&bytes).unwrap_err().message;
        assert!(refused.contains("checksum"), "{refused}");
        let stepping = serialize(&i);
        let mut me = deserialize::<Instance>(&stepping).unwrap();
        me.state = FmiState::ContinuousTimeMode;
        let refused = deserialize::<Instance>(&serialize(&me))
            .unwrap_err()
            .message;
        assert!(
            refused.contains("CoSimulation instance in state ContinuousTimeMode"),
            "{refused}"
        );
    });
}

/// The window at 0.03 s and a master stepping 0.029 + 1e-3 (one ulp past it), or at two ulps
/// past that end: it opens within the resolution of time of the step's end, so it opens
/// there. The flywheel driven by inputs (the idle engine's motion), the engine (DOPRI5 and
/// Radau IIA) and the input side imposed (its gears stepped apart), with steps ended at each
/// impact too (FMI 3.0's early return): every step succeeds, and each gear's window and
/// quadratures equal those of the run whose window opens on the communication point, to
/// the last bit, with impacts counted in it.
#[test]
fn a_window_within_rounding_of_a_step_end_opens_there() {
    use gear_rattle::physics::{Engine, EngineParams, Shaft};
    use gearbox_rattle::simulation::Simulation;
    with_stack(|| {
        let ulps = |x: f64, n: i64| f64::from_bits((x.to_bits() as i64 + n) as u64);
        let t_end = 0.029 + 1e-3;
        let engine = Engine::new(&EngineParams::idle());
        let w = 2.0 * std::f64::consts::PI * 26.7;
        let input_side = |t: f64| Shaft {
            theta: 84.0 * t + 600.0 / (w * w) * (w * t).sin(),
            omega: 84.0 + 600.0 / w * (w * t).cos(),
            alpha: -600.0 * (w * t).sin(),
        };
        let run = |(excitation, solver): (i64, i64), stats_from: f64, at_impact: bool| {
            let mut values = fmi2_shell::values::Values::start(VARIABLES);
            values.set_integer(vr::excitation, excitation);
            values.set_integer(vr::solver, solver);
            values.set_integer(vr::n_gears, 3);
            values.set_real(vr::omega_I, 84.0);
            let flywheel = engine.steady_at(0.0).unwrap();
            for (vr, value) in [
                (vr::theta_F, flywheel.theta),
                (vr::omega_F, flywheel.omega),
                (vr::alpha_F, flywheel.alpha),
                (vr::stats_from, stats_from),
            ] {
                values.set_real(vr, value);
            }
            let mut sim = Simulation::new(&values, 0.0, 1e-6, false).unwrap();
            let points = (0..20).map(|k| k as f64 * 1e-3);
            for t in points.chain((0..40).map(|k| 0.02 + k as f64 * 1e-3)) {
                let h = 1e-3;
                // From the master's communication point, as the instance steps; each
                // drive takes its own inputs.
                sim.t = t;
                sim.set_flywheel(engine.steady_at(t).unwrap());
                sim.set_input_side(input_side(t));
                while sim.step_until(t + h, at_impact).unwrap() < t + h {}
            }
            (0..3)
                .map(|i| {
                    sim.window(i)
                        .map(|(window, q)| (*window, q.map(f64::to_bits)))
                })
                .collect::<Vec<_>>()
        };
        for case in [(0, 0), (1, 0), (1, 2), (2, 0)] {
            for at_impact in [false, true] {
                let on_the_point = run(case, t_end, at_impact);
                let impacts: u64 = on_the_point
                    .iter()
                    .map(|w| w.unwrap().0.flanks.iter().map(|f| f.impacts).sum::<u64>())
                    .sum();
                assert!(impacts > 0, "{case:?}");
                for from in [0.03, ulps(t_end, 2)] {
                    assert!(
                        run(case, from, at_impact) == on_the_point,
                        "{case:?} {from}"
                    );
                }
            }
        }
    });
}
