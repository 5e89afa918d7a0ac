//! What each group of quadratures costs a step (a benchmark, ignored by `cargo test`; it
//! prints its figures and asserts only that the trajectories are the same bits):
//!
//!     cargo test --release --test extras_cost -- --ignored --nocapture
//!
//! S1 in sine mode over 1 s at rtol 1e-5, served at communication points every 0.1 ms as the
//! FMU's co-simulation serves them (ends interpolated in natural steps), with the state ξ, ξ'
//! alone (N = 2), with the energies and the shaft's work (N = 5, a run without statistics) and
//! with the window's integrals too (N = 8): one run of each in turn, the median over the
//! rounds of the wall time per run. The peak search is not in these runs (no window opens).

use gear_rattle::integrator::Solver;
use gear_rattle::physics::{Dynamics, Excitation, GearParams, Sine};
use gear_rattle::rattle::{self, KinematicRattle, XI, XI_DOT};
use std::time::Instant;

const ROUNDS: usize = 61;

/// One run: its wall time, ξ and ξ' at its end (bits) and its accepted steps.
fn run<const N: usize>() -> (f64, [u64; 2], u64) {
    let p = GearParams::paper();
    let excitation = Excitation::Sine(Sine::new(300.0, 30.0, 0.0));
    let mut sys = KinematicRattle::<N>::new(Dynamics::new(p), excitation, 0.5 * p.G);
    let mut solver = Solver::new(sys.tolerance(1e-5));
    solver.interpolate_ends = true;
    let (mut t, mut y) = (0.0, [0.0; N]);
    y[XI] = 0.5 * p.G;
    let start = Instant::now();
    for k in 1..=10_000 {
        solver
            .advance(&mut sys, &mut t, &mut y, k as f64 * 1e-4)
            .unwrap();
    }
    let end = [y[XI].to_bits(), y[XI_DOT].to_bits()];
    (start.elapsed().as_secs_f64(), end, solver.stats.accepted)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

#[test]
#[ignore = "a benchmark: prints what each group of quadratures costs"]
fn what_each_group_of_quadratures_costs() {
    let mut times = [vec![], vec![], vec![]];
    let mut ends = vec![];
    for _ in 0..ROUNDS {
        for (k, (time, end, steps)) in [
            run::<{ rattle::E_CONTACT }>(),
            run::<{ rattle::N_LEAN }>(),
            run::<{ rattle::N }>(),
        ]
        .into_iter()
        .enumerate()
        {
            times[k].push(time);
            ends.push((end, steps));
        }
    }
    assert!(
        ends.iter().all(|e| *e == ends[0]),
        "the trajectories differ"
    );
    let [bare, energies, all] = times.map(median);
    println!(
        "S1 1 s, rtol 1e-5, 0.1 ms points, {} steps; median of {ROUNDS} rounds:",
        ends[0].1
    );
    println!("  xi, xi' alone (N = 2):          {:.3} ms", bare * 1e3);
    println!(
        "  + energies and work (N = 5):    {:.3} ms ({:+.1} %)",
        energies * 1e3,
        100.0 * (energies / bare - 1.0)
    );
    println!(
        "  + the window's integrals (N = 8): {:.3} ms ({:+.1} % more)",
        all * 1e3,
        100.0 * (all / energies - 1.0)
    );
}
