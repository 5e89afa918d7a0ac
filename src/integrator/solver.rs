//! The driver: advances a piecewise-smooth system to an exact end time with adaptive steps,
//! ends steps exactly on the edges of the pieces (so no step straddles a kink), and keeps its
//! step size, method and controllers' memory from one call to the next.
//!
//! With `interpolate_ends`, explicit steps run past the end times and serve them from their
//! dense output, so that the trajectory and its cost do not depend on how often the caller
//! asks (communication steps of 10 µs take the steps of 10 ms ones, bit for bit).
//!
//! A piece with a solution in closed form ([`Piecewise::exact`]) is crossed without
//! steps: `passage` searches where that solution leaves the piece, and serves the end times
//! inside it from the solution itself.
//!
//! The method is DOPRI5, with Taylor-series steps in the pieces whose series the system gives
//! ([`Piecewise::series`], `series_step`), or Radau IIA while the problem is stiff
//! ([`Method::Auto`], the rule in `stiffness`), or either one throughout. Edges are located the same way on both methods'
//! dense outputs. A non-stiff run pays for the implicit side only Hairer's stiffness
//! estimate per accepted step (two weighted norms of the stages DOPRI5 has computed anyway).

use super::control::{Controller, Tolerance};
use super::dopri5::{self, EVALS_PER_STEP};
use super::entries::{Entries, Entry};
use super::left_off::LeftOff;
use super::options::OPTIONS;
use super::passage::{self, Passage};
use super::radau5::{Jacobian, RadauTrial, Stepper};
use super::roots::illinois;
use super::stiffness::{Switch, spectral_radius, stiffness};
use super::{Dense, Edge, Piecewise, taylor};
use serde::{Deserialize, Serialize};

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

/// Which method steps (the FMU's `solver` parameter).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Method {
    /// DOPRI5, handing over to Radau IIA while the problem is stiff.
    #[default]
    Auto,
    /// DOPRI5 throughout.
    Explicit,
    /// Radau IIA throughout.
    Implicit,
}

/// An accepted step, whichever method took it.
struct Accepted<const N: usize> {
    y1: [f64; N],
    /// Taken by DOPRI5: the trial buffer holds the step (its last stage is f(t + h, y1); its
    /// dense output serves the points inside it). False for Radau IIA.
    explicit: bool,
    h_next: f64,
    /// The edge the step leaves its piece through, and at which fraction of the step.
    edge: Option<(Edge, f64)>,
    /// DOPRI5's stiffness estimate h·ρ of the step (0 when not asked for).
    h_rho: f64,
}

/// A DOPRI5 step taken past the end time of a call ([`Solver::interpolate_ends`]): the end
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
    edge: Option<Edge>,
    /// What the caller was given last.
    left_off: LeftOff<N>,
}

impl<const N: usize> Ahead<N> {
    /// Where the kept step ends.
    fn t1(&self) -> f64 {
        self.t0 + self.h
    }

    fn continued_by(&self, t: f64, y: &[f64; N]) -> bool {
        self.left_off.continued_by(t, y)
    }

    /// (t, y) at t_end inside the step, handed out and remembered.
    fn serve(&mut self, t: &mut f64, y: &mut [f64; N], t_end: f64) {
        *y = self.dense.at((t_end - self.t0) / self.h);
        *t = t_end;
        self.left_off = LeftOff::at(t_end, y);
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

/// Where a step starts: t, y and f(t, y).
#[derive(Clone, Copy)]
struct Start<'a, const N: usize> {
    t: f64,
    y: &'a [f64; N],
    k1: &'a [f64; N],
}

/// Adaptive DOPRI5 / Radau IIA with edge location; all of its state is plain data (copyable).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Solver<const N: usize> {
    tol: Tolerance<N>,
    /// Most steps one `advance` may take.
    pub max_steps: u64,
    /// End times of `advance` are reached by interpolation inside DOPRI5's natural steps
    /// (4th-order dense output) instead of by steps cut short to end on them: the
    /// trajectory, and its cost, are then those of a run without those end times, however
    /// close together they are. For systems that do not change between calls (the bench's
    /// sine); a caller that changes the system must call `invalidate`.
    pub interpolate_ends: bool,
    pub stats: Stats,
    method: Method,
    /// Radau IIA is stepping now.
    implicit: bool,
    /// Step size proposed for the next step (0: not chosen yet).
    h: f64,
    controller: Controller,
    stepper: Stepper<N>,
    switch: Switch,
    /// Spectral radius of Radau's latest Jacobian, and that Jacobian's number.
    rho: f64,
    rho_of: u64,
    /// f(t, y) at the current point (first stage of the next step), when `k1_valid`.
    #[serde(with = "super::serde_array")]
    k1: [f64; N],
    k1_valid: bool,
    /// An edge was just crossed: the state may lie a rounding error short of it, on the side
    /// of the piece it left, and must not be sent back there.
    just_crossed: bool,
    ahead: Option<Ahead<N>>,
    /// The passage through a piece with an exact solution, kept from the last call.
    passage: Option<Passage<N>>,
    /// The piece just entered, until its first DOPRI5 step is judged, and what was learnt
    /// of the first steps into each piece (see `entries`).
    entering: Option<Entry>,
    entries: Entries,
}

