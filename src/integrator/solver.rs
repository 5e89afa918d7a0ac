//! The driver: advances a piecewise-smooth system to an exact end time with adaptive DOPRI5
//! steps, ends steps exactly on the edges of the pieces (so no step straddles a kink), and
//! keeps its step size and controller memory from one call to the next.

use super::control::{Controller, Tolerance};
use super::dopri5::{self, EVALS_PER_STEP};
use super::roots::illinois;
use super::{Dense, Edge, Piecewise};
use serde::{Deserialize, Serialize};

/// Work counters, as DOPRI5 reports them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stats {
    pub rhs_evals: u64,
    pub accepted: u64,
    pub rejected: u64,
    /// Edges crossed (each costs one extra step, ending exactly on the edge).
    pub edges: u64,
}

/// Why the solver stopped short of the end time. The state is left at the last good point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SolverError {
    /// The step size fell below what the time resolution allows.
    StepTooSmall { t: f64, h: f64 },
    /// More steps than allowed for one call.
    TooManySteps { t: f64, steps: u64 },
    /// The state keeps crossing edges without advancing in time.
    Chattering { t: f64 },
}

impl std::fmt::Display for SolverError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SolverError::StepTooSmall { t, h } => {
                write!(
                    f,
                    "step size {h:e} s below the resolution of time at t = {t} s"
                )
            }
            SolverError::TooManySteps { t, steps } => {
                write!(
                    f,
                    "more than {steps} internal steps in one call, at t = {t} s"
                )
            }
            SolverError::Chattering { t } => {
                write!(f, "edge crossings without progress in time at t = {t} s")
            }
        }
    }
}

/// Edge crossings allowed at one instant before the solver gives up.
const MAX_CROSSINGS_AT_ONCE: u32 = 8;

/// Adaptive DOPRI5 with edge location; all of its state is plain data (copyable).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Solver<const N: usize> {
    pub tol: Tolerance<N>,
    /// Most steps one `advance` may take.
    pub max_steps: u64,
    pub stats: Stats,
    /// Step size proposed for the next step (0: not chosen yet).
    h: f64,
    controller: Controller,
    /// f(t, y) at the current point (first stage of the next step), when `k1_valid`.
    #[serde(with = "super::serde_array")]
    k1: [f64; N],
    k1_valid: bool,
    /// An edge was just crossed: the state may lie a rounding error short of it, on the side
    /// of the piece it left, and must not be sent back there.
    just_crossed: bool,
}

impl<const N: usize> Solver<N> {
    pub fn new(tol: Tolerance<N>) -> Self {
        Solver {
            tol,
            max_steps: 10_000_000,
            stats: Stats::default(),
            h: 0.0,
            controller: Controller::default(),
            k1: [0.0; N],
            k1_valid: false,
            just_crossed: false,
        }
    }

    /// To be called when the system or the state changed from outside (new inputs, a jump):
    /// the stored derivative no longer holds.
    pub fn invalidate(&mut self) {
        self.k1_valid = false;
        self.just_crossed = false;
    }

    /// Step size the next step will try.
    pub fn proposed_step(&self) -> f64 {
        self.h
    }

    fn derivative<S: Piecewise<N>>(&mut self, sys: &S, t: f64, y: &[f64; N]) -> [f64; N] {
        if !self.k1_valid {
            self.stats.rhs_evals += 1;
            self.k1 = sys.rhs(t, y);
            self.k1_valid = true;
        }
        self.k1
    }

