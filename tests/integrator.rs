//! The integrator on problems with known solutions: order of convergence of the DOPRI5 step
//! and of its dense output, tolerance proportionality, step size carried over between calls,
//! and edge location (exact crossing times, each crossing counted once, grazes not skipped).

use gear_rattle::integrator::dopri5;
use gear_rattle::integrator::{
    Crossing, Edge, Jacobian, Method, Piecewise, Solver, System, Tolerance,
};

/// y' = y cos t, y(0) = 1: y = exp(sin t).
struct Exp;

impl System<1> for Exp {
    fn rhs(&self, t: f64, y: &[f64; 1]) -> [f64; 1] {
        [y[0] * t.cos()]
    }
}

impl Jacobian<1> for Exp {
    fn jacobian(&self, t: f64, _: &[f64; 1]) -> [[f64; 1]; 1] {
        [[t.cos()]]
    }
}

/// A smooth system seen as one infinite piece.
impl Piecewise<1> for Exp {
    fn guard(_: usize) -> (usize, usize) {
        (0, 0)
    }
    fn piece(&self, _: usize) -> (f64, f64) {
        (f64::NEG_INFINITY, f64::INFINITY)
    }
    fn cross(&mut self, _: Crossing, _: f64, _: &[f64; 1]) {
        unreachable!("no edges")
    }
}

fn exact(t: f64) -> f64 {
    t.sin().exp()
}

/// Errors at t = T (end) and at the middle of the last step (dense), with n fixed steps.
fn fixed_steps(n: usize) -> (f64, f64) {
    let t_end = 2.0;
    let h = t_end / n as f64;
    let (mut t, mut y) = (0.0, [1.0]);
    let mut dense_err = 0.0f64;
    for _ in 0..n {
        let k1 = Exp.rhs(t, &y);
        let mut trial = dopri5::Trial::empty();
        dopri5::step(&Exp, t, &y, &k1, h, 1, &mut trial);
        dense_err = dense_err.max((trial.dense(0, 0.5) - exact(t + 0.5 * h)).abs());
        y = trial.y1;
        t += h;
    }
    ((y[0] - exact(t_end)).abs(), dense_err)
}

#[test]
fn the_step_is_fifth_order_and_the_dense_output_fourth() {
    let mut previous = fixed_steps(10);
    for n in [20, 40, 80] {
        let now = fixed_steps(n);
        let order = (previous.0 / now.0).log2();
        let dense_order = (previous.1 / now.1).log2();
        assert!((4.6..5.6).contains(&order), "order {order} at n = {n}");
        assert!(
            dense_order > 3.8,
            "dense output order {dense_order} at n = {n}"
        );
        previous = now;
    }
}

fn adaptive(rtol: f64, chunks: usize, interpolate_ends: bool) -> (f64, u64) {
    let tol = Tolerance {
        rtol,
        atol: [rtol],
        controlled: 1,
    };
    let mut solver = Solver::new(tol);
    solver.interpolate_ends = interpolate_ends;
    let (mut t, mut y) = (0.0, [1.0]);
    let t_end = 20.0;
    for k in 1..=chunks {
        solver
            .advance(&mut Exp, &mut t, &mut y, t_end * k as f64 / chunks as f64)
            .unwrap();
    }
    assert_eq!(t, t_end);
    ((y[0] - exact(t_end)).abs(), solver.stats.rhs_evals)
}

#[test]
fn the_error_follows_the_tolerance() {
    let (e6, _) = adaptive(1e-6, 1, false);
    let (e9, _) = adaptive(1e-9, 1, false);
    assert!(e6 < 1e-4 && e9 < 1e-7, "{e6:e} {e9:e}");
    assert!(e6 / e9 > 100.0, "1e-6 → {e6:e}, 1e-9 → {e9:e}");
}

/// Cutting the run into many calls costs at most the extra last steps: the step size and
/// the controller carry over, nothing restarts.
#[test]
fn the_step_size_carries_over_between_calls() {
    let (e1, one_call) = adaptive(1e-10, 1, false);
    let (e100, hundred_calls) = adaptive(1e-10, 100, false);
    assert!(
        (hundred_calls as f64) < 1.3 * one_call as f64 + 6.0 * 100.0,
        "{hundred_calls} vs {one_call} evaluations"
    );
    assert!(e100 < 10.0 * e1.max(1e-12), "{e100:e} vs {e1:e}");
}

