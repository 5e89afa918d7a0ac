//! Energy balance of docs/MODEL.md §3 with C = C_LM = 0 (and B = 0): ½ I_L ω_L² + V(ξ) minus the
//! work fed in by the main shaft stays constant (in torque mode, with the shaft's kinetic
//! energy, minus the work of the drivetrain's torque). V is integrated here from docs/MODEL.md's
//! contact law (tests/common), independently of the crate.
#![allow(non_snake_case)]

mod common;

use common::{Paper, V};
use gear_rattle::integrator::Solver;
use gear_rattle::physics::{Dynamics, Excitation, GearParams, Sine};
use gear_rattle::rattle::{self, KinematicRattle, W_SHAFT, XI, XI_DOT};

/// The paper's gear pair without its dampings, for the crate and for docs/MODEL.md written out.
fn lossless() -> (GearParams, Paper) {
    let params = GearParams {
        C_LM: 0.0,
        C: 0.0,
        ..GearParams::paper()
    };
    let paper = Paper {
        K_star: params.K_star,
        alpha: params.alpha,
        epsilon: params.epsilon,
        G: params.G,
        C_LM: 0.0,
    };
    (params, paper)
}

/// With the statistics window's quadratures and without them (the state of a run that asks
/// for no window): the shaft's work is carried the same.
#[test]
fn energy_is_conserved_without_dissipation_over_one_second_of_s1() {
    conserved_over_one_second_of_s1::<{ rattle::N }>();
    conserved_over_one_second_of_s1::<{ rattle::N_LEAN }>();
}

fn conserved_over_one_second_of_s1<const N: usize>() {
    let (params, paper) = lossless();
    let excitation = Excitation::Sine(Sine::new(300.0, 30.0, 0.0));
    let mut rattle = KinematicRattle::<N>::new(Dynamics::new(params), excitation, 0.5 * params.G);
    let mut solver = Solver::new(rattle.tolerance(1e-12));
    let (mut t, mut y) = (0.0, [0.0; N]);
    y[XI] = 0.5 * params.G;
    let energy = |t: f64, y: &[f64; N]| {
        let omega_M = excitation.at(t).omega;
        let omega_L = (y[XI_DOT] + params.r_M * omega_M) / params.r_L;
        let kinetic = 0.5 * params.I_L * omega_L * omega_L;
        (kinetic + V(&paper, y[XI]) - y[W_SHAFT], kinetic)
    };
    let (e0, _) = energy(t, &y);
    let (mut drift, mut scale) = (0.0f64, 0.0f64);
    for k in 1..=200 {
        solver
            .advance(&mut rattle, &mut t, &mut y, k as f64 * 0.005)
            .unwrap();
        let (e, kinetic) = energy(t, &y);
        drift = drift.max((e - e0).abs());
        scale = scale.max(kinetic);
    }
    assert_conserved(rattle.impacts.count, 50, drift, scale);
}

/// Torque mode (src/rattle/torque.rs): the main shaft an inertia I_M driven by τ_in, pushed
/// back by the contact (I_M ω_M' = τ_in + r_M F). With C = C_LM = 0 and B = 0,
/// ½ I_L ω_L² + ½ I_M ω_M² + V(ξ) − ∫ τ_in ω_M dt stays constant. τ_in is held over each
/// 1 ms step (an S1-like sine torque, I_M √2 300 rad/s² sin(2π 30 t), sampled), so its work
/// is Σ τ_k (θ_M(t_k+1) − θ_M(t_k)) exactly, from the shaft's angle alone.
#[test]
fn energy_is_conserved_in_torque_mode_without_dissipation() {
    use gear_rattle::physics::{MainShaft, TorqueRamp};
    use gear_rattle::rattle::torque::{self, OMEGA_M, THETA_M, TorqueRattle};

    let (params, paper) = lossless();
    let I_M = 0.008;
    let (amplitude, w) = (I_M * 2f64.sqrt() * 300.0, 2.0 * std::f64::consts::PI * 30.0);
    let torque_at = |t: f64| amplitude * (w * t).sin();
    let ramp = |t: f64| TorqueRamp {
        t0: t,
        tau0: torque_at(t),
        rate: 0.0,
    };
    let mut sys = TorqueRattle::new(
        Dynamics::new(params),
        MainShaft { I_M },
        ramp(0.0),
        0.5 * params.G,
    );
    let mut solver = Solver::new(sys.tolerance(1e-12));
    let (mut t, mut y) = (0.0, [0.0; torque::N]);
    y[torque::XI] = 0.5 * params.G;
    // zero-mean shaft speed, as the bench's −A/w cos(wt)
    y[OMEGA_M] = -amplitude / I_M / w;
    let energy = |y: &[f64; torque::N]| {
        let omega_L = (y[torque::XI_DOT] + params.r_M * y[OMEGA_M]) / params.r_L;
        let kinetic = 0.5 * params.I_L * omega_L * omega_L + 0.5 * I_M * y[OMEGA_M] * y[OMEGA_M];
        (kinetic + V(&paper, y[torque::XI]), kinetic)
    };
    let (e0, _) = energy(&y);
    let (mut work_in, mut drift, mut scale) = (0.0, 0.0f64, 0.0f64);
    for k in 1..=500 {
        let (tau, theta_before) = (sys.torque.tau0, y[THETA_M]);
        solver
            .advance(&mut sys, &mut t, &mut y, k as f64 * 0.001)
            .unwrap();
        work_in += tau * (y[THETA_M] - theta_before);
        let (e, kinetic) = energy(&y);
        drift = drift.max((e - work_in - e0).abs());
        scale = scale.max(kinetic);
        sys.torque = ramp(t);
        solver.invalidate();
    }
    assert_conserved(sys.impacts.count, 20, drift, scale);
    eprintln!(
        "torque mode: impacts {:?}, drift {:e} relative",
        sys.impacts.count,
        drift / scale
    );
}

/// The run rattled (more than `min` impacts on each flank) and its energy balance drifted by
/// at most 1e-9 of its kinetic energy scale.
fn assert_conserved(impacts: [u64; 2], min: u64, drift: f64, scale: f64) {
    assert!(
        impacts[0] > min && impacts[1] > min,
        "it rattles: {impacts:?}"
    );
    assert!(
        drift <= 1e-9 * scale,
        "energy drift {drift:e} J against a kinetic energy scale {scale:e} J ({:e} relative)",
        drift / scale
    );
}
