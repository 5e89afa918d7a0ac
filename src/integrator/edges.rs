//! Edge location on a step's dense output: where an accepted step leaves its piece, among
//! all of the system's guards ([`Piecewise::guards`]).

use super::roots::illinois;
use super::{Crossing, Dense, Edge, Piecewise};

/// The earliest edge that the accepted step leaves its piece through, among all guards of
/// `sys`, and the fraction θ of the step at which it does (each guard located by
/// [`locate_edge`]; a tie goes to the lower guard).
pub(crate) fn locate_crossing<S: Piecewise<N>, T: Dense<N>, const N: usize>(
    sys: &S,
    step: &T,
) -> Option<(Crossing, f64)> {
    let mut first: Option<(Crossing, f64)> = None;
    for guard in 0..sys.guards() {
        let (lo, hi) = sys.piece(guard);
        if let Some((edge, theta)) = locate_edge(step, S::guard(guard), lo, hi)
            && first.is_none_or(|(_, earliest)| theta < earliest)
        {
            first = Some((Crossing { guard, edge }, theta));
        }
    }
    first
}

/// Whether the accepted trial leaves [lo, hi] on a guard component, and where: the edge and
/// the fraction θ of the step at which the dense output first reaches it. The rate of the
/// guard tells the shape of the trajectory inside the step: moving out then back in (a graze,
/// decided by the extremum, so it is not skipped), moving in then out (the exit can only come
/// after the extremum, which matters when the step starts on the edge it just crossed), or
/// monotone.
pub(crate) fn locate_edge<T: Dense<N>, const N: usize>(
    trial: &T,
    (g, r): (usize, usize),
    lo: f64,
    hi: f64,
) -> Option<(Edge, f64)> {
    let (y0, y1) = trial.ends();
    let extremum = || illinois(|th| trial.dense(r, th), 0.0, 1.0, 1e-12);
    let find = |edge: Edge, level: f64| -> Option<f64> {
        let outside = |v: f64| match edge {
            Edge::Lower => v < level,
            Edge::Upper => v > level,
        };
        let outward = |rate: f64| match edge {
            Edge::Lower => rate < 0.0,
            Edge::Upper => rate > 0.0,
        };
        // Starting on the edge or a rounding error beyond it (just after crossing it the
        // other way) and moving out: the trajectory leaves at once.
        let on_or_beyond = outside(y0[g]) || y0[g] == level;
        if on_or_beyond && outward(y0[r]) {
            return Some(0.0);
        }
        let (a, b) = match (outward(y0[r]), outward(y1[r])) {
            (true, false) => {
                let th = extremum();
                if !outside(trial.dense(g, th)) {
                    return None;
                }
                (0.0, th)
            }
            (false, true) if outside(y1[g]) => (extremum(), 1.0),
            _ if outside(y1[g]) => (0.0, 1.0),
            _ => return None,
        };
        Some(illinois(|th| trial.dense(g, th) - level, a, b, 1e-13))
    };
    let lower = if lo.is_finite() {
        find(Edge::Lower, lo)
    } else {
        None
    };
    let upper = if hi.is_finite() {
        find(Edge::Upper, hi)
    } else {
        None
    };
    match (lower, upper) {
        (Some(a), Some(b)) if b < a => Some((Edge::Upper, b)),
        (Some(a), _) => Some((Edge::Lower, a)),
        (None, Some(b)) => Some((Edge::Upper, b)),
        (None, None) => None,
    }
}
