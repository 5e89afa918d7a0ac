//! The driver: advances a piecewise-smooth system to an exact end time, piece by piece, each
//! crossed the way the system says it can be: in closed form ([`Piecewise::exact`], no steps:
//! `passage`), by Taylor-series steps ([`Piecewise::series`]: `taylor`) or by Runge-Kutta
//! steps (`runge_kutta`). Whichever stepper took a step, the driver ends it in one place: on
//! the edge inside it (crossed there, so no step straddles a kink), or on the end time, or
//! kept past the end time. The limits of a call are checked in one place too ([`Budget`]).
//!
//! With `interpolate_ends`, explicit steps run past the end times and serve them from their
//! dense output, so that the trajectory and its cost do not depend on how often the caller
//! asks (communication steps of 10 µs take the steps of 10 ms ones, bit for bit). A passage
//! in closed form serves the end times inside it from the solution itself. Both are kept from
//! one call to the next while the caller continues from where the last call left off.

use super::control::Tolerance;
use super::dopri5;
use super::entries::Entry;
use super::left_off::LeftOff;
use super::options::OPTIONS;
use super::passage::{self, Passage};
use super::radau5::Jacobian;
use super::roots::illinois;
use super::runge_kutta::{Accepted, Mode, RungeKutta};
use super::{Crossing, Dense, Edge, Piecewise, taylor};
use serde::{Deserialize, Serialize};

pub use super::runge_kutta::Method;

/// Work counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stats {
    pub rhs_evals: u64,
    pub accepted: u64,
    pub rejected: u64,
    /// Edges crossed (each costs one extra step, ending exactly on the edge).
    pub edges: u64,
    /// Accepted steps taken by Radau IIA (the others by DOPRI5).
    pub implicit_steps: u64,
    /// Jacobians evaluated and LU decompositions (pairs) made by Radau IIA.
    pub jacobians: u64,
    pub decompositions: u64,
    /// Hand-overs between DOPRI5 and Radau IIA.
    pub switches: u64,
    /// Evaluations of a piece's solution in closed form (the free flight), in place of steps.
    pub exact_evals: u64,
    /// Accepted steps taken by Taylor series ([`taylor`]; counted in `accepted` too).
    pub series_steps: u64,
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
    /// The root search on a piece's exact solution made no headway (a guard creeping along
    /// an edge).
    SearchStalled { t: f64 },
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
            SolverError::SearchStalled { t } => {
                write!(
                    f,
                    "the search for the end of a free flight stalled at t = {t} s"
                )
            }
        }
    }
}

/// The limits of one call of [`Solver::advance`]: steps taken, and edges crossed at the same
/// instant.
#[derive(Default)]
pub(super) struct Budget {
    steps: u64,
    crossings_here: u32,
}

impl Budget {
    /// The next step from t towards t_end, `natural` long (infinite: unbounded): its size
    /// and whether it is cut to end on t_end (not when it may step `past` it). It ends on
    /// t_end, not a sliver before (Hairer's 1.01). Fails when the step is below the
    /// resolution of time or the call has taken too many.
    pub fn step(
        &mut self,
        t: f64,
        t_end: f64,
        natural: f64,
        past: bool,
    ) -> Result<(f64, bool), SolverError> {
        let last = !natural.is_finite() || (!past && t + OPTIONS.sliver * natural >= t_end);
        let h = if last { t_end - t } else { natural };
        if h <= OPTIONS.min_step_ulps * f64::EPSILON * t.abs().max(t_end.abs()) {
            return Err(SolverError::StepTooSmall { t, h });
        }
        self.steps += 1;
        if self.steps > OPTIONS.max_steps {
            return Err(SolverError::TooManySteps {
                t,
                steps: OPTIONS.max_steps,
            });
        }
        Ok((h, last))
    }

    /// An edge crossed at θ of a step from t: with progress in time, or again at the same
    /// instant, which fails after a few times.
    fn crossing(&mut self, t: f64, theta: f64) -> Result<(), SolverError> {
        if theta > 0.0 {
            self.crossings_here = 0;
        } else {
            self.crossings_here += 1;
            if self.crossings_here > OPTIONS.crossings_at_once {
                return Err(SolverError::Chattering { t });
            }
        }
        Ok(())
    }
}

/// An accepted step, whichever stepper took it.
enum Taken<'a, const N: usize> {
    /// A Taylor step, its polynomial its own dense output; cut to end on t_end if `last`.
    Series(&'a taylor::Step<N>, bool),
    /// A DOPRI5 step (in the trial buffer) or a Radau IIA step.
    RungeKutta(Accepted<N>),
}