/// With end times served from the dense output, 20 000 calls (one per millisecond) cost
/// the right-hand sides of one call, and each end is as accurate as the steps around it.
#[test]
fn interpolated_ends_cost_nothing_and_keep_the_accuracy() {
    let (e1, one_call) = adaptive(1e-8, 1, true);
    let (e_many, many_calls) = adaptive(1e-8, 20_000, true);
    let (_, cut_short) = adaptive(1e-8, 20_000, false);
    println!(
        "1 call: {one_call} rhs; 20 000 calls: {many_calls} interpolated, {cut_short} cut short"
    );
    assert!(many_calls <= one_call + 30, "{many_calls} vs {one_call}");
    assert!(cut_short > 10 * many_calls);
    assert!(e_many < 1e-6 && e1 < 1e-6, "{e_many:e} {e1:e}");
}

/// A master that passes its own time k·h rather than the one it was handed back,
/// (k − 1)·h + h, which differs by an ulp or so: its points are still served from the kept
/// steps, at the cost of one call.
#[test]
fn interpolated_ends_survive_times_rounded_differently() {
    let tol = Tolerance {
        rtol: 1e-8,
        atol: [1e-8],
        controlled: 1,
    };
    let mut solver = Solver::new(tol);
    solver.interpolate_ends = true;
    let (mut t, mut y) = (0.0, [1.0]);
    let h = 1e-3;
    let mut rounded_differently = 0;
    for k in 0..20_000 {
        let master_t = k as f64 * h;
        if master_t != t {
            rounded_differently += 1;
        }
        t = master_t;
        solver
            .advance(&mut Exp, &mut t, &mut y, master_t + h)
            .unwrap();
    }
    let (_, one_call) = adaptive(1e-8, 1, true);
    println!(
        "{rounded_differently} of 20 000 times rounded differently; {} rhs against {one_call}",
        solver.stats.rhs_evals
    );
    assert!(rounded_differently > 1000);
    assert!(solver.stats.rhs_evals <= one_call + 30);
    assert!((y[0] - exact(20.0)).abs() < 1e-6);
}

/// x'' = a_above while x ≥ 0 and a_below while x ≤ 0: piecewise quadratic exact solutions,
/// with the crossings of x = 0 recorded.
struct TwoPieces {
    accel: [f64; 2],
    below: bool,
    crossings: Vec<(f64, Edge)>,
}

impl TwoPieces {
    fn new(a_above: f64, a_below: f64) -> Self {
        TwoPieces {
            accel: [a_above, a_below],
            below: false,
            crossings: vec![],
        }
    }
}

impl System<2> for TwoPieces {
    fn rhs(&self, _t: f64, y: &[f64; 2]) -> [f64; 2] {
        [y[1], self.accel[self.below as usize]]
    }
}

impl Jacobian<2> for TwoPieces {
    fn jacobian(&self, _: f64, _: &[f64; 2]) -> [[f64; 2]; 2] {
        [[0.0, 1.0], [0.0, 0.0]]
    }
}

impl Piecewise<2> for TwoPieces {
    fn guard(_: usize) -> (usize, usize) {
        (0, 1)
    }
    fn piece(&self, _: usize) -> (f64, f64) {
        if self.below {
            (f64::NEG_INFINITY, 0.0)
        } else {
            (0.0, f64::INFINITY)
        }
    }
    fn cross(&mut self, at: Crossing, t: f64, _: &[f64; 2]) {
        self.below = at.edge == Edge::Lower;
        self.crossings.push((t, at.edge));
    }
}

fn run(
    sys: &mut TwoPieces,
    method: Method,
    y0: [f64; 2],
    t_end: f64,
    chunks: usize,
    tol: f64,
) -> Vec<(f64, Edge)> {
    let tol = Tolerance {
        rtol: tol,
        atol: [tol, tol],
        controlled: 2,
    };
    let mut solver = Solver::with_method(tol, method);
    let (mut t, mut y) = (0.0, y0);
    for k in 1..=chunks {
        solver
            .advance(sys, &mut t, &mut y, t_end * k as f64 / chunks as f64)
            .unwrap();
    }
    std::mem::take(&mut sys.crossings)
}

/// Both methods locate edges on their dense output (DOPRI5's and Radau IIA's).
const METHODS: [Method; 2] = [Method::Explicit, Method::Implicit];

/// x'' = −1 above 0 and +1 below, from x(0) = 1 at rest: crossings at t = (2k+1)√2.
#[test]
fn edges_are_located_exactly_and_crossed_once() {
    for (method, chunks) in METHODS
        .into_iter()
        .flat_map(|m| [(m, 1), (m, 7), (m, 1000)])
    {
        let mut sys = TwoPieces::new(-1.0, 1.0);
        let crossings = run(&mut sys, method, [1.0, 0.0], 20.0, chunks, 1e-8);
        let expected: Vec<f64> = (0..7).map(|k| (2 * k + 1) as f64 * 2f64.sqrt()).collect();
        assert_eq!(crossings.len(), expected.len(), "{crossings:?}");
        for (k, ((t, edge), want)) in crossings.iter().zip(&expected).enumerate() {
            assert!(
                (t - want).abs() < 1e-9,
                "{method:?}: crossing {k} at {t}, expected {want}"
            );
            let down = k % 2 == 0;
            assert_eq!(*edge, if down { Edge::Lower } else { Edge::Upper });
        }
    }
}

