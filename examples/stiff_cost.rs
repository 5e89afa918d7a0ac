//! `cargo run --release --example stiff_cost [S1|S1-IL|S1-CLM [rtol]]`: the integrator's cost on the
//! stiff pairs of the stress suite against S1 (docs/MODEL.md §5: 30 Hz, 300 rad/s² RMS, 0.2 s),
//! called directly as the benchmark's "GearRattle (direct)" does (`Solver::advance` to each
//! 1 ms point, `interpolate_ends`): S1, S1-IL (I_L / 1e4) and S1-CLM (C_LM × 1000), at rtol
//! 1e-6 and 1e-9, the best wall-clock time of 15 runs (on a shared machine, compare runs of
//! one call only) and the solver's counters. With a scene's name (and an rtol, 1e-6 by
//! default): where its steps go, per millisecond (the region at its end, steps, Radau IIA's share, rejections, right-hand
//! sides, Jacobians, LU decompositions, edges, the step proposed next).
#![allow(non_snake_case)]

use std::time::Instant;

use gear_rattle::integrator::{Solver, Stats};
use gear_rattle::physics::{Dynamics, Excitation, GearParams, Sine};
use gear_rattle::rattle::{N, Rattle, XI};

/// 0.2 s of S1 with the parameters `p` at `rtol`, from ξ = G/2 at rest; the per-millisecond
/// profile printed if `profile`. Returns the wall-clock time and the counters.
fn run(p: GearParams, rtol: f64, profile: bool) -> (f64, Stats) {
    let start = Instant::now();
    let sine = Excitation::Sine(Sine::new(300.0, 30.0, 0.0));
    let mut rattle = Rattle::new(Dynamics::new(p), sine, 0.5 * p.G);
    let mut solver = Solver::new(rattle.tolerance(rtol));
    solver.interpolate_ends = true;
    let (mut t, mut y) = (0.0, [0.0; N]);
    y[XI] = 0.5 * p.G;
    let mut last = solver.stats;
    for k in 1..=200 {
        solver
            .advance(&mut rattle, &mut t, &mut y, k as f64 * 1e-3)
            .expect("the run reaches its end");
        if profile {
            let s = solver.stats;
            println!(
                "{k:4} ms {:>12} steps {:3} implicit {:3} rejected {:3} rhs {:4} jacobians {:3} \
                 LU {:3} edges {:2} h {:.2e} xi/G {:.3}",
                format!("{:?}", rattle.region),
                s.accepted - last.accepted,
                s.implicit_steps - last.implicit_steps,
                s.rejected - last.rejected,
                s.rhs_evals - last.rhs_evals,
                s.jacobians - last.jacobians,
                s.decompositions - last.decompositions,
                s.edges - last.edges,
                solver.proposed_step(),
                y[XI] / p.G
            );
            last = s;
        }
    }
    (start.elapsed().as_secs_f64(), solver.stats)
}

fn main() {
    let paper = GearParams::paper();
    let scenes = [
        ("S1", paper),
        (
            "S1-IL",
            GearParams {
                I_L: paper.I_L / 1e4,
                ..paper
            },
        ),
        (
            "S1-CLM",
            GearParams {
                C_LM: paper.C_LM * 1000.0,
                ..paper
            },
        ),
    ];
    if let Some(name) = std::env::args().nth(1) {
        let (_, p) = scenes
            .iter()
            .find(|(n, _)| *n == name)
            .expect("a scene: S1, S1-IL or S1-CLM");
        let rtol = std::env::args()
            .nth(2)
            .map_or(1e-6, |r| r.parse().expect("an rtol"));
        run(*p, rtol, true);
        return;
    }
    for rtol in [1e-6, 1e-9] {
        let mut s1 = f64::NAN;
        for (name, p) in scenes {
            let best = (0..15)
                .map(|_| run(p, rtol, false).0)
                .fold(f64::INFINITY, f64::min);
            if name == "S1" {
                s1 = best;
            }
            let s = run(p, rtol, false).1;
            println!(
                "rtol {rtol:e} {name}: {:.0} µs ({:.2}× S1); RHS {}, steps {} + {} rejected \
                 ({} by Radau IIA), Jacobians {}, LU {}, edges {}",
                best * 1e6,
                best / s1,
                s.rhs_evals,
                s.accepted,
                s.rejected,
                s.implicit_steps,
                s.jacobians,
                s.decompositions,
                s.edges
            );
        }
    }
}