/// What a call keeps for the next one, to serve end times from if it continues from where
/// this one left off.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
enum Kept<const N: usize> {
    /// An explicit step taken past the end time (`interpolate_ends`).
    Step(Ahead<N>),
    /// The passage through a piece in closed form.
    Passage(Passage<N>),
}

/// Whether a call goes on stepping or has reached its end time.
#[derive(PartialEq)]
enum Flow {
    Go,
    Done,
}

/// An explicit step taken past the end time of a call ([`Solver::interpolate_ends`]): the end
/// times inside it come from its dense output, and stepping resumes from its end.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct Ahead<const N: usize> {
    t0: f64,
    h: f64,
    /// The step's dense output.
    dense: Interpolant<N>,
    #[serde(with = "super::serde_array")]
    y1: [f64; N],
    /// The edge the step ends on, to be crossed when a call goes past it.
    edge: Option<Crossing>,
    /// What the caller was given last.
    left_off: LeftOff<N>,
}

impl<const N: usize> Ahead<N> {
    /// Where the kept step ends.
    fn t1(&self) -> f64 {
        self.t0 + self.h
    }

    /// The state at t_end inside the step, remembered as handed out.
    fn serve(&mut self, t_end: f64) -> [f64; N] {
        let y = self.dense.at((t_end - self.t0) / self.h);
        self.left_off = LeftOff::at(t_end, &y);
        y
    }
}

/// The dense output of a kept step, whichever explicit method took it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
enum Interpolant<const N: usize> {
    Dopri5(dopri5::Continuous<N>),
    Taylor(taylor::Step<N>),
}

impl<const N: usize> Interpolant<N> {
    #[inline]
    fn at(&self, theta: f64) -> [f64; N] {
        match self {
            Interpolant::Dopri5(c) => c.at(theta),
            Interpolant::Taylor(s) => s.at(theta),
        }
    }
}

/// The driver over a piecewise system's pieces, with edge location; all of its state is
/// plain data (copyable, part of the FMU state).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Solver<const N: usize> {
    tol: Tolerance<N>,
    /// End times of `advance` are reached by interpolation inside the explicit steps'
    /// natural lengths (their dense output) instead of by steps cut short to end on them:
    /// the trajectory, and its cost, are then those of a run without those end times, however
    /// close together they are. For systems that do not change between calls (the bench's
    /// sine); a caller that changes the system must call `invalidate`.
    pub interpolate_ends: bool,
    pub stats: Stats,
    rk: RungeKutta<N>,
    /// An edge was just crossed: the state may lie a rounding error short of it, on the side
    /// of the piece it left, and must not be sent back there.
    just_crossed: bool,
    kept: Option<Kept<N>>,
}

impl<const N: usize> Solver<N> {
    /// A solver choosing its method by itself ([`Method::Auto`]).
    pub fn new(tol: Tolerance<N>) -> Self {
        Self::with_method(tol, Method::Auto)
    }

    pub fn with_method(tol: Tolerance<N>, method: Method) -> Self {
        Solver {
            tol,
            interpolate_ends: false,
            stats: Stats::default(),
            rk: RungeKutta::new(tol, method),
            just_crossed: false,
            kept: None,
        }
    }

    /// True while Radau IIA steps.
    pub fn is_implicit(&self) -> bool {
        self.rk.mode == Mode::Radau
    }

    /// Step size the next step will try.
    pub fn proposed_step(&self) -> f64 {
        self.rk.h
    }

    /// To be called when the system or the state changed from outside (new inputs, a jump):
    /// the stored derivative, Jacobian and extrapolations no longer hold.
    pub fn invalidate(&mut self) {
        self.rk.invalidate();
        self.just_crossed = false;
        self.kept = None;
    }

    /// Moves (t, y) to t_end inside the step or the passage kept from the last call, if that
    /// call left off at (t, y) and what was kept reaches t_end: no stepping or search, so it
    /// cannot fail. False, with nothing changed, otherwise.
    pub fn serve<S: Piecewise<N>>(
        &mut self,
        sys: &mut S,
        t: &mut f64,
        y: &mut [f64; N],
        t_end: f64,
    ) -> bool {
        let served = match &mut self.kept {
            Some(Kept::Step(a)) if a.left_off.continued_by(*t, y) && t_end <= a.t1() => {
                Some((a.serve(t_end), 0))
            }
            Some(Kept::Passage(p)) if p.continued_by(*t, y) && t_end <= p.t_clear => {
                p.serve(sys, t_end)
            }
            _ => None,
        };
        let Some((y_end, evals)) = served else {
            return false;
        };
        (*t, *y) = (t_end, y_end);
        self.stats.exact_evals += evals;
        true
    }

