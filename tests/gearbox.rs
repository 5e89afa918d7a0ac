//! The gearbox of docs/GEARBOX.md against what can be known without it: the energy balance of §3
//! with every dissipation off (the potentials written out here, V_i from docs/MODEL.md's contact
//! law in tests/common), the damper's linear resonance, the right-hand side for one gear
//! against GearRattle's gear pair, and §8's regimes (every gear rattles at 40 °C, none at
//! −10 °C).
#![allow(non_snake_case)]

mod common;

use common::{Paper, V};
use gear_rattle::gearbox::{
    self, Drive, Gearbox, GearboxParams, PHI, PHI_DOT, State, W_FLYWHEEL, xi, xi_dot,
};
use gear_rattle::integrator::{Piecewise, Solver, System};
use gear_rattle::physics::{Dynamics, Engine, Excitation, Polynomial, Shaft};
use gear_rattle::rattle::{self, Rattle};

fn engine_driven(params: &GearboxParams) -> (Gearbox, State) {
    Gearbox::start(params, Drive::Engine(Engine::new(&params.engine))).unwrap()
}

/// The flywheel's θ_F, ω_F, α_F at t0 from the drivetrain, and the drive they make.
fn driven_by_inputs(t0: f64, [theta, omega, alpha]: [f64; 3]) -> (Shaft, Drive) {
    let at_t0 = Shaft {
        theta,
        omega,
        alpha,
    };
    (at_t0, Drive::Flywheel(Polynomial { t0, at_t0 }))
}

/// Runs from (sys, y) to t_end in chunks of `dt`, calling `each` after every chunk.
fn run(
    sys: &mut Gearbox,
    y: &mut State,
    rtol: f64,
    t_end: f64,
    dt: f64,
    mut each: impl FnMut(f64, &Gearbox, &State),
) -> Solver<{ gearbox::N }> {
    let mut solver = Solver::new(sys.tolerance(rtol));
    let mut t = 0.0;
    let chunks = (t_end / dt).round() as usize;
    for k in 1..=chunks {
        solver
            .advance(sys, &mut t, y, k as f64 * dt)
            .unwrap_or_else(|e| panic!("{e}"));
        each(t, sys, y);
    }
    solver
}

/// docs/GEARBOX.md §2's V_cl = ∫ T_k dφ, written out.
fn V_cl(p: &GearboxParams, phi: f64) -> f64 {
    let (k_1, k_2, phi_1) = (p.damper.k_1, p.damper.k_2, p.damper.phi_1);
    let a = phi.abs();
    if a <= phi_1 {
        0.5 * k_1 * a * a
    } else {
        0.5 * k_1 * phi_1 * phi_1 + k_1 * phi_1 * (a - phi_1) + 0.5 * k_2 * (a - phi_1).powi(2)
    }
}

/// docs/GEARBOX.md §3: with c_cl = H_1 = H_2 = 0, c_I = C_i = C_LM,i = B_i = 0,
/// ½ I_I ω_I² + Σ ½ I_L,i ω_L,i² + V_cl(φ) + Σ V_i(ξ_i) − ∫ T_cl ω_F dt stays constant over
/// 1 s of the default box, within 1e-9 of its kinetic energy.
#[test]
fn energy_is_conserved_without_dissipation() {
    let mut p = GearboxParams::default_box();
    (p.damper.c_cl, p.damper.H_1, p.damper.H_2, p.c_I) = (0.0, 0.0, 0.0, 0.0);
    for gear in &mut p.gears {
        (gear.pair.C, gear.pair.C_LM, gear.pair.B) = (0.0, 0.0, 0.0);
    }
    let (mut sys, mut y) = engine_driven(&p);
    let energy = |t: f64, y: &State| {
        let omega_F = Engine::new(&p.engine).steady_at(t).unwrap().omega;
        let omega_I = omega_F - y[PHI_DOT];
        let mut kinetic = 0.5 * p.I_I * omega_I * omega_I;
        let mut potential = V_cl(&p, y[PHI]);
        for (i, g) in p.gears.iter().enumerate() {
            let q = &g.pair;
            let omega_L = (y[xi_dot(i)] + q.r_M * g.rho * omega_I) / q.r_L;
            kinetic += 0.5 * q.I_L * omega_L * omega_L;
            let paper = Paper {
                K_star: q.K_star,
                alpha: q.alpha,
                epsilon: q.epsilon,
                G: q.G,
                C_LM: 0.0,
            };
            potential += V(&paper, y[xi(i)]);
        }
        (kinetic + potential - y[W_FLYWHEEL], kinetic)
    };
    let (e0, _) = energy(0.0, &y);
    let (mut drift, mut scale) = (0.0f64, 0.0f64);
    let solver = run(&mut sys, &mut y, 1e-11, 1.0, 0.005, |t, _, y| {
        let (e, kinetic) = energy(t, y);
        drift = drift.max((e - e0).abs());
        scale = scale.max(kinetic);
    });
    let impacts: Vec<u64> = sys.gears[..5]
        .iter()
        .map(|g| g.impacts.count[0] + g.impacts.count[1])
        .collect();
    println!(
        "energy drift {drift:e} J of {scale:e} J ({:e}), impacts {impacts:?}, {:?}",
        drift / scale,
        solver.stats
    );
    assert!(impacts.iter().all(|&n| n > 10), "it rattles: {impacts:?}");
    assert!(
        drift <= 1e-9 * scale,
        "energy drift {drift:e} J against {scale:e} J"
    );
}

