//! Passages through pieces that have a solution in closed form ([`Piecewise::exact`], the
//! gear's free flight): no steps are taken there; the solver looks for where the solution
//! leaves the piece with a root search that cannot step over a crossing, and keeps the
//! passage from one call to the next so that the trajectory does not depend on the end
//! times asked for.
//!
//! The search watches guard 0 of the system ([`Piecewise::guard`]): from a point where the
//! guard g lies at distances d_lo, d_hi from the piece's bounds and moves at its rate v, with |g''| ≤ M along the solution, g cannot
//! reach a bound before the time s at which d − w s − M s²/2 = 0 (w = the speed towards it),
//! so the search jumps there, re-evaluates, and repeats. Towards a crossing at speed w the
//! distance left falls as M d² / w² (quadratic convergence); the crossing is declared when the
//! guard is within `tol` of a bound and not moving back into the piece. A grazing approach
//! only slows the search down; it cannot hide a crossing, as a bisection on signs could.

use serde::{Deserialize, Serialize};

use super::left_off::LeftOff;
use super::options::OPTIONS;
use super::{ClosedForm, Edge, Piecewise};

/// A passage through a piece from (t0, y0), searched up to `t_clear`: no crossing in
/// [t0, t_clear]; once `exit` is found, the piece is left through it at t_clear.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub(super) struct Passage<const N: usize> {
    pub t0: f64,
    #[serde(with = "super::serde_array")]
    pub y0: [f64; N],
    /// Bound on |g''| from t0 on (g: guard 0).
    bound: f64,
    pub t_clear: f64,
    #[serde(with = "super::serde_array")]
    pub y_clear: [f64; N],
    pub exit: Option<Edge>,
    /// What the caller was given last.
    left_off: LeftOff<N>,
}

impl<const N: usize> Passage<N> {
    /// A passage starting at (t, y) along `exact`, the piece's solution from there.
    pub fn new(t: f64, y: &[f64; N], exact: &impl ClosedForm<N>) -> Self {
        Passage {
            t0: t,
            y0: *y,
            bound: exact.guard_acceleration_bound(),
            t_clear: t,
            y_clear: *y,
            exit: None,
            left_off: LeftOff::at(t, y),
        }
    }

    /// Whether a call from (t, y) continues from where the last one left off.
    pub fn continued_by(&self, t: f64, y: &[f64; N]) -> bool {
        self.left_off.continued_by(t, y)
    }

    /// Extends the search along `exact` through the piece [lo, hi] of `S`'s guard 0 until it
    /// is clear past t_end or has found the exit; returns the number of evaluations of the
    /// exact solution, or None if it needed more than `max_exit_evals` (a guard creeping
    /// along a bound). The exit is declared within `tol` of a bound.
    pub fn search<S: Piecewise<N>>(
        &mut self,
        exact: &impl ClosedForm<N>,
        (lo, hi): (f64, f64),
        t_end: f64,
        tol: f64,
    ) -> Option<u64> {
        let mut evals = 0;
        while self.exit.is_none() && self.t_clear < t_end {
            let (guard, rate) = S::guard(0);
            let (g, v) = (self.y_clear[guard], self.y_clear[rate]);
            let (d_lo, d_hi) = ((g - lo).max(0.0), (hi - g).max(0.0));
            if d_lo <= tol && v <= 0.0 {
                self.exit = Some(Edge::Lower);
            } else if d_hi <= tol && v >= 0.0 {
                self.exit = Some(Edge::Upper);
            } else {
                let (s_lo, s_hi) = (reach(d_lo, -v, self.bound), reach(d_hi, v, self.bound));
                let s = s_lo.min(s_hi);
                if self.t_clear + s == self.t_clear {
                    // Closer than time can resolve (a long run's late times): it leaves here.
                    self.exit = Some(if s_lo <= s_hi {
                        Edge::Lower
                    } else {
                        Edge::Upper
                    });
                    break;
                }
                evals += 1;
                if evals > OPTIONS.max_exit_evals {
                    return None;
                }
                self.t_clear += s;
                self.y_clear = exact.at(self.t_clear);
            }
        }
        Some(evals)
    }

    /// The state at t_end ≤ t_clear, remembered as handed out, and the number of evaluations
    /// of the exact solution it took (none at t_clear itself); None if the system's piece has
    /// no closed form.
    pub fn serve<S: Piecewise<N>>(&mut self, sys: &mut S, t_end: f64) -> Option<([f64; N], u64)> {
        let (y, evals) = if t_end == self.t_clear {
            (self.y_clear, 0)
        } else {
            (sys.exact(self.t0, &self.y0)?.at(t_end), 1)
        };
        self.left_off = LeftOff::at(t_end, &y);
        Some((y, evals))
    }
}