    /// Advances (t, y) to `t_end` exactly.
    pub fn advance<S: Piecewise<N>>(
        &mut self,
        sys: &mut S,
        t: &mut f64,
        y: &mut [f64; N],
        t_end: f64,
    ) -> Result<(), SolverError> {
        let mut steps = 0u64;
        let mut crossings_here = 0u32;
        while *t < t_end {
            if !self.just_crossed && sys.settle(*t, y) > 0 {
                self.invalidate();
            }
            let k1 = self.derivative(sys, *t, y);
            if self.h <= 0.0 {
                self.h = self.initial_step(sys, *t, y, &k1, t_end - *t);
            }
            // Reach t_end exactly, without leaving a sliver (Hairer's 1.01).
            let last = *t + 1.01 * self.h >= t_end;
            let h = if last { t_end - *t } else { self.h };
            if h <= 16.0 * f64::EPSILON * t.abs().max(t_end.abs()) {
                return Err(SolverError::StepTooSmall { t: *t, h });
            }
            steps += 1;
            if steps > self.max_steps {
                return Err(SolverError::TooManySteps {
                    t: *t,
                    steps: self.max_steps,
                });
            }
            let trial = dopri5::step(sys, *t, y, &k1, h);
            self.stats.rhs_evals += EVALS_PER_STEP;
            let verdict = self
                .controller
                .judge(self.tol.norm(&trial.y0, &trial.y1, &trial.err), h);
            if !verdict.accept {
                self.stats.rejected += 1;
                self.h = verdict.h_next;
                continue;
            }
            self.stats.accepted += 1;
            let (lo, hi) = sys.piece();
            if let Some((edge, theta)) = locate_edge(&trial, (S::GUARD, S::RATE), lo, hi) {
                // Redo the step so that it ends on the edge, then cross it. The state is kept
                // as the step gives it (not moved onto the edge: where the force is not zero
                // there, that would add or remove energy at every crossing).
                if theta > 0.0 {
                    let redo = dopri5::step(sys, *t, y, &k1, theta * h);
                    self.stats.rhs_evals += EVALS_PER_STEP;
                    *y = redo.y1;
                    *t += theta * h;
                    crossings_here = 0;
                } else {
                    crossings_here += 1;
                    if crossings_here > MAX_CROSSINGS_AT_ONCE {
                        return Err(SolverError::Chattering { t: *t });
                    }
                }
                sys.cross(edge, *t, y);
                self.stats.edges += 1;
                self.k1_valid = false;
                self.just_crossed = true;
                self.h = verdict.h_next.max(theta * h);
                continue;
            }
            crossings_here = 0;
            self.just_crossed = false;
            *t = if last { t_end } else { *t + h };
            *y = trial.y1;
            self.k1 = *trial.k_end();
            self.k1_valid = true;
            // A step cut short to land on t_end says little about the natural step size.
            self.h = if last {
                verdict.h_next.max(self.h)
            } else {
                verdict.h_next
            };
        }
        Ok(())
    }

    /// Hairer's starting step: from the sizes of y, f and an estimate of f', capped.
    fn initial_step<S: Piecewise<N>>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64; N],
        f0: &[f64; N],
        h_max: f64,
    ) -> f64 {
        let n = self.tol.controlled;
        let scale = |i: usize| self.tol.atol[i] + self.tol.rtol * y[i].abs();
        let rms = |v: &dyn Fn(usize) -> f64| {
            ((0..n).map(|i| v(i).powi(2)).sum::<f64>() / n as f64).sqrt()
        };
        let dny = rms(&|i| y[i] / scale(i));
        let dnf = rms(&|i| f0[i] / scale(i));
        let mut h = if dny <= 1e-10 || dnf <= 1e-10 {
            1e-6
        } else {
            0.01 * dny / dnf
        };
        h = h.min(h_max);
        let mut y1 = *y;
        for i in 0..N {
            y1[i] += h * f0[i];
        }
        let f1 = sys.rhs(t + h, &y1);
        self.stats.rhs_evals += 1;
        let der2 = rms(&|i| (f1[i] - f0[i]) / scale(i)) / h;
        let der12 = der2.max(dnf);
        let h1 = if der12 <= 1e-15 {
            (h * 1e-3).max(1e-6)
        } else {
            (0.01 / der12).powf(0.2)
        };
        (100.0 * h).min(h1).min(h_max)
    }
}

/// Whether the accepted trial leaves [lo, hi] on its guard component, and where: the edge and
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