    /// Advances (t, y) to `t_end` exactly.
    pub fn advance<S: Piecewise<N> + Jacobian<N>>(
        &mut self,
        sys: &mut S,
        t: &mut f64,
        y: &mut [f64; N],
        t_end: f64,
    ) -> Result<(), SolverError> {
        if self.serve(sys, t, y, t_end) {
            return Ok(());
        }
        self.resume(sys, t, y);
        let mut budget = Budget::default();
        // The DOPRI5 steps are written here in place (see `dopri5::step`), the series too.
        let mut trial = dopri5::Trial::empty();
        let mut series = [[0.0; N]; taylor::TERMS];
        while *t < t_end {
            if !self.just_crossed && sys.settle(*t, y) > 0 {
                self.invalidate();
            }
            if let Some(flow) = self.pass(sys, t, y, t_end)? {
                match flow {
                    Flow::Go => continue,
                    Flow::Done => return Ok(()),
                }
            }
            let past = self.interpolate_ends && self.rk.mode == Mode::Dopri5;
            let series_step;
            let step = if self.rk.mode == Mode::Dopri5 && sys.series(*t, y, &mut series) {
                let natural = taylor::Step::length(&series, &self.tol);
                let (h, last) = budget.step(*t, t_end, natural, past)?;
                series_step = taylor::Step::new(series, h);
                sys.observe(*t, h, &series_step);
                self.stats.accepted += 1;
                self.stats.series_steps += 1;
                self.rk.stepped_by_series();
                Taken::Series(&series_step, last)
            } else {
                let rough = self.just_crossed && sys.rough_start();
                let work = (&self.tol, &mut self.stats, &mut budget);
                match self
                    .rk
                    .attempt(sys, work, (*t, y), t_end, past, rough, &mut trial)?
                {
                    Some(accepted) => Taken::RungeKutta(accepted),
                    None => continue,
                }
            };
            let flow = self.end_step(sys, &step, (t, y), t_end, past, &mut budget, &mut trial)?;
            if flow == Flow::Done {
                return Ok(());
            }
        }
        Ok(())
    }

    /// At the start of a call: from the end of the step kept by the last one if the call
    /// continues from where that left off (crossing the edge it ends on), else without it.
    fn resume<S: Piecewise<N>>(&mut self, sys: &mut S, t: &mut f64, y: &mut [f64; N]) {
        let Some(Kept::Step(ahead)) = &self.kept else {
            return;
        };
        let (continued, t1, y1, edge) = (
            ahead.left_off.continued_by(*t, y),
            ahead.t1(),
            ahead.y1,
            ahead.edge,
        );
        self.kept = None;
        if !continued {
            // f is known at the kept step's end, not here.
            self.rk.moved();
            return;
        }
        (*t, *y) = (t1, y1);
        if let Some(edge) = edge {
            self.cross(sys, edge, *t, y);
        }
    }

    /// Through a piece in closed form (see `passage`): to t_end, where the passage is kept
    /// for the next call (Done), or to where the solution leaves the piece, crossing that
    /// edge (Go). None if the piece has no closed form.
    fn pass<S: Piecewise<N>>(
        &mut self,
        sys: &mut S,
        t: &mut f64,
        y: &mut [f64; N],
        t_end: f64,
    ) -> Result<Option<Flow>, SolverError> {
        let continued = match self.kept {
            Some(Kept::Passage(p)) if p.continued_by(*t, y) => Some(p),
            _ => None,
        };
        let (t0, y0) = continued.map_or((*t, *y), |p| (p.t0, p.y0));
        let piece = sys.piece(0);
        let Some(exact) = sys.exact(t0, &y0) else {
            return Ok(None);
        };
        let mut passage = continued.unwrap_or_else(|| Passage::new(t0, &y0, &exact));
        self.kept = None;
        let tol = passage::exit_tolerance(piece, self.tol.atol[S::guard(0).0]);
        let evals = passage
            .search::<S>(&exact, piece, t_end, tol)
            .ok_or(SolverError::SearchStalled { t: *t })?;
        self.stats.exact_evals += evals;
        drop(exact);
        match passage.exit {
            Some(edge) if passage.t_clear <= t_end => {
                *t = passage.t_clear;
                *y = passage.y_clear;
                self.cross(sys, Crossing { guard: 0, edge }, *t, y);
                Ok(Some(Flow::Go))
            }
            _ => {
                if let Some((y_end, evals)) = passage.serve(sys, t_end) {
                    (*t, *y) = (t_end, y_end);
                    self.stats.exact_evals += evals;
                }
                self.kept = Some(Kept::Passage(passage));
                Ok(Some(Flow::Done))
            }
        }
    }