/// With the gear out of contact (a backlash of 1 m, no drag) and the engine at a steady
/// speed without orders, a twist of 0.01 rad inside the pre-damper oscillates freely at
/// √(k_1/I_I)/(2π) (9.52 Hz): its zero crossings over 1 s give the frequency within 0.5 %.
#[test]
fn the_damper_resonates_at_its_linear_frequency() {
    let mut p = GearboxParams::default_box();
    (p.damper.c_cl, p.damper.H_1, p.damper.H_2, p.c_I) = (0.0, 0.0, 0.0, 0.0);
    p.engine.orders[0].a = 0.0;
    p.engine.orders[1].a = 0.0;
    p.gears.truncate(1);
    (p.gears[0].pair.G, p.gears[0].pair.C) = (1.0, 0.0);
    let (mut sys, mut y) = engine_driven(&p);
    y[PHI] = 0.01;
    sys.settle(0.0, &y);
    let mut crossings = vec![];
    let mut last = y[PHI];
    let dt = 1e-5;
    run(&mut sys, &mut y, 1e-9, 1.0, dt, |t, _, y| {
        if (last > 0.0) != (y[PHI] > 0.0) {
            // Linear interpolation inside the 10 µs chunk.
            crossings.push(t - dt * y[PHI] / (y[PHI] - last));
        }
        last = y[PHI];
    });
    let n = crossings.len();
    let measured = (n - 1) as f64 / (2.0 * (crossings[n - 1] - crossings[0]));
    let expected = (p.damper.k_1 / p.I_I).sqrt() / std::f64::consts::TAU;
    println!("{n} zero crossings: {measured} Hz, expected {expected} Hz");
    assert!(n >= 18, "{n} crossings");
    assert!(
        (measured - expected).abs() < 5e-3 * expected,
        "{measured} Hz vs {expected} Hz"
    );
    assert_eq!(sys.gears[0].impacts.count, [0, 0]);
}

