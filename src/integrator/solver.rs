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
use super::edges::locate_crossing;
use super::entries::Entry;
use super::left_off::{LeftOff, same_time};
use super::passage::{self, Passage};
use super::radau5::Jacobian;
use super::runge_kutta::{Accepted, Mode, RungeKutta};
use super::work::Call;
use super::{Crossing, Dense, Piecewise, taylor};
use serde::{Deserialize, Serialize};

pub use super::runge_kutta::Method;
pub use super::work::{SolverError, Stats, resolution};

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
    /// The step from t0 of length h to y1 (ending on `edge`, if any), with its dense output;
    /// what the caller is given is recorded by the first `serve`.
    fn new(t0: f64, h: f64, dense: Interpolant<N>, y1: [f64; N], edge: Option<Crossing>) -> Self {
        Ahead {
            t0,
            h,
            dense,
            y1,
            edge,
            left_off: LeftOff::at(t0, &y1),
        }
    }

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

    /// Component i of [`at`](Self::at), to the bit.
    #[inline]
    fn component(&self, i: usize, theta: f64) -> f64 {
        match self {
            Interpolant::Dopri5(c) => c.component(i, theta),
            Interpolant::Taylor(s) => s.dense(i, theta),
        }
    }

    /// Whether every component stays finite throughout the step (with a margin for the
    /// rounding of θ at its ends).
    fn finite_throughout(&self) -> bool {
        let bound = f64::MAX / 4.0;
        match self {
            Interpolant::Dopri5(c) => c.bounded(bound),
            Interpolant::Taylor(s) => s.bounded(bound),
        }
    }
}

/// The state at the end of a call served by [`Solver::serve_run`], read component by
/// component from the kept step's dense output: only the components read are computed.
pub struct Point<'a, const N: usize> {
    dense: &'a Interpolant<N>,
    theta: f64,
}