impl<const N: usize> Solver<N> {
    /// A solver choosing its method by itself ([`Method::Auto`]).
    pub fn new(tol: Tolerance<N>) -> Self {
        Self::with_method(tol, Method::Auto)
    }

    pub fn with_method(tol: Tolerance<N>, method: Method) -> Self {
        Solver {
            tol,
            max_steps: OPTIONS.max_steps,
            interpolate_ends: false,
            stats: Stats::default(),
            method,
            implicit: method == Method::Implicit,
            h: 0.0,
            controller: Controller::default(),
            stepper: Stepper::new(tol),
            switch: Switch::default(),
            rho: 0.0,
            rho_of: 0,
            k1: [0.0; N],
            k1_valid: false,
            just_crossed: false,
            ahead: None,
            passage: None,
            entering: None,
            entries: Entries::default(),
        }
    }

    pub fn tolerance(&self) -> &Tolerance<N> {
        &self.tol
    }

    /// True while Radau IIA steps.
    pub fn is_implicit(&self) -> bool {
        self.implicit
    }

    /// To be called when the system or the state changed from outside (new inputs, a jump):
    /// the stored derivative, Jacobian and extrapolations no longer hold.
    pub fn invalidate(&mut self) {
        self.k1_valid = false;
        self.just_crossed = false;
        self.ahead = None;
        self.passage = None;
        self.stepper.invalidate();
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
        if let Some(a) = &mut self.ahead
            && a.continued_by(*t, y)
            && t_end <= a.t1()
        {
            a.serve(t, y, t_end);
            return true;
        }
        if let Some(p) = &mut self.passage
            && p.continued_by(*t, y)
            && t_end <= p.t_clear
        {
            let (t0, y0) = (p.t0, p.y0);
            if let Some(exact) = sys.exact(t0, &y0) {
                self.stats.exact_evals += p.serve(&exact, t, y, t_end);
                return true;
            }
        }
        false
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
        if let Some(ahead) = self.ahead.take() {
            if !ahead.continued_by(*t, y) {
                // Not where the last call left off: k1 was f at the step's end.
                self.k1_valid = false;
            } else {
                *t = ahead.t1();
                *y = ahead.y1;
                if let Some(edge) = ahead.edge {
                    self.cross(sys, edge, *t, y);
                }
            }
        }
        let mut steps = 0u64;
        let mut crossings_here = 0u32;
        // The DOPRI5 steps are written here in place (see `dopri5::step`), the series too.
        let mut trial = dopri5::Trial::empty();
        let mut series = [[0.0; N]; taylor::TERMS];
        while *t < t_end {
            if !self.just_crossed && sys.settle(*t, y) > 0 {
                self.invalidate();
            }
            if let Some(passed) = self.pass(sys, t, y, t_end)? {
                if passed {
                    continue;
                }
                return Ok(());
            }
            if !self.implicit && sys.series(*t, y, &mut series) {
                steps += 1;
                if steps > self.max_steps {
                    return Err(SolverError::TooManySteps {
                        t: *t,
                        steps: self.max_steps,
                    });
                }
                if self.series_step(sys, &series, t, y, t_end, &mut crossings_here)? {
                    continue;
                }
                return Ok(());
            }
            let k1 = self.derivative(sys, *t, y);
            if self.h <= 0.0 {
                // Capped by the call's length only where steps end on t_end: with
                // `interpolate_ends` the first step must not depend on the end time asked
                // for, or neither would the trajectory.
                let h_max = if self.interpolate_ends && !self.implicit {
                    f64::INFINITY
                } else {
                    t_end - *t
                };
                self.h = self.initial_step(sys, *t, y, &k1, h_max);
            }
            // The first DOPRI5 step into a piece just entered starts from what was learnt of
            // that piece's entries, as a ratio to a base: the time to cross the piece at the
            // guard's rate where the piece is bounded (a band: ε/|ξ'|, whatever step the
            // free flight or the contact before it left), else the step carried over the edge.
            let entering = match self.entering.take() {
                Some(entry) if !self.implicit => {
                    let rate = y[S::RATE].abs();
                    let width = entry.hi - entry.lo;
                    let base = if width.is_finite() && rate > 0.0 {
                        width / rate
                    } else {
                        self.h
                    };
                    self.h = base * self.entries.ratio(&entry);
                    Some((entry, base))
                }
                _ => None,
            };
            // Reach t_end exactly, without leaving a sliver (Hairer's 1.01), or step past it.
            let step_past = self.interpolate_ends && !self.implicit;
            let last = !step_past && *t + OPTIONS.sliver * self.h >= t_end;
            let h = if last { t_end - *t } else { self.h };
            if h <= OPTIONS.min_step_ulps * f64::EPSILON * t.abs().max(t_end.abs()) {
                return Err(SolverError::StepTooSmall { t: *t, h });
            }
            steps += 1;
            if steps > self.max_steps {
                return Err(SolverError::TooManySteps {
                    t: *t,
                    steps: self.max_steps,
                });
            }
            let start = Start { t: *t, y, k1: &k1 };
            let attempt = self.attempt(sys, start, h, &mut trial);
            if let Some((entry, carried)) = entering {
                let wanted = attempt.as_ref().map_or_else(|h_next| *h_next, |s| s.h_next);
                self.entries.learn(&entry, carried, wanted);
            }
            let step = match attempt {
                Ok(step) => step,
                Err(h_next) => {
                    self.stats.rejected += 1;
                    self.h = h_next;
                    continue;
                }
            };
            self.stats.accepted += 1;
            if self.implicit {
                self.stats.implicit_steps += 1;
            }
            if let Some((edge, theta)) = step.edge
                && step_past
                && *t + theta * h > t_end
            {
                // The edge lies past t_end: the step redone to end on it is kept ahead, t_end
                // served from it, and the edge crossed when a call goes past it.
                self.explicit_step(sys, start, theta * h, &mut trial);
                self.h = step.h_next.max(theta * h);
                self.keep_ahead(&trial, Some(edge), t, y, t_end);
                return Ok(());
            }
            if let Some((edge, theta)) = step.edge {
                // Redo the step so that it ends on the edge, then cross it. The state is kept
                // as the step gives it (not moved onto the edge: where the force is not zero
                // there, that would add or remove energy at every crossing).
                if theta > 0.0 {
                    let Some(y_edge) = self.redo(sys, start, theta * h, &mut trial) else {
                        self.h = 0.5 * theta * h;
                        continue;
                    };
                    *y = y_edge;
                    *t += theta * h;
                    crossings_here = 0;
                } else {
                    crossings_here += 1;
                    if crossings_here > OPTIONS.crossings_at_once {
                        return Err(SolverError::Chattering { t: *t });
                    }
                }
                self.cross(sys, edge, *t, y);
                self.h = step.h_next.max(theta * h);
                continue;
            }
            crossings_here = 0;
            self.just_crossed = false;
            if step.explicit {
                self.k1 = *trial.k_end();
            } else {
                self.k1_valid = false;
            }
            if step.explicit && step_past && *t + h > t_end {
                self.h = step.h_next;
                self.hand_over(step.h_rho);
                self.keep_ahead(&trial, None, t, y, t_end);
                return Ok(());
            }
            *t = if last { t_end } else { *t + h };
            *y = step.y1;
            // A step cut short to land on t_end says little about the natural step size.
            self.h = if last {
                step.h_next.max(self.h)
            } else {
                step.h_next
            };
            self.hand_over(step.h_rho);
        }
        Ok(())
    }