/// One gear with ρ = 1.5, driven by inputs: its ξ'' equals GearRattle's for the same ξ, ξ'
/// with the main shaft turning as the driving gear (r_M ρ, ω_I = ω_F − φ', α_I from
/// docs/GEARBOX.md §3 written out here), in every region; and φ'' = α_F − α_I.
#[test]
fn one_gear_follows_the_gear_pairs_right_hand_side() {
    let mut p = GearboxParams::default_box();
    p.gears.truncate(1);
    p.gears[0].rho = 1.5;
    p.gears[0].pair.B = 0.01;
    p.gears[0].pair.omega_S = 2.0;
    let q = p.gears[0].pair;
    let (flywheel, inputs) = driven_by_inputs(0.01, [3.0, 90.0, 700.0]);
    let (phi, phi_dot) = (0.02, 1.3);
    for xi0 in [-3e-6, -0.4e-6, 40e-6, q.G + 0.3e-6, q.G + 2e-6] {
        let xi_dot0 = -0.02;
        let mut y = [0.0; gearbox::N];
        (y[PHI], y[PHI_DOT], y[xi(0)], y[xi_dot(0)]) = (phi, phi_dot, xi0, xi_dot0);
        let sys = Gearbox::new(&p, inputs, &y);
        let f = sys.rhs(0.01, &y);
        // docs/GEARBOX.md §2-§3 by hand (pre-damper, drags at 40 °C).
        let omega_I = flywheel.omega - phi_dot;
        let d = &p.damper;
        let T_cl = d.k_1 * phi + d.H_1 * (phi_dot / d.omega_h).tanh() + d.c_cl * phi_dot;
        let mut pair = q;
        pair.r_M *= 1.5;
        let dynamics = Dynamics::new(pair);
        let region = dynamics.law.classify(xi0);
        let F = dynamics.law.force(region, xi0, xi_dot0).total();
        let alpha_I = (T_cl + 1.5 * q.r_M * F - p.c_I * omega_I) / p.I_I;
        let shaft = Excitation::Polynomial(Polynomial {
            t0: 0.0,
            at_t0: Shaft {
                theta: 0.0,
                omega: omega_I,
                alpha: alpha_I,
            },
        });
        let rattle = Rattle::new(dynamics, shaft, xi0);
        let mut yr = [0.0; rattle::N];
        (yr[rattle::XI], yr[rattle::XI_DOT]) = (xi0, xi_dot0);
        let fr = rattle.rhs(0.0, &yr);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
        assert_eq!(f[xi(0)], xi_dot0);
        assert!(
            close(f[xi_dot(0)], fr[rattle::XI_DOT]),
            "{region:?}: {} vs {}",
            f[xi_dot(0)],
            fr[rattle::XI_DOT]
        );
        assert!(close(f[PHI_DOT], flywheel.alpha - alpha_I));
        assert_eq!(f[PHI], phi_dot);
    }
}

/// Impacts per second of each gear over [from, to] of the default box at `T_oil`, and the
/// share of the time the damper spends in its main stage.
fn rattle_rates(T_oil: f64, from: f64, to: f64) -> (Vec<f64>, f64, Solver<{ gearbox::N }>) {
    let mut p = GearboxParams::default_box();
    p.T_oil = T_oil;
    let (mut sys, mut y) = engine_driven(&p);
    let total = |sys: &Gearbox| -> Vec<u64> {
        sys.gears[..5]
            .iter()
            .map(|g| g.impacts.count[0] + g.impacts.count[1])
            .collect()
    };
    let mut at_from = vec![];
    let (mut main, mut samples) = (0u64, 0u64);
    let dt = 1e-4;
    let solver = run(&mut sys, &mut y, 1e-7, to, dt, |t, sys, _| {
        if (t - from).abs() < 0.5 * dt {
            at_from = total(sys);
        }
        if t > from {
            samples += 1;
            main += u64::from(sys.stage != gear_rattle::physics::Stage::PreDamper);
        }
    });
    let rates = total(&sys)
        .iter()
        .zip(&at_from)
        .map(|(b, a)| (b - a) as f64 / (to - from))
        .collect();
    (rates, main as f64 / samples as f64, solver)
}

/// docs/GEARBOX.md §8, B1: the default box at 40 °C runs 1 s and every gear rattles (§8's
/// reference: ≈ 140 / 220 / 185 / 165 / 185 impacts per second over 0.5-2 s).
#[test]
fn every_gear_rattles_at_40_degrees() {
    let (rates, main, solver) = rattle_rates(40.0, 0.5, 1.0);
    println!(
        "B1 impacts/s over 0.5-1 s: {rates:.0?}, main stage {:.0} % of the time, {:?}",
        100.0 * main,
        solver.stats
    );
    assert!(rates.iter().all(|&r| r > 20.0), "{rates:?}");
}