impl<const N: usize> Point<'_, N> {
    /// Component i of the state there, to the bit as a call of `advance` ending there has it.
    #[inline]
    pub fn component(&self, i: usize) -> f64 {
        self.dense.component(i, self.theta)
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

    /// The error weights, which a caller may change between calls (a component weighted 0 by
    /// an infinite atol: examples/free_flight_bound.rs).
    pub fn tolerance_mut(&mut self) -> &mut Tolerance<N> {
        &mut self.tol
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

    /// The calls of `advance` from each `from` to its `to` in `calls` (each continuing where
    /// the one before ends), as far as the step kept by the last call reaches: each served
    /// from its dense output, to the bit as `advance` would, with no stepping or search, so
    /// none can fail and the counters do not move. `read` reads the state at the end of each
    /// (through [`Point::component`]) and says whether to take it; the first call not
    /// served, or not taken, ends the run. Returns how many were taken, (t, y) at the end of
    /// the last one as `advance` leaves them. None where no step is kept (a passage in
    /// closed form serves its end times the ordinary way), or where its dense output might
    /// not stay finite (the ordinary call then finds out).
    pub fn serve_run<S>(
        &mut self,
        sys: &S,
        t: &mut f64,
        y: &mut [f64; N],
        calls: impl Iterator<Item = (f64, f64)>,
        mut read: impl FnMut(&S, Point<N>) -> bool,
    ) -> usize {
        let Some(Kept::Step(a)) = &mut self.kept else {
            return 0;
        };
        // Where the last call taken ends.
        let (mut left, mut taken) = (None, 0);
        for (from, to) in calls {
            let continued = match left {
                None => a.left_off.continued_by(from, y) && a.dense.finite_throughout(),
                Some(left) => same_time(left, from),
            };
            if !(continued && to <= a.t1()) {
                break;
            }
            let theta = (to - a.t0) / a.h;
            if !read(
                sys,
                Point {
                    dense: &a.dense,
                    theta,
                },
            ) {
                break;
            }
            (left, taken) = (Some(to), taken + 1);
        }
        if let Some(left) = left {
            (*t, *y) = (left, a.serve(left));
        }
        taken
    }

    /// Advances (t, y) to `t_end` exactly.
    pub fn advance<S: Piecewise<N> + Jacobian<N>>(
        &mut self,
        sys: &mut S,
        t: &mut f64,
        y: &mut [f64; N],
        t_end: f64,
    ) -> Result<(), SolverError> {
        self.advance_until(sys, t, y, t_end, |_| 0).map(|_| ())
    }

    /// Advances (t, y) towards `t_end` as [`advance`](Self::advance) does, and stops on the
    /// first edge whose crossing raises the system's count of `events` (a gear pair's
    /// impacts): true if it stopped there, (t, y) at the edge as located, false at t_end. Up
    /// to the stop the trajectory is `advance`'s, to the bit; the next call continues from
    /// the edge, just crossed.
    pub fn advance_until<S: Piecewise<N> + Jacobian<N>>(
        &mut self,
        sys: &mut S,
        t: &mut f64,
        y: &mut [f64; N],
        t_end: f64,
        events: impl Fn(&S) -> u64,
    ) -> Result<bool, SolverError> {
        if self.serve(sys, t, y, t_end) {
            return Ok(false);
        }
        let mut seen = events(sys);
        self.resume(sys, t, y);
        if events(sys) != seen {
            return Ok(true);
        }
        let t_start = *t;
        let mut call = Call::new(t_end);
        // The Taylor steps are written here in place, the DOPRI5 steps in `call.trial`.
        let mut series = taylor::Step::blank();
        while *t < t_end {
            if !self.just_crossed && sys.settle(*t, y) > 0 {
                self.invalidate();
                // Edges crossed where the call starts (the state moved from outside) are no
                // event to stop at.
                if *t == t_start {
                    seen = events(sys);
                }
            }
            if let Some(flow) = self.pass(sys, t, y, t_end)? {
                match flow {
                    Flow::Go if events(sys) != seen => return Ok(true),
                    Flow::Go => continue,
                    Flow::Done => return Ok(false),
                }
            }
            call.past = self.interpolate_ends && self.rk.mode == Mode::Dopri5;
            let step = if self.rk.mode == Mode::Dopri5 && sys.series(*t, y, series.series_mut()) {
                let natural = taylor::Step::length(series.series(), &self.tol);
                let (h, last) = call.budget.step(*t, t_end, natural, call.past)?;
                series.set_length(h);
                sys.observe(*t, h, &series);
                self.stats.accepted += 1;
                self.stats.series_steps += 1;
                self.rk.stepped_by_series();
                Taken::Series(&series, last)
            } else {
                let rough = self.just_crossed && sys.rough_start();
                let attempt =
                    self.rk
                        .attempt(sys, &self.tol, &mut self.stats, (*t, y), &mut call, rough)?;
                match attempt {
                    Some(accepted) => Taken::RungeKutta(accepted),
                    None => continue,
                }
            };
            if self.end_step(sys, &step, t, y, &mut call)? == Flow::Done {
                return Ok(false);
            }
            if events(sys) != seen {
                return Ok(true);
            }
        }
        Ok(false)
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
    fn end_step<S: Piecewise<N> + Jacobian<N>>(
        &mut self,
        sys: &mut S,
        step: &Taken<N>,
        t: &mut f64,
        y: &mut [f64; N],
        call: &mut Call<N>,
    ) -> Result<Flow, SolverError> {
        let (h, y1, edge) = match step {
            Taken::Series(s, _) => (s.h, s.y1, locate_crossing(sys, *s)),
            Taken::RungeKutta(a) => (a.h, a.y1, a.edge),
        };
        let (t_end, past) = (call.t_end, call.past);
        let trial = &mut call.trial;
        if let Some((edge, theta)) = edge {
            if past && *t + theta * h > t_end {
                let (dense, h_kept, y_kept) = match step {
                    Taken::Series(s, _) => {
                        let kept = s.cut(theta);
                        (Interpolant::Taylor(kept), kept.h, kept.y1)
                    }
                    Taken::RungeKutta(a) => {
                        // Stepping past t_end, the step is DOPRI5's.
                        self.redo(sys, (*t, y), a, theta, trial);
                        self.rk.ended_on_edge(a, theta);
                        (Interpolant::Dopri5(trial.continuous()), trial.h, trial.y1)
                    }
                };
                let ahead = Ahead::new(*t, h_kept, dense, y_kept, Some(edge));
                self.keep(ahead, t, y, t_end);
                return Ok(Flow::Done);
            }
            if theta > 0.0 {
                *y = match step {
                    Taken::Series(s, _) => s.at(theta),
                    Taken::RungeKutta(a) => match self.redo(sys, (*t, y), a, theta, trial) {
                        Some(y_edge) => y_edge,
                        None => return Ok(Flow::Go),
                    },
                };
                *t += theta * h;
            }
            call.budget.crossing(*t, theta)?;
            self.cross(sys, edge, *t, y);
            if let Taken::RungeKutta(a) = step {
                self.rk.ended_on_edge(a, theta);
            }
            return Ok(Flow::Go);
        }
        call.budget.advanced();
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
            self.keep(Ahead::new(*t, h, dense, y1, None), t, y, t_end);
            return Ok(Flow::Done);
        }
        *t = if last { t_end } else { *t + h };
        *y = y1;
        Ok(Flow::Go)
    }

    /// The accepted Runge-Kutta `step` from (t, y) redone to end at θ, on the edge inside it
    /// (see [`RungeKutta::redo`]).
    fn redo<S: Piecewise<N> + Jacobian<N>>(
        &mut self,
        sys: &S,
        (t, y): (f64, &[f64; N]),
        step: &Accepted<N>,
        theta: f64,
        trial: &mut dopri5::Trial<N>,
    ) -> Option<[f64; N]> {
        let h = theta * step.h;
        self.rk
            .redo(sys, &self.tol, &mut self.stats, (t, y), h, trial)
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

    /// Keeps a step that reaches past t_end and hands out (t_end, y(t_end)) from its dense
    /// output.
    #[inline]
    fn keep(&mut self, ahead: Ahead<N>, t: &mut f64, y: &mut [f64; N], t_end: f64) {
        let Kept::Step(kept) = self.kept.insert(Kept::Step(ahead)) else {
            unreachable!("a step was just kept");
        };
        (*t, *y) = (t_end, kept.serve(t_end));
    }
}