/// How close to an edge of the piece [lo, hi] the guard leaves through it: a share of its
/// absolute tolerance `atol`, or a few rounding errors of the edges' values.
pub(super) fn exit_tolerance((lo, hi): (f64, f64), atol: f64) -> f64 {
    let scale = [lo, hi]
        .iter()
        .filter(|b| b.is_finite())
        .fold(0.0f64, |m, b| m.max(b.abs()));
    (OPTIONS.exit_share * atol).max(OPTIONS.min_step_ulps * f64::EPSILON * scale)
}

/// Time before a distance d ≥ 0 can be closed, starting at speed w towards it (negative:
/// away) with an acceleration of at most m: the positive root of d − w s − m s²/2 = 0,
/// infinite if there is none.
fn reach(d: f64, w: f64, m: f64) -> f64 {
    if w > 0.0 {
        2.0 * d / (w + (w * w + 2.0 * m * d).sqrt())
    } else if m > 0.0 {
        (-w + (w * w + 2.0 * m * d).sqrt()) / m
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::System;

    /// g'' = −a cos(ω t) from g = 0.5, g' = 0 in the piece [0, 1]: exact solution
    /// g = 0.5 + a/ω² (cos ωt − 1), g' = −(a/ω) sin ωt, bound a.
    struct Swing {
        a: f64,
        omega: f64,
    }

    impl System<2> for Swing {
        fn rhs(&self, t: f64, y: &[f64; 2]) -> [f64; 2] {
            [y[1], -self.a * (self.omega * t).cos()]
        }
    }

    impl Piecewise<2> for Swing {
        fn guard(_: usize) -> (usize, usize) {
            (0, 1)
        }
        fn piece(&self, _: usize) -> (f64, f64) {
            PIECE
        }
        fn cross(&mut self, _: crate::integrator::Crossing, _: f64, _: &[f64; 2]) {}
    }

    impl ClosedForm<2> for Swing {
        fn at(&self, t: f64) -> [f64; 2] {
            let (a, w) = (self.a, self.omega);
            [
                0.5 + a / (w * w) * ((w * t).cos() - 1.0),
                -(a / w) * (w * t).sin(),
            ]
        }
        fn guard_acceleration_bound(&self) -> f64 {
            self.a
        }
    }

    const PIECE: (f64, f64) = (0.0, 1.0);

    /// A transversal crossing is found where it is, to the tolerance, in a few evaluations.
    #[test]
    fn finds_a_crossing() {
        // g = 0 first where cos ωt = 1 − ω²/(2a): a = 4, ω = 2 → cos 2t = 0.5, t = π/6.
        let swing = Swing { a: 4.0, omega: 2.0 };
        let mut p = Passage::new(0.0, &[0.5, 0.0], &swing);
        let evals = p
            .search::<Swing>(&swing, PIECE, 10.0, 1e-12)
            .expect("found");
        assert_eq!(p.exit, Some(Edge::Lower));
        let t_exact = std::f64::consts::PI / 6.0;
        assert!(
            p.t_clear <= t_exact && t_exact - p.t_clear < 1e-11,
            "{}",
            p.t_clear
        );
        assert!(evals < 40, "{evals} evaluations");
    }

    /// A swing that comes within 1e-9 of the lower bound and turns back is not taken for a
    /// crossing, nor is a deeper one that crosses missed (a sign test between the search's
    /// points would miss it: it dips below 0 for 2e-4 s only).
    #[test]
    fn neither_invents_nor_skips_a_grazing_crossing() {
        // min g = 0.5 − 2a/ω² (at ωt = π).
        let near = Swing {
            a: (0.5 - 1e-9) / 2.0 * 4.0,
            omega: 2.0,
        };
        let mut p = Passage::new(0.0, &[0.5, 0.0], &near);
        p.search::<Swing>(&near, PIECE, 3.0, 1e-12)
            .expect("searched");
        assert_eq!(p.exit, None, "no crossing: the swing turns back 1e-9 short");
        assert!(p.t_clear >= 3.0);

        let dip = Swing {
            a: (0.5 + 1e-8) / 2.0 * 4.0,
            omega: 2.0,
        };
        let mut p = Passage::new(0.0, &[0.5, 0.0], &dip);
        p.search::<Swing>(&dip, PIECE, 3.0, 1e-12)
            .expect("searched");
        assert_eq!(p.exit, Some(Edge::Lower));
        // It crosses just before ωt = π, i.e. t = π/2.
        assert!(
            (p.t_clear - std::f64::consts::FRAC_PI_2).abs() < 1e-3,
            "{}",
            p.t_clear
        );
    }

    #[test]
    fn reach_solves_the_quadratic() {
        for (d, w, m) in [
            (1.0, 0.5, 2.0),
            (0.3, -1.0, 4.0),
            (2.0, 0.0, 1.0),
            (1.0, 2.0, 0.0),
        ] {
            let s = reach(d, w, m);
            assert!(
                (d - w * s - 0.5 * m * s * s).abs() < 1e-12,
                "{d} {w} {m}: {s}"
            );
        }
        assert_eq!(reach(1.0, -1.0, 0.0), f64::INFINITY);
    }
}
