//! `cargo run --release --example free_flight_bound`: what leaving the gears in free flight out
//! of the coupled box's numerical step could save (docs/DECISIONS.md, D54). 2 s of B1 (40 °C),
//! B2 (−10 °C) and R1 (the run-down) at rtol 1e-6 with communication points every 0.1 ms, as
//! docs/GEARBOX.md §11's bench steps them, twice: as the box steps them, and with each gear's
//! ξ, ξ' weighted 0 in the error norm while it is in flight (the weights set again at every
//! communication point and at every contact onset, where the call stops). The steps the second
//! run saves are what a closed-form flight can save in steps; the share of gear-time in flight
//! bounds what it can save in right-hand-side work.
#![allow(non_snake_case)]

use std::time::Instant;

use gear_rattle::gearbox::{Drive, Gearbox, GearboxParams, xi, xi_dot};
use gear_rattle::integrator::{Solver, Stats};
use gear_rattle::physics::{Engine, Region};

struct Run {
    stats: Stats,
    seconds: f64,
    /// The share of gear-time in flight, sampled at the communication points.
    in_flight: f64,
}

fn impacts(sys: &Gearbox) -> u64 {
    sys.gears
        .iter()
        .map(|g| g.impacts.count.iter().sum::<u64>())
        .sum()
}

fn run(p: &GearboxParams, flight_out_of_norm: bool) -> Run {
    let (mut sys, mut y) = Gearbox::start(p, Drive::Engine(Engine::new(&p.engine))).unwrap();
    let tol = sys.tolerance(1e-6);
    let mut solver = Solver::new(tol);
    solver.interpolate_ends = true;
    let n = sys.n_gears();
    let (mut t, dt) = (0.0, 1e-4);
    let mut in_flight = 0.0;
    let start = Instant::now();
    for k in 1..=20_000 {
        let t_end = k as f64 * dt;
        loop {
            if flight_out_of_norm {
                let weights = solver.tolerance_mut();
                for (i, gear) in sys.gears[..n].iter().enumerate() {
                    let free = gear.region == Region::Gap;
                    for c in [xi(i), xi_dot(i)] {
                        weights.atol[c] = if free { f64::INFINITY } else { tol.atol[c] };
                    }
                }
            }
            let stopped = solver
                .advance_until(&mut sys, &mut t, &mut y, t_end, impacts)
                .unwrap_or_else(|e| panic!("{e}"));
            if !stopped {
                t = t_end;
                break;
            }
        }
        let free = sys.gears[..n].iter().filter(|g| g.region == Region::Gap);
        in_flight += free.count() as f64 / n as f64;
    }
    Run {
        stats: solver.stats,
        seconds: start.elapsed().as_secs_f64(),
        in_flight: in_flight / 20_000.0,
    }
}

fn main() {
    let default = GearboxParams::default_box();
    let mut rundown = default.clone();
    rundown.engine.rpm_rate = -150.0;
    let cold = GearboxParams {
        T_oil: -10.0,
        ..default.clone()
    };
    for (scene, p) in [("B1", default), ("B2", cold), ("R1", rundown)] {
        for (label, out) in [("as stepped", false), ("flight out of the norm", true)] {
            let r = run(&p, out);
            let s = r.stats;
            println!(
                "{scene} {label}: {} steps, {} rejected, {} right-hand sides, {} edges, {:.3} s; \
                 gears in flight {:.0} % of the gear-time",
                s.accepted,
                s.rejected,
                s.rhs_evals,
                s.edges,
                r.seconds,
                100.0 * r.in_flight
            );
        }
    }
}