    /// Through a piece in closed form (see `passage`): to t_end, where the passage is kept
    /// for the next call (false), or to where the solution leaves the piece, crossing that
    /// edge (true). None if the piece has no closed form.
    fn pass<S: Piecewise<N>>(
        &mut self,
        sys: &mut S,
        t: &mut f64,
        y: &mut [f64; N],
        t_end: f64,
    ) -> Result<Option<bool>, SolverError> {
        let continued = match self.passage {
            Some(p) if p.continued_by(*t, y) => Some(p),
            _ => None,
        };
        let (t0, y0) = continued.map_or((*t, *y), |p| (p.t0, p.y0));
        let piece = sys.piece();
        let Some(exact) = sys.exact(t0, &y0) else {
            return Ok(None);
        };
        let mut passage = continued.unwrap_or_else(|| Passage::new(t0, &y0, &exact));
        self.passage = None;
        let tol = passage::exit_tolerance(piece, self.tol.atol[S::GUARD]);
        let evals = passage
            .search::<S>(&exact, piece, t_end, tol)
            .ok_or(SolverError::SearchStalled { t: *t })?;
        self.stats.exact_evals += evals;
        match passage.exit {
            Some(edge) if passage.t_clear <= t_end => {
                drop(exact);
                *t = passage.t_clear;
                *y = passage.y_clear;
                self.cross(sys, edge, *t, y);
                Ok(Some(true))
            }
            _ => {
                self.stats.exact_evals += passage.serve(&exact, t, y, t_end);
                self.passage = Some(passage);
                Ok(Some(false))
            }
        }
    }

