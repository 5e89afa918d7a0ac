//! `cargo run --release --example gearbox_cost`: the cost of 2 s of docs/GEARBOX.md's default box
//! (B1, 40 °C) and of the same box at −10 °C (B2), rtol 1e-6 (GearRattle's default), with
//! each gear's impacts per second over 0.5-2 s and the damper's stage (docs/GEARBOX.md §8's
//! figures to compare with); then the cost of one right-hand side for 1..8 gears, to show
//! that a box pays for the gears it has, not for the slots. Wall-clock times (the best of
//! three runs for the box, of five for the right-hand side): on a shared machine, compare
//! runs of one call only.
#![allow(non_snake_case)]

use std::time::Instant;

use gear_rattle::gearbox::{Drive, Gearbox, GearboxParams, N, PHI, xi, xi_dot};
use gear_rattle::integrator::{Solver, Stats, System};
use gear_rattle::physics::{Engine, Stage};

struct Run {
    seconds: f64,
    stats: Stats,
    rates: Vec<f64>,
    main_share: f64,
    max_twist: f64,
}

/// 2 s of `p` from docs/GEARBOX.md §6's start, sampled every 0.1 ms from 0.5 s.
fn run(p: &GearboxParams) -> Run {
    let (mut sys, mut y) = Gearbox::start(p, Drive::Engine(Engine::new(&p.engine))).unwrap();
    let mut solver = Solver::new(sys.tolerance(1e-6));
    solver.interpolate_ends = true;
    let count = |sys: &Gearbox| -> Vec<u64> {
        sys.gears[..sys.n_gears()]
            .iter()
            .map(|g| g.impacts.count[0] + g.impacts.count[1])
            .collect()
    };
    let (mut t, dt) = (0.0, 1e-4);
    let mut at_half = vec![];
    let (mut main, mut samples, mut max_twist) = (0u64, 0u64, 0.0f64);
    let start = Instant::now();
    for k in 1..=20_000 {
        solver
            .advance(&mut sys, &mut t, &mut y, k as f64 * dt)
            .unwrap_or_else(|e| panic!("{e}"));
        if k == 5_000 {
            at_half = count(&sys);
        } else if k > 5_000 {
            samples += 1;
            main += u64::from(sys.stage != Stage::PreDamper);
            max_twist = max_twist.max(y[PHI].abs());
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    let rates = count(&sys)
        .iter()
        .zip(&at_half)
        .map(|(b, a)| (b - a) as f64 / 1.5)
        .collect();
    Run {
        seconds,
        stats: solver.stats,
        rates,
        main_share: main as f64 / samples as f64,
        max_twist,
    }
}

fn best_of_three(p: &GearboxParams) -> Run {
    let mut best = run(p);
    for _ in 0..2 {
        let r = run(p);
        if r.seconds < best.seconds {
            best = r;
        }
    }
    best
}

fn main() {
    for (scene, T_oil) in [("B1", 40.0), ("B2", -10.0)] {
        let p = GearboxParams {
            T_oil,
            ..GearboxParams::default_box()
        };
        let r = best_of_three(&p);
        println!(
            "{scene} ({T_oil} °C): 2 s in {:.3} s CPU-wall; impacts/s over 0.5-2 s per gear {:.0?}; \
             main stage {:.0} % of the time, twist up to {:.2}°",
            r.seconds,
            r.rates,
            100.0 * r.main_share,
            r.max_twist.to_degrees()
        );
        println!("    {:?}", r.stats);
    }
    // The right-hand side alone for 1..8 gears (the default gears repeated), in contact.
    for n in 1..=8 {
        let mut p = GearboxParams::default_box();
        p.gears = (0..n).map(|i| p.gears[i % 5]).collect();
        let mut y = [0.0; N];
        for i in 0..n {
            (y[xi(i)], y[xi_dot(i)]) = (-2e-6 - 1e-8 * i as f64, 0.01);
        }
        let sys = Gearbox::new(&p, Drive::Engine(Engine::new(&p.engine)), &y);
        let calls = 1_000_000;
        let mut acc = 0.0;
        let mut ns = f64::INFINITY;
        for _ in 0..5 {
            let start = Instant::now();
            for k in 0..calls {
                let t = k as f64 * 1e-9;
                acc += std::hint::black_box(&sys).rhs(t, std::hint::black_box(&y))[1];
            }
            ns = ns.min(start.elapsed().as_secs_f64() / calls as f64 * 1e9);
        }
        println!("{n} gear(s): {ns:.0} ns per right-hand side ({acc:.1e})");
    }
}
