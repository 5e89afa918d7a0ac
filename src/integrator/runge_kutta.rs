//! Runge-Kutta steps, for the pieces crossed by steps: DOPRI5 with its PI controller, or Radau
//! IIA while the problem is stiff ([`Method::Auto`], the rule in `stiffness`), or either one
//! throughout. The first DOPRI5 step into a piece starts from what was learnt of earlier
//! entries (`entries`). A non-stiff run pays for the implicit side only Hairer's stiffness
//! estimate per accepted step (two weighted norms of the stages DOPRI5 has computed anyway).

use serde::{Deserialize, Serialize};

use super::control::{Controller, Tolerance};
use super::dopri5::{self, EVALS_PER_STEP};
use super::entries::{Entries, Entry};
use super::options::OPTIONS;
use super::radau5::{Jacobian, RadauTrial, Stepper};
use super::solver::{Budget, SolverError, Stats, locate_crossing};
use super::stiffness::{Switch, spectral_radius, stiffness};
use super::{Crossing, Dense, Piecewise, System};

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

/// Which of the two methods steps now.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub(super) enum Mode {
    Dopri5,
    Radau,
}

/// An accepted step of size h from the current point.
pub(super) struct Accepted<const N: usize> {
    pub h: f64,
    /// Cut short to end on the call's end time.
    pub last: bool,
    pub y1: [f64; N],
    h_next: f64,
    /// The edge the step leaves its piece through, and at which fraction of the step.
    pub edge: Option<(Crossing, f64)>,
    /// DOPRI5's stiffness estimate h·ρ of the step (0 when not asked for).
    h_rho: f64,
}

/// The Runge-Kutta side of the solver: the method, the step size, both methods' controllers
/// and what is known of the current point. Plain data (part of the FMU state).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub(super) struct RungeKutta<const N: usize> {
    method: Method,
    pub mode: Mode,
    /// Step size proposed for the next step (0: not chosen yet).
    pub h: f64,
    controller: Controller,
    radau: Stepper<N>,
    switch: Switch,
    /// Spectral radius of Radau's latest Jacobian, and that Jacobian's number.
    rho: f64,
    rho_of: u64,
    /// f(t, y) at the current point (the first stage of the next step), once known.
    #[serde(with = "super::serde_array::option")]
    k1: Option<[f64; N]>,
    /// The piece just entered, until its first DOPRI5 step is judged, and what was learnt
    /// of the first steps into each piece (see `entries`).
    entering: Option<Entry>,
    entries: Entries,
}

impl<const N: usize> RungeKutta<N> {
    pub fn new(tol: Tolerance<N>, method: Method) -> Self {
        RungeKutta {
            method,
            mode: match method {
                Method::Implicit => Mode::Radau,
                Method::Auto | Method::Explicit => Mode::Dopri5,
            },
            h: 0.0,
            controller: Controller::default(),
            radau: Stepper::new(tol),
            switch: Switch::default(),
            rho: 0.0,
            rho_of: 0,
            k1: None,
            entering: None,
            entries: Entries::default(),
        }
    }

    /// The call starts elsewhere than at the end of the step kept from the last one: f there
    /// is not known.
    pub fn moved(&mut self) {
        self.k1 = None;
    }

    /// The system changed from outside: Radau's Jacobian and extrapolation no longer hold.
    pub fn invalidate(&mut self) {
        self.k1 = None;
        self.radau.invalidate();
    }

    /// An edge was crossed into `entry`: the first step into it is learnt.
    pub fn entered(&mut self, entry: Entry) {
        self.entering = Some(entry);
        self.invalidate();
    }

    /// A Taylor step was taken: what was known of the piece's entry does not carry over.
    pub fn stepped_by_series(&mut self) {
        self.k1 = None;
        self.entering = None;
    }