    /// A Taylor step from (t, y) with the series `c` of the current piece: as long as the
    /// tolerance allows, or to t_end, or to an edge inside it, which is then crossed. False
    /// when the step reaches past t_end and is kept for the next call (`interpolate_ends`),
    /// t_end served from it.
    fn series_step<S: Piecewise<N>>(
        &mut self,
        sys: &mut S,
        c: &taylor::Coefficients<N>,
        t: &mut f64,
        y: &mut [f64; N],
        t_end: f64,
        crossings_here: &mut u32,
    ) -> Result<bool, SolverError> {
        let step_past = self.interpolate_ends;
        let natural = taylor::Step::length(c, &self.tol);
        let last = !natural.is_finite() || (!step_past && *t + OPTIONS.sliver * natural >= t_end);
        let h = if last { t_end - *t } else { natural };
        if h <= OPTIONS.min_step_ulps * f64::EPSILON * t.abs().max(t_end.abs()) {
            return Err(SolverError::StepTooSmall { t: *t, h });
        }
        let step = taylor::Step::new(*c, h);
        sys.observe(*t, h, &step);
        self.stats.accepted += 1;
        self.stats.series_steps += 1;
        // What DOPRI5 knew of this point and of the piece's entry does not carry over.
        self.k1_valid = false;
        self.entering = None;
        let (lo, hi) = sys.piece();
        if let Some((edge, theta)) = locate_edge(&step, (S::GUARD, S::RATE), lo, hi) {
            if step_past && *t + theta * h > t_end {
                // The edge lies past t_end: the step up to it is kept, as DOPRI5's is.
                let kept = taylor::Step::new(*c, theta * h);
                self.keep(
                    Interpolant::Taylor(kept),
                    kept.h,
                    kept.y1,
                    Some(edge),
                    t,
                    y,
                    t_end,
                );
                return Ok(false);
            }
            if theta > 0.0 {
                *y = step.at(theta);
                *t += theta * h;
                *crossings_here = 0;
            } else {
                *crossings_here += 1;
                if *crossings_here > OPTIONS.crossings_at_once {
                    return Err(SolverError::Chattering { t: *t });
                }
            }
            self.cross(sys, edge, *t, y);
            return Ok(true);
        }
        *crossings_here = 0;
        self.just_crossed = false;
        if step_past && *t + h > t_end {
            self.keep(Interpolant::Taylor(step), h, step.y1, None, t, y, t_end);
            return Ok(false);
        }
        *t = if last { t_end } else { *t + h };
        *y = step.y1;
        Ok(true)
    }

    /// Crosses `edge` at (t, y): the system changes piece, and what was known of the old one
    /// goes.
    fn cross<S: Piecewise<N>>(&mut self, sys: &mut S, edge: Edge, t: f64, y: &[f64; N]) {
        sys.cross(edge, t, y);
        let (lo, hi) = sys.piece();
        self.entering = Some(Entry {
            lo,
            hi,
            through: edge,
        });
        self.stats.edges += 1;
        self.k1_valid = false;
        self.stepper.invalidate();
        self.just_crossed = true;
    }

    /// Keeps an accepted DOPRI5 step from (t, y) that reaches past t_end (ending on `edge`,
    /// if any) and hands out (t_end, y(t_end)) from its dense output.
    fn keep_ahead(
        &mut self,
        step: &dopri5::Trial<N>,
        edge: Option<Edge>,
        t: &mut f64,
        y: &mut [f64; N],
        t_end: f64,
    ) {
        let dense = Interpolant::Dopri5(step.continuous());
        self.keep(dense, step.h, step.y1, edge, t, y, t_end);
    }

    /// Keeps a step from (t, y) of length h to y1 that reaches past t_end and hands out
    /// (t_end, y(t_end)) from its dense output.
    #[allow(clippy::too_many_arguments)]
    fn keep(
        &mut self,
        dense: Interpolant<N>,
        h: f64,
        y1: [f64; N],
        edge: Option<Edge>,
        t: &mut f64,
        y: &mut [f64; N],
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
        ahead.serve(t, y, t_end);
        self.ahead = Some(ahead);
    }

