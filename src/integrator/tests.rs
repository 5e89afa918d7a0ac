//! The driver with each method and with the automatic hand-over, on the systems of
//! `test_systems`: Radau IIA through [`Solver`] against exact solutions and a published
//! reference, edges on a stiff contact, and what the hand-over saves.

use super::solver::{Method, Solver, Stats};
use super::test_systems::{Bounce, G, Linear, Robertson, sci, tolerance};
use super::{Jacobian, Piecewise, Tolerance};

/// Runs from (t_ends[0], y0) through each of the following end times (one `advance` each,
/// like communication steps); the state at each end and the counters.
fn run<S: Piecewise<N> + Jacobian<N>, const N: usize>(
    sys: &mut S,
    solver: &mut Solver<N>,
    t_ends: &[f64],
    y0: [f64; N],
) -> Vec<[f64; N]> {
    let (mut t, mut y) = (t_ends[0], y0);
    t_ends[1..]
        .iter()
        .map(|&t_end| {
            solver.advance(sys, &mut t, &mut y, t_end).unwrap();
            assert_eq!(t, t_end);
            y
        })
        .collect()
}

fn summary(s: &Stats) -> String {
    format!(
        "{} steps ({} implicit, {} rejected), {} edges, {} rhs, {} Jacobians, {} LU, {} switches",
        s.accepted,
        s.implicit_steps,
        s.rejected,
        s.edges,
        s.rhs_evals,
        s.jacobians,
        s.decompositions,
        s.switches
    )
}

/// Contact tolerance of the bounce: x to 1e-14 (the rest position is −1e-9), x' alike on the
/// scale of the contact frequency 1e5.
fn bounce_tolerance() -> Tolerance<2> {
    Tolerance {
        rtol: 1e-8,
        atol: [1e-14, 1e-14 * 1e5],
        controlled: 2,
    }
}

const REST: f64 = -G / 1e10;

/// The bounce from `make()` and y0 over [0, t_end] with each method: end state and counters.
fn by_method(
    label: &str,
    methods: &[Method],
    make: impl Fn() -> Bounce,
    t_end: f64,
    y0: [f64; 2],
) -> Vec<([f64; 2], Stats)> {
    methods
        .iter()
        .map(|&method| {
            let mut solver = Solver::with_method(bounce_tolerance(), method);
            let y = run(&mut make(), &mut solver, &[0.0, t_end], y0)[0];
            println!(
                "{label}, {method:?}: x = {:e}; {}",
                y[0],
                summary(&solver.stats)
            );
            (y, solver.stats)
        })
        .collect()
}

#[test]
fn radau_on_a_stiff_linear_system_against_its_eigendecomposition() {
    let y0 = [1.0, 0.0];
    let ends = [0.0, 1e-6, 1e-3, 0.1, 1.0, 5.0];
    for rtol in [1e-4, 1e-7, 1e-10] {
        let mut solver = Solver::with_method(tolerance(rtol, [rtol; 2]), Method::Implicit);
        let ys = run(&mut Linear, &mut solver, &ends, y0);
        let mut worst = 0.0f64;
        for (y, &t) in ys.iter().zip(&ends[1..]) {
            let exact = Linear::exact(t, y0);
            for i in 0..2 {
                worst = worst.max((y[i] - exact[i]).abs() / (rtol + rtol * exact[i].abs()));
            }
        }
        let s = solver.stats;
        println!(
            "linear λ = −1, −1e6 to t = 5, rtol {rtol:e}: error {worst:.2} × tol; {}",
            summary(&s)
        );
        assert!(worst < 10.0, "error {worst} × tol");
        assert!(s.accepted < 300 && s.implicit_steps == s.accepted);
    }
}

#[test]
fn radau_on_robertson_at_40_against_the_published_reference() {
    let reference = [0.715_827_068_7, 9.185_534_764e-6, 0.284_163_745_7];
    for rtol in [1e-6, 1e-9] {
        let tol = tolerance(rtol, [rtol * 1e-2, rtol * 1e-6, rtol * 1e-2]);
        let mut solver = Solver::with_method(tol, Method::Implicit);
        let y = run(&mut Robertson, &mut solver, &[0.0, 40.0], [1.0, 0.0, 0.0])[0];
        let rel: Vec<f64> = (0..3)
            .map(|i| (y[i] - reference[i]).abs() / reference[i])
            .collect();
        println!(
            "Robertson t = 40, rtol {rtol:e}: relative errors {}; {}",
            sci(&rel),
            summary(&solver.stats)
        );
        for e in rel {
            // The reference has 10 digits.
            assert!(e < (10.0 * rtol).max(2e-9), "relative error {e}");
        }
    }
}

/// Falls from 5 cm, bounces a dozen times (restitution 0.53), then rests on the contact:
/// Radau IIA crosses the edges like DOPRI5 and rests at −g/k for a fraction of the work.
#[test]
fn radau_crosses_the_stiff_contact_for_far_fewer_right_hand_sides() {
    let y0 = [0.05, 0.0];
    let runs = by_method(
        "bounce ζ = 0.2, 1 s",
        &[Method::Implicit, Method::Explicit],
        || Bounce::new(0.2, y0[0]),
        1.0,
        y0,
    );
    for (y, _) in &runs {
        assert!((y[0] - REST).abs() < 1e-13 && y[1].abs() < 1e-6, "{y:?}");
    }
    let (implicit, explicit) = (runs[0].1, runs[1].1);
    assert_eq!(implicit.edges, explicit.edges);
    assert!(explicit.rhs_evals > 20 * implicit.rhs_evals);
}

