//! Energy balance of MODEL.md §3 with C = C_LM = 0 (and B = 0): ½ I_L ω_L² + V(ξ) minus the
//! work fed in by the main shaft stays constant. V is integrated here from MODEL.md's
//! contact law (tests/common), independently of the crate.
#![allow(non_snake_case)]

mod common;

use common::{Paper, V};
use gear_rattle::integrator::Solver;
use gear_rattle::physics::{Dynamics, Excitation, GearParams, Sine};
use gear_rattle::rattle::{self, Rattle, W_SHAFT, XI, XI_DOT};

#[test]
fn energy_is_conserved_without_dissipation_over_one_second_of_s1() {
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
    let excitation = Excitation::Sine(Sine::new(300.0, 30.0, 0.0));
    let mut rattle = Rattle::new(Dynamics::new(params), excitation, 0.5 * params.G);
    let mut solver = Solver::new(rattle.tolerance(1e-12));
    let (mut t, mut y) = (0.0, [0.0; rattle::N]);
    y[XI] = 0.5 * params.G;
    let energy = |t: f64, y: &[f64; rattle::N]| {
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
    let impacts = rattle.impacts.count;
    assert!(
        impacts[0] > 50 && impacts[1] > 50,
        "it rattles: {impacts:?}"
    );
    assert!(
        drift <= 1e-9 * scale,
        "energy drift {drift:e} J against a kinetic energy scale {scale:e} J ({:e} relative)",
        drift / scale
    );
}