    /// One step from (t, y) towards t_end (past it when `past`): accepted, or None when
    /// rejected (the next attempt's size set). `rough`: the step starts on the edge of a
    /// piece that is rough there, and its error estimate is distrusted (DOPRI5 only).
    #[allow(clippy::too_many_arguments)]
    pub fn attempt<S: Piecewise<N> + Jacobian<N>>(
        &mut self,
        sys: &mut S,
        (tol, stats, budget): (&Tolerance<N>, &mut Stats, &mut Budget),
        (t, y): (f64, &[f64; N]),
        t_end: f64,
        past: bool,
        rough: bool,
        trial: &mut dopri5::Trial<N>,
    ) -> Result<Option<Accepted<N>>, SolverError> {
        let k1 = self.derivative(sys, t, y, stats);
        if self.h <= 0.0 {
            // Capped by the call's length only where steps end on t_end: stepping past it,
            // the first step must not depend on the end time asked for, or neither would
            // the trajectory.
            let h_max = if past { f64::INFINITY } else { t_end - t };
            self.h = initial_step(sys, tol, (t, y, &k1), h_max, stats);
        }
        // The first DOPRI5 step into a piece just entered starts from what was learnt of
        // that piece's entries, as a ratio to a base: the time to cross the piece at the
        // guard's rate where the piece is bounded (a band: ε/|ξ'|, whatever step the free
        // flight or the contact before it left), else the step carried over the edge.
        let entering = match self.entering.take() {
            Some(entry) if self.mode == Mode::Dopri5 => {
                let rate = y[S::guard(entry.through.guard).1].abs();
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
        let (h, last) = budget.step(t, t_end, self.h, past)?;
        let (verdict, y1, edge, h_rho) = match self.mode {
            Mode::Radau => {
                let trial = self.implicit_step(sys, (t, y, &k1), h, stats);
                let verdict = self.radau.judge(&trial);
                let edge = verdict.accept.then(|| observed(sys, (t, h), &trial));
                (verdict, trial.y1, edge, 0.0)
            }
            Mode::Dopri5 => {
                explicit_step(sys, (t, y, &k1), h, tol, trial, stats);
                let mut err = tol.norm(&trial.y0, &trial.y1, &trial.err);
                if rough {
                    err *= OPTIONS.first_step_distrust;
                }
                let verdict = self.controller.judge(err, h);
                let edge = verdict.accept.then(|| observed(sys, (t, h), &*trial));
                let auto = verdict.accept && self.method == Method::Auto;
                (
                    verdict,
                    trial.y1,
                    edge,
                    if auto { stiffness(trial, tol) } else { 0.0 },
                )
            }
        };
        if let Some((entry, carried)) = entering {
            self.entries.learn(&entry, carried, verdict.h_next);
        }
        let Some(edge) = edge else {
            stats.rejected += 1;
            self.h = verdict.h_next;
            return Ok(None);
        };
        stats.accepted += 1;
        if self.mode == Mode::Radau {
            stats.implicit_steps += 1;
        }
        Ok(Some(Accepted {
            h,
            last,
            y1,
            h_next: verdict.h_next,
            edge,
            h_rho,
        }))
    }

    /// The accepted `step` from (t, y) redone to end at θ, on the edge inside it (a DOPRI5
    /// step into `trial`; f at (t, y) is known from the step); None if Radau's Newton iteration fails on it (the next attempt's
    /// size set).
    #[allow(clippy::too_many_arguments)]
    pub fn redo<S: Piecewise<N> + Jacobian<N>>(
        &mut self,
        sys: &S,
        (tol, stats): (&Tolerance<N>, &mut Stats),
        (t, y): (f64, &[f64; N]),
        step: &Accepted<N>,
        theta: f64,
        trial: &mut dopri5::Trial<N>,
    ) -> Option<[f64; N]> {
        let h = theta * step.h;
        let k1 = self.derivative(sys, t, y, stats);
        match self.mode {
            Mode::Radau => {
                let trial = self.implicit_step(sys, (t, y, &k1), h, stats);
                if !trial.converged() {
                    self.h = 0.5 * theta * step.h;
                    return None;
                }
                Some(trial.y1)
            }
            Mode::Dopri5 => {
                explicit_step(sys, (t, y, &k1), h, tol, trial, stats);
                Some(trial.y1)
            }
        }
    }

    /// The accepted `step` ends on the edge at θ: the next step starts from the larger of
    /// the step wanted and the one taken.
    pub fn ended_on_edge(&mut self, step: &Accepted<N>, theta: f64) {
        self.h = step.h_next.max(theta * step.h);
    }

    /// The accepted `step` is taken whole (a DOPRI5 step in `trial`, whose last stage is
    /// f at its end): the next step's start and size, and the hand-over of [`Method::Auto`].
    pub fn ended_inside(
        &mut self,
        step: &Accepted<N>,
        trial: &dopri5::Trial<N>,
        stats: &mut Stats,
    ) {
        self.k1 = (self.mode == Mode::Dopri5).then(|| *trial.k_end());
        // A step cut short to land on t_end says little about the natural step size.
        self.h = if step.last {
            step.h_next.max(self.h)
        } else {
            step.h_next
        };
        self.hand_over(step.h_rho, stats);
    }

    /// f(t, y), evaluated unless known.
    fn derivative<S: Piecewise<N>>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64; N],
        stats: &mut Stats,
    ) -> [f64; N] {
        match self.k1 {
            Some(k1) => k1,
            None => {
                stats.rhs_evals += 1;
                let k1 = sys.rhs(t, y);
                self.k1 = Some(k1);
                k1
            }
        }
    }