#[test]
fn the_hand_over_on_a_settling_contact() {
    let y0 = [0.05, 0.0];
    let mut sys = Bounce::new(0.2, y0[0]);
    let mut solver = Solver::new(bounce_tolerance());
    let y = run(&mut sys, &mut solver, &[0.0, 1.0], y0)[0];
    let s = solver.stats;
    println!("auto, bounce ζ = 0.2, 1 s: x = {:e}; {}", y[0], summary(&s));
    assert!((y[0] - REST).abs() < 1e-13 && y[1].abs() < 1e-6, "{y:?}");
    assert!(
        s.switches >= 1 && s.implicit_steps > 0 && s.rhs_evals < 10_000,
        "{s:?}"
    );
}

/// Undamped bouncing: every contact is resolved, never stiff: DOPRI5 all along, the very same
/// steps as DOPRI5 alone.
#[test]
fn no_hand_over_where_nothing_is_stiff() {
    let y0 = [0.05, 0.0];
    let runs = by_method(
        "bounce ζ = 0, 0.5 s",
        &[Method::Auto, Method::Explicit],
        || Bounce::new(0.0, y0[0]),
        0.5,
        y0,
    );
    assert_eq!(runs[0], runs[1]);
    assert_eq!(runs[0].1.switches, 0);
}

/// Resting on the contact, lifted off by the load, landing and settling, each second: stiff,
/// not stiff, stiff again; against DOPRI5 alone.
#[test]
fn the_hand_over_both_ways_on_a_lifted_contact() {
    let y0 = [REST, 0.0];
    let forced = || Bounce {
        forced: true,
        ..Bounce::new(0.2, y0[0])
    };
    let runs = by_method(
        "bounce ζ = 0.2 lifted each second, 2 s",
        &[Method::Auto, Method::Explicit],
        forced,
        2.0,
        y0,
    );
    let ((auto, a), (explicit, e)) = (runs[0], runs[1]);
    assert!(a.switches >= 3, "{a:?}");
    assert!(a.rhs_evals * 5 < e.rhs_evals, "{a:?} {e:?}");
    assert!(
        (auto[0] - explicit[0]).abs() < 1e-11,
        "{auto:?} {explicit:?}"
    );
}

/// A solver saved while Radau IIA steps (Jacobian and LU in use, the hand-over's memory) and
/// restored continues bit for bit: the FMU state relies on it.
#[test]
fn a_restored_solver_continues_bit_for_bit() {
    let y0 = [0.05, 0.0];
    let mut sys = Bounce::new(0.2, y0[0]);
    let mut solver = Solver::new(bounce_tolerance());
    let y = run(&mut sys, &mut solver, &[0.0, 0.6], y0)[0];
    assert!(solver.is_implicit(), "{:?}", solver.stats);
    let bytes = postcard::to_allocvec(&solver).unwrap();
    let mut restored: Solver<2> = postcard::from_bytes(&bytes).unwrap();
    let mut sys2 = sys;
    let ends = [0.6, 0.7, 0.8, 1.0];
    let a = run(&mut sys, &mut solver, &ends, y);
    let b = run(&mut sys2, &mut restored, &ends, y);
    assert_eq!(a, b);
    let (sa, sb) = (solver.stats, restored.stats);
    assert_eq!(
        (sa.accepted, sa.rejected, sa.rhs_evals),
        (sb.accepted, sb.rejected, sb.rhs_evals)
    );
}

/// `advance_until` stops on each edge whose crossing changes the count it is given (here the
/// contact itself: every landing and lift-off of the undamped bounce), with the state on the
/// edge: the first landing of the fall from 0.05 m where it falls, at 0.1 s. A call that
/// continues from a stop to the same end time goes on as `advance` does: the end times get
/// the states of a run that never stopped, to the bit.
#[test]
fn advance_until_stops_on_each_edge_and_keeps_the_trajectory() {
    let y0 = [0.05, 0.0];
    let ends: Vec<f64> = (0..=40).map(|k| k as f64 * 0.0123).collect();
    let mut plain = Solver::new(bounce_tolerance());
    let want = run(&mut Bounce::new(0.0, y0[0]), &mut plain, &ends, y0);
    let mut sys = Bounce::new(0.0, y0[0]);
    let mut solver = Solver::new(bounce_tolerance());
    let (mut t, mut y, mut stops, mut got) = (0.0, y0, Vec::new(), Vec::new());
    for &t_end in &ends[1..] {
        let contact = |s: &Bounce| u64::from(s.contact);
        while solver
            .advance_until(&mut sys, &mut t, &mut y, t_end, contact)
            .unwrap()
        {
            assert!(t < t_end && y[0].abs() < 1e-12, "{t} {y:?}");
            stops.push(t);
        }
        assert_eq!(t, t_end);
        got.push(y);
    }
    assert_eq!(got, want);
    assert_eq!(stops.len() as u64, plain.stats.edges);
    assert!(
        stops.len() >= 4 && (stops[0] - 0.1).abs() < 1e-12,
        "{stops:?}"
    );
}