/// A trajectory that dips 10 nm below the edge for 0.3 ms and comes back is caught even
/// though a single step of the (exact, quadratic) solution could jump over the dip:
/// x = 1e-8 − 2e-4 t + t²/2, minimum −1e-8 at t = 2e-4, roots at 2e-4 ∓ √2·1e-4.
#[test]
fn a_graze_inside_one_step_is_not_skipped() {
    for method in METHODS {
        let mut sys = TwoPieces::new(1.0, 1.0);
        let crossings = run(&mut sys, method, [1e-8, -2e-4], 1.0, 1, 1e-3);
        let roots = [2e-4 - 2f64.sqrt() * 1e-4, 2e-4 + 2f64.sqrt() * 1e-4];
        assert_eq!(crossings.len(), 2, "{method:?}: {crossings:?}");
        assert!((crossings[0].0 - roots[0]).abs() < 1e-9, "{method:?}");
        assert!((crossings[1].0 - roots[1]).abs() < 1e-9, "{method:?}");
    }
}

/// Two independent coordinates, each x'' = −a above 0 and +a below, as the two guards of one
/// system: x1 with a = 1 from 1 crosses 0 at (2k+1)√2, x2 with a = 4 from 1 at (2k+1)/√2.
/// Every crossing of both is found where it is, in time order, by the right guard, whatever
/// the end times asked for: steps end on the earliest crossing among the guards.
struct TwoGuards {
    accel: [f64; 2],
    below: [bool; 2],
    crossings: Vec<(f64, Crossing)>,
}

impl System<4> for TwoGuards {
    fn rhs(&self, _t: f64, y: &[f64; 4]) -> [f64; 4] {
        let a = |k: usize| {
            if self.below[k] {
                self.accel[k]
            } else {
                -self.accel[k]
            }
        };
        [y[1], a(0), y[3], a(1)]
    }
}

impl Jacobian<4> for TwoGuards {
    fn jacobian(&self, _: f64, _: &[f64; 4]) -> [[f64; 4]; 4] {
        let mut j = [[0.0; 4]; 4];
        (j[0][1], j[2][3]) = (1.0, 1.0);
        j
    }
}

impl Piecewise<4> for TwoGuards {
    fn guards(&self) -> usize {
        2
    }
    fn guard(k: usize) -> (usize, usize) {
        (2 * k, 2 * k + 1)
    }
    fn piece(&self, k: usize) -> (f64, f64) {
        if self.below[k] {
            (f64::NEG_INFINITY, 0.0)
        } else {
            (0.0, f64::INFINITY)
        }
    }
    fn cross(&mut self, at: Crossing, t: f64, _: &[f64; 4]) {
        self.below[at.guard] = at.edge == Edge::Lower;
        self.crossings.push((t, at));
    }
}

#[test]
fn the_earliest_crossing_among_guards_ends_the_step() {
    let sqrt2 = 2f64.sqrt();
    let mut expected: Vec<(f64, usize)> = (0..7)
        .map(|k| ((2 * k + 1) as f64 * sqrt2, 0))
        .chain((0..14).map(|k| ((2 * k + 1) as f64 / sqrt2, 1)))
        .filter(|&(t, _)| t < 20.0)
        .collect();
    expected.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (method, chunks) in METHODS
        .into_iter()
        .flat_map(|m| [(m, 1), (m, 7), (m, 1000)])
    {
        let mut sys = TwoGuards {
            accel: [1.0, 4.0],
            below: [false; 2],
            crossings: vec![],
        };
        let tol = Tolerance {
            rtol: 1e-8,
            atol: [1e-8; 4],
            controlled: 4,
        };
        let mut solver = Solver::with_method(tol, method);
        let (mut t, mut y) = (0.0, [1.0, 0.0, 1.0, 0.0]);
        for k in 1..=chunks {
            solver
                .advance(&mut sys, &mut t, &mut y, 20.0 * k as f64 / chunks as f64)
                .unwrap();
        }
        assert_eq!(sys.crossings.len(), expected.len(), "{:?}", sys.crossings);
        for (k, ((t, at), (want, guard))) in sys.crossings.iter().zip(&expected).enumerate() {
            assert_eq!(at.guard, *guard, "{method:?}: crossing {k} at {t}");
            assert!(
                (t - want).abs() < 1e-9,
                "{method:?}: crossing {k} of guard {guard} at {t}, expected {want}"
            );
        }
    }
}
