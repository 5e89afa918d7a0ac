//! What a solver's work is counted and bounded by: the counters ([`Stats`]), why a call stops
//! short ([`SolverError`]), the limits of one call (`Budget`) and what one call carries from
//! step to step (`Call`). Shared by the driver (`solver`) and its steppers (`runge_kutta`).

use serde::{Deserialize, Serialize};

use super::dopri5;
use super::options::OPTIONS;

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
    /// Accepted steps taken by Taylor series ([`super::taylor`]; counted in `accepted` too).
    pub series_steps: u64,
}

impl std::ops::AddAssign for Stats {
    /// The work of two solvers together.
    fn add_assign(&mut self, o: Stats) {
        self.rhs_evals += o.rhs_evals;
        self.accepted += o.accepted;
        self.rejected += o.rejected;
        self.edges += o.edges;
        self.implicit_steps += o.implicit_steps;
        self.jacobians += o.jacobians;
        self.decompositions += o.decompositions;
        self.switches += o.switches;
        self.exact_evals += o.exact_evals;
        self.series_steps += o.series_steps;
    }
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

/// The resolution of time between t and t_end: the solver refuses a step there that is not
/// longer ([`SolverError::StepTooSmall`]; `min_step_ulps` machine epsilons of the larger
/// time).
#[inline]
pub fn resolution(t: f64, t_end: f64) -> f64 {
    OPTIONS.min_step_ulps * f64::EPSILON * t.abs().max(t_end.abs())
}

/// The limits of one call of the solver's `advance`: steps taken, and edges crossed at the same
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
        if h <= resolution(t, t_end) {
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

    /// A step ended without crossing an edge: the count of crossings at one instant restarts.
    pub fn advanced(&mut self) {
        self.crossings_here = 0;
    }

    /// An edge crossed at θ of a step from t: with progress in time, or again at the same
    /// instant, which fails after a few times.
    pub fn crossing(&mut self, t: f64, theta: f64) -> Result<(), SolverError> {
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

/// One call of the solver's `advance`: its end time, whether the step under way may reach
/// past it (explicit steps with `interpolate_ends`), its limits, and the buffer the DOPRI5
/// steps are written in (see `dopri5::step`).
pub(super) struct Call<const N: usize> {
    pub t_end: f64,
    pub past: bool,
    pub budget: Budget,
    pub trial: dopri5::Trial<N>,
}

impl<const N: usize> Call<N> {
    pub fn new(t_end: f64) -> Self {
        Call {
            t_end,
            past: false,
            budget: Budget::default(),
            trial: dopri5::Trial::empty(),
        }
    }
}