    /// One step of size h from (t, y) with the current method: accepted (with the edge it
    /// leaves its piece through, if any) or rejected with the step size to retry with.
    fn attempt<S: Piecewise<N> + Jacobian<N>>(
        &mut self,
        sys: &mut S,
        at: Start<N>,
        h: f64,
        trial_buffer: &mut dopri5::Trial<N>,
    ) -> Result<Accepted<N>, f64> {
        let (lo, hi) = sys.piece();
        let guard = (S::GUARD, S::RATE);
        if self.implicit {
            let trial = self.implicit_step(sys, at, h);
            let verdict = self.stepper.judge(&trial);
            if !verdict.accept {
                return Err(verdict.h_next);
            }
            sys.observe(at.t, h, &trial);
            Ok(Accepted {
                y1: trial.y1,
                explicit: false,
                h_next: verdict.h_next,
                edge: locate_edge(&trial, guard, lo, hi),
                h_rho: 0.0,
            })
        } else {
            self.explicit_step(sys, at, h, trial_buffer);
            let trial = &*trial_buffer;
            let mut err = self.tol.norm(&trial.y0, &trial.y1, &trial.err);
            if self.just_crossed && sys.rough_start() {
                err *= OPTIONS.first_step_distrust;
            }
            let verdict = self.controller.judge(err, h);
            if !verdict.accept {
                return Err(verdict.h_next);
            }
            sys.observe(at.t, h, trial);
            Ok(Accepted {
                y1: trial.y1,
                h_next: verdict.h_next,
                edge: locate_edge(trial, guard, lo, hi),
                h_rho: if self.method == Method::Auto {
                    stiffness(trial, &self.tol)
                } else {
                    0.0
                },
                explicit: true,
            })
        }
    }

    /// The step redone with size h to end on an edge; None if Radau's Newton iteration fails
    /// on it.
    fn redo<S: Piecewise<N> + Jacobian<N>>(
        &mut self,
        sys: &S,
        at: Start<N>,
        h: f64,
        trial: &mut dopri5::Trial<N>,
    ) -> Option<[f64; N]> {
        if self.implicit {
            let trial = self.implicit_step(sys, at, h);
            trial.converged().then_some(trial.y1)
        } else {
            self.explicit_step(sys, at, h, trial);
            Some(trial.y1)
        }
    }

    /// A DOPRI5 trial into `trial`, with its work counted.
    fn explicit_step<S: Piecewise<N>>(
        &mut self,
        sys: &S,
        at: Start<N>,
        h: f64,
        trial: &mut dopri5::Trial<N>,
    ) {
        self.stats.rhs_evals += EVALS_PER_STEP;
        dopri5::step(sys, at.t, at.y, at.k1, h, self.tol.controlled, trial);
    }

    /// A Radau IIA trial, with its work counted and the spectral radius of a new Jacobian
    /// taken (once per Jacobian: it is what the way back to DOPRI5 is judged by).
    fn implicit_step<S: Jacobian<N>>(&mut self, sys: &S, at: Start<N>, h: f64) -> RadauTrial<N> {
        let before = self.stepper.stats;
        let trial = self.stepper.step(sys, at.t, at.y, at.k1, h);
        let after = self.stepper.stats;
        self.stats.rhs_evals += after.rhs_evals - before.rhs_evals;
        self.stats.jacobians += after.jacobians - before.jacobians;
        self.stats.decompositions += after.decompositions - before.decompositions;
        if after.jacobians != self.rho_of
            && let Some(j) = self.stepper.jacobian()
        {
            self.rho = spectral_radius(j);
            self.rho_of = after.jacobians;
        }
        trial
    }

    /// After an accepted step that did not cross an edge: the hand-over of [`Method::Auto`].
    /// To Radau IIA (afresh) when DOPRI5 has been held back by stability; back to DOPRI5 (a
    /// fresh controller, Radau's step size) when Radau's steps are within DOPRI5's stability.
    fn hand_over(&mut self, explicit_h_rho: f64) {
        if self.method != Method::Auto {
            return;
        }
        if self.implicit {
            if self.switch.to_explicit(self.h * self.rho) {
                self.implicit = false;
                self.controller = Controller::default();
                self.stats.switches += 1;
            }
        } else if self.switch.to_implicit(explicit_h_rho) {
            self.implicit = true;
            self.stepper.invalidate();
            self.stats.switches += 1;
        }
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