/// docs/GEARBOX.md §8, B2: at −10 °C the cold drag holds every gear on its flank: no impact.
#[test]
fn no_gear_rattles_at_minus_10_degrees() {
    let (rates, main, _) = rattle_rates(-10.0, 0.5, 1.0);
    println!(
        "B2 impacts/s over 0.5-1 s: {rates:.0?}, main stage {:.0} %",
        100.0 * main
    );
    assert!(rates.iter().all(|&r| r == 0.0), "{rates:?}");
}

/// Radau IIA steps the box too (its analytic Jacobian): 0.1 s of B1, inside the horizon over
/// which B1 is pointwise predictable, with Radau IIA throughout agrees with DOPRI5 on every
/// ξ_i within 1e-3 G_i and on φ within 1e-6 rad.
#[test]
fn radau_agrees_with_dopri5() {
    use gear_rattle::integrator::Method;
    let p = GearboxParams::default_box();
    let at = |method: Method| {
        let (mut sys, mut y) = engine_driven(&p);
        let mut solver = Solver::with_method(sys.tolerance(1e-9), method);
        let mut t = 0.0;
        solver.advance(&mut sys, &mut t, &mut y, 0.1).unwrap();
        (y, solver.stats)
    };
    let (explicit, _) = at(Method::Explicit);
    let (implicit, stats) = at(Method::Implicit);
    println!("Radau IIA over 0.1 s: {stats:?}");
    assert!(stats.implicit_steps > 0);
    assert!((explicit[PHI] - implicit[PHI]).abs() < 1e-6);
    for (i, g) in p.gears.iter().enumerate() {
        let d = (explicit[xi(i)] - implicit[xi(i)]).abs();
        assert!(d < 1e-3 * g.pair.G, "gear {}: {d:e}", i + 1);
    }
}

/// Under an engine ramp ω_F is integrated with the box: after 0.3 s at +1500 rpm/s it
/// equals ω_F(0) + ∫ α_F dt (Simpson's rule here) within 1e-9 relative, and θ_I = θ_F − φ.
#[test]
fn a_ramp_integrates_the_flywheel() {
    let mut p = GearboxParams::default_box();
    p.engine.rpm_rate = 1500.0;
    let engine = Engine::new(&p.engine);
    let (mut sys, mut y) = engine_driven(&p);
    let solver = run(&mut sys, &mut y, 1e-8, 0.3, 0.01, |_, _, _| {});
    let n = 30_000;
    let h = 0.3 / n as f64;
    let integral: f64 = (0..n)
        .map(|k| {
            let t = k as f64 * h;
            h / 6.0 * (engine.alpha(t) + 4.0 * engine.alpha(t + 0.5 * h) + engine.alpha(t + h))
        })
        .sum();
    let r = sys.readout(0.3, &y);
    let expected = engine.omega_start() + integral;
    println!(
        "ramp: omega_F {} vs {expected}, {:?}",
        r.input.omega_F, solver.stats
    );
    assert!((r.input.omega_F - expected).abs() < 1e-9 * expected);
    assert_eq!(r.input.theta_I, r.input.theta_F - y[PHI]);
    assert!(r.input.theta_F > 0.3 * 800.0 * std::f64::consts::PI / 30.0);
}

/// Driven by inputs: new flywheel motion moves the twist, not the input side (θ_I, ω_I and
/// every ξ_i stay), and the damper's stage follows φ; between inputs the flywheel turns as
/// extrapolated from them.
#[test]
fn new_inputs_move_the_twist_not_the_input_side() {
    let p = GearboxParams::default_box();
    let (_, inputs) = driven_by_inputs(0.0, [100.0, 84.0, 300.0]);
    let (mut sys, mut y) = Gearbox::start(&p, inputs).unwrap();
    let mut solver = Solver::new(sys.tolerance(1e-7));
    let mut t = 0.0;
    solver.advance(&mut sys, &mut t, &mut y, 0.01).unwrap();
    let before = sys.readout(t, &y);
    assert!((before.input.theta_F - (100.0 + 0.84 + 0.5 * 300.0 * 1e-4)).abs() < 1e-12);
    let next = Shaft {
        theta: before.input.theta_F + 0.08,
        omega: before.input.omega_F + 2.0,
        alpha: -500.0,
    };
    let crossed = sys.set_flywheel(t, &mut y, next);
    solver.invalidate();
    let after = sys.readout(t, &y);
    assert!((after.input.theta_I - before.input.theta_I).abs() < 1e-12);
    assert!((after.input.omega_I - before.input.omega_I).abs() < 1e-12);
    assert!((after.input.phi - before.input.phi - 0.08).abs() < 1e-12);
    assert_eq!(after.input.alpha_F, -500.0);
    for (a, b) in after.gears.iter().zip(&before.gears) {
        assert_eq!((a.xi, a.xi_dot), (b.xi, b.xi_dot));
    }
    let (lo, hi) = sys.piece(0);
    assert!(
        lo <= y[PHI] && y[PHI] <= hi,
        "stage settled ({crossed} crossed)"
    );
    solver.advance(&mut sys, &mut t, &mut y, 0.02).unwrap();
}