    /// A Radau IIA trial, with its work counted and the spectral radius of a new Jacobian
    /// taken (once per Jacobian: it is what the way back to DOPRI5 is judged by).
    fn implicit_step<S: Jacobian<N>>(
        &mut self,
        sys: &S,
        (t, y, k1): (f64, &[f64; N], &[f64; N]),
        h: f64,
        stats: &mut Stats,
    ) -> RadauTrial<N> {
        let before = self.radau.stats;
        let trial = self.radau.step(sys, t, y, k1, h);
        let after = self.radau.stats;
        stats.rhs_evals += after.rhs_evals - before.rhs_evals;
        stats.jacobians += after.jacobians - before.jacobians;
        stats.decompositions += after.decompositions - before.decompositions;
        if after.jacobians != self.rho_of
            && let Some(j) = self.radau.jacobian()
        {
            self.rho = spectral_radius(j);
            self.rho_of = after.jacobians;
        }
        trial
    }

    /// After an accepted step that did not cross an edge: the hand-over of [`Method::Auto`].
    /// To Radau IIA (afresh) when DOPRI5 has been held back by stability; back to DOPRI5 (a
    /// fresh controller, Radau's step size) when Radau's steps are within DOPRI5's stability.
    fn hand_over(&mut self, explicit_h_rho: f64, stats: &mut Stats) {
        if self.method != Method::Auto {
            return;
        }
        match self.mode {
            Mode::Radau => {
                if self.switch.to_explicit(self.h * self.rho) {
                    self.mode = Mode::Dopri5;
                    self.controller = Controller::default();
                    stats.switches += 1;
                }
            }
            Mode::Dopri5 => {
                if self.switch.to_implicit(explicit_h_rho) {
                    self.mode = Mode::Radau;
                    self.radau.invalidate();
                    stats.switches += 1;
                }
            }
        }
    }
}

/// An accepted step from t of length h, shown to the system ([`Piecewise::observe`]): the
/// earliest edge it leaves its piece through, if any.
fn observed<S: Piecewise<N>, D: Dense<N>, const N: usize>(
    sys: &mut S,
    (t, h): (f64, f64),
    step: &D,
) -> Option<(Crossing, f64)> {
    sys.observe(t, h, step);
    locate_crossing(sys, step)
}

/// A DOPRI5 trial from (t, y, f(t, y)) into `trial`, with its work counted.
fn explicit_step<S: System<N>, const N: usize>(
    sys: &S,
    (t, y, k1): (f64, &[f64; N], &[f64; N]),
    h: f64,
    tol: &Tolerance<N>,
    trial: &mut dopri5::Trial<N>,
    stats: &mut Stats,
) {
    stats.rhs_evals += EVALS_PER_STEP;
    dopri5::step(sys, t, y, k1, h, tol.controlled, trial);
}

/// Hairer's starting step: from the sizes of y, f and an estimate of f', capped.
fn initial_step<S: System<N>, const N: usize>(
    sys: &S,
    tol: &Tolerance<N>,
    (t, y, f0): (f64, &[f64; N], &[f64; N]),
    h_max: f64,
    stats: &mut Stats,
) -> f64 {
    let n = tol.controlled;
    let scale = |i: usize| tol.atol[i] + tol.rtol * y[i].abs();
    let rms =
        |v: &dyn Fn(usize) -> f64| ((0..n).map(|i| v(i).powi(2)).sum::<f64>() / n as f64).sqrt();
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
    stats.rhs_evals += 1;
    let der2 = rms(&|i| (f1[i] - f0[i]) / scale(i)) / h;
    let der12 = der2.max(dnf);
    let h1 = if der12 <= 1e-15 {
        (h * 1e-3).max(1e-6)
    } else {
        (0.01 / der12).powf(0.2)
    };
    (100.0 * h).min(h1).min(h_max)
}