    /// Ends an accepted step from (t, y): on the edge it leaves its piece through, which is
    /// then crossed; else at its end, or on t_end if it was cut short to; else, reaching past
    /// t_end, kept for the next call with t_end served from it (ending on the edge past
    /// t_end, if any, crossed when a call goes past it).
    ///
    /// An edge is reached by redoing the Runge-Kutta step to end on it, and on the Taylor
    /// step's own polynomial. The state is kept as the step gives it (not moved onto the
    /// edge: where the force is not zero there, that would add or remove energy at every
    /// crossing).
    #[allow(clippy::too_many_arguments)]
    fn end_step<S: Piecewise<N> + Jacobian<N>>(
        &mut self,
        sys: &mut S,
        step: &Taken<N>,
        (t, y): (&mut f64, &mut [f64; N]),
        t_end: f64,
        past: bool,
        budget: &mut Budget,
        trial: &mut dopri5::Trial<N>,
    ) -> Result<Flow, SolverError> {
        let (h, y1, edge) = match step {
            Taken::Series(s, _) => (s.h, s.y1, locate_crossing(sys, *s)),
            Taken::RungeKutta(a) => (a.h, a.y1, a.edge),
        };
        let work = (&self.tol, &mut self.stats);
        if let Some((edge, theta)) = edge {
            if past && *t + theta * h > t_end {
                let (dense, h_kept, y_kept) = match step {
                    Taken::Series(s, _) => {
                        let kept = s.cut(theta);
                        (Interpolant::Taylor(kept), kept.h, kept.y1)
                    }
                    Taken::RungeKutta(a) => {
                        // Stepping past t_end, the step is DOPRI5's.
                        self.rk.redo(sys, work, (*t, y), a, theta, trial);
                        self.rk.ended_on_edge(a, theta);
                        (Interpolant::Dopri5(trial.continuous()), trial.h, trial.y1)
                    }
                };
                self.keep(dense, h_kept, y_kept, Some(edge), (t, y), t_end);
                return Ok(Flow::Done);
            }
            if theta > 0.0 {
                *y = match step {
                    Taken::Series(s, _) => s.at(theta),
                    Taken::RungeKutta(a) => {
                        match self.rk.redo(sys, work, (*t, y), a, theta, trial) {
                            Some(y_edge) => y_edge,
                            None => return Ok(Flow::Go),
                        }
                    }
                };
                *t += theta * h;
            }
            budget.crossing(*t, theta)?;
            self.cross(sys, edge, *t, y);
            if let Taken::RungeKutta(a) = step {
                self.rk.ended_on_edge(a, theta);
            }
            return Ok(Flow::Go);
        }
        budget.crossings_here = 0;
        self.just_crossed = false;
        let last = match step {
            Taken::Series(_, last) => *last,
            Taken::RungeKutta(a) => {
                self.rk.ended_inside(a, trial, &mut self.stats);
                a.last
            }
        };
        if past && *t + h > t_end {
            let dense = match step {
                Taken::Series(s, _) => Interpolant::Taylor(**s),
                Taken::RungeKutta(_) => Interpolant::Dopri5(trial.continuous()),
            };
            self.keep(dense, h, y1, None, (t, y), t_end);
            return Ok(Flow::Done);
        }
        *t = if last { t_end } else { *t + h };
        *y = y1;
        Ok(Flow::Go)
    }

    /// Crosses `edge` at (t, y): the system changes piece, and what was known of the old one
    /// goes.
    fn cross<S: Piecewise<N>>(&mut self, sys: &mut S, edge: Crossing, t: f64, y: &[f64; N]) {
        sys.cross(edge, t, y);
        let (lo, hi) = sys.piece(edge.guard);
        self.rk.entered(Entry {
            lo,
            hi,
            through: edge,
        });
        self.stats.edges += 1;
        self.just_crossed = true;
    }

    /// Keeps a step from (t, y) of length h to y1 that reaches past t_end (ending on `edge`,
    /// if any) and hands out (t_end, y(t_end)) from its dense output.
    fn keep(
        &mut self,
        dense: Interpolant<N>,
        h: f64,
        y1: [f64; N],
        edge: Option<Crossing>,
        (t, y): (&mut f64, &mut [f64; N]),
        t_end: f64,
    ) {
        let mut ahead = Ahead {
            t0: *t,
            h,
            dense,
            y1,
            edge,
            left_off: LeftOff::at(t_end, y),
        };
        (*t, *y) = (t_end, ahead.serve(t_end));
        self.kept = Some(Kept::Step(ahead));
    }
}

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