/// A box starts only from valid parameters, the error naming the one at fault.
#[test]
fn start_refuses_invalid_parameters() {
    let mut p = GearboxParams::default_box();
    p.damper.k_2 = 0.5 * p.damper.k_1;
    let error = Gearbox::start(&p, Drive::Engine(Engine::new(&p.engine))).unwrap_err();
    assert!(error.to_string().starts_with("parameter k_2 = "), "{error}");
}

/// The input side driven by inputs (no damper): each gear is GearRattle's pair with the
/// input side as its main shaft (r_M ρ): the same ξ'' in every region; φ, φ' stay; new
/// inputs move each ξ_i by r_M,i ρ_i times the jump of θ_I (ξ_i' by that of ω_I), the loose
/// gears standing; ω_S = σ ω_out.
#[test]
fn an_imposed_input_side_drives_gear_rattles_pairs() {
    let mut p = GearboxParams::default_box();
    p.gears[1].rho = 1.4;
    p.gears[1].sigma = 0.5;
    let input = Shaft {
        theta: 2.0,
        omega: 80.0,
        alpha: -900.0,
    };
    let drive = Drive::InputSide(Polynomial {
        t0: 0.0,
        at_t0: input,
    });
    let (mut sys, mut y) = Gearbox::start(&p, drive).unwrap();
    sys.set_output_speed(10.0);
    for xi0 in [-2e-6, -0.3e-6, 30e-6, 80e-6 + 0.5e-6, 80e-6 + 4e-6] {
        (y[xi(1)], y[xi_dot(1)]) = (xi0, 0.015);
        sys.settle(0.0, &y);
        let f = sys.rhs(0.003, &y);
        let mut pair = p.gears[1].pair;
        (pair.r_M, pair.omega_S) = (pair.r_M * 1.4, 5.0);
        let shaft = Excitation::Polynomial(Polynomial {
            t0: 0.0,
            at_t0: input,
        });
        let rattle = Rattle::new(Dynamics::new(pair), shaft, xi0);
        let mut yr = [0.0; rattle::N];
        (yr[rattle::XI], yr[rattle::XI_DOT]) = (xi0, 0.015);
        let fr = rattle.rhs(0.003, &yr);
        let want = fr[rattle::XI_DOT];
        assert!(
            (f[xi_dot(1)] - want).abs() <= 1e-12 * want.abs(),
            "{xi0}: {} vs {want}",
            f[xi_dot(1)]
        );
        assert_eq!((f[PHI], f[PHI_DOT]), (0.0, 0.0));
    }
    let (xi_before, dot_before) = (y[xi(1)], y[xi_dot(1)]);
    let at = sys.readout(0.0, &y).input;
    let next = Shaft {
        theta: at.theta_I + 1e-4,
        omega: at.omega_I - 0.5,
        alpha: 0.0,
    };
    sys.set_input_side(0.0, &mut y, next);
    let lever = p.gears[1].pair.r_M * 1.4;
    assert!((y[xi(1)] - (xi_before - lever * 1e-4)).abs() < 1e-15);
    assert!((y[xi_dot(1)] - (dot_before + lever * 0.5)).abs() < 1e-12);
    let mut solver = Solver::new(sys.tolerance(1e-7));
    let mut t = 0.0;
    solver.advance(&mut sys, &mut t, &mut y, 0.05).unwrap();
    assert_eq!((y[PHI], y[PHI_DOT]), (0.0, 0.0));
}
