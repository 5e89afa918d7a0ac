//! A co-simulation step as the models of this shell take it, written once: the model steps
//! its running simulation from the master's point; a step that fails, or ends in a state
//! that is no longer finite, becomes the error the importer reads; one that succeeds brings
//! the inputs the master does not set again in line with their extrapolation and writes the
//! event and step logs. The model supplies the hooks, and where it can, the steps of the
//! sampling entry's grid served without stepping ([`Stepping::serve`]).

use crate::slave::Slave;
use crate::status::{FmiError, FmiResult};
use std::fmt::Display;
use std::ops::Range;

/// Steps of the sampling entry's grid (`gearRattleDoStepSampled`): step k goes from
/// t0 + k·dt to that + dt, as the importer's fmi2DoStep(t0 + k·dt, dt) would (the
/// communication point and the step's end computed alike, to the bit).
#[derive(Clone, Debug)]
pub struct Grid {
    pub t0: f64,
    pub dt: f64,
    /// The steps still to take.
    pub steps: Range<usize>,
}

impl Grid {
    /// Each step's communication point and end, in order.
    pub fn ends(&self) -> impl Iterator<Item = (f64, f64)> + use<> {
        let (t0, dt) = (self.t0, self.dt);
        self.steps.clone().map(move |k| {
            let t = t0 + k as f64 * dt;
            (t, t + dt)
        })
    }
}

/// What a model supplies to [`Stepping::step_until`], the step of its
/// [`Lifecycle::step`] and [`Lifecycle::step_to_event`] (a [`Model`]'s, written by the shell).
///
/// [`Lifecycle::step`]: crate::slave::Lifecycle::step
/// [`Lifecycle::step_to_event`]: crate::slave::Lifecycle::step_to_event
/// [`Model`]: crate::instance::Model
pub trait Stepping: Slave {
    /// What logEvents compares the end of a step with: the model's event counts before it.
    type Events;
    /// Why the simulation refused a step.
    type StepError: Display;
    /// The contract's log categories of events and of the solver's steps.
    const EVENTS: usize;
    const STEPS: usize;

    /// The event counts now (the simulation is running).
    fn events(&self) -> Self::Events;

    /// Steps the running simulation from `current` towards `t_end`, with `at_event` ended at
    /// its first event inside; returns the time reached. A failure leaves it at `current`.
    fn advance(&mut self, current: f64, t_end: f64, at_event: bool)
    -> Result<f64, Self::StepError>;

    /// Whether the simulation's state is finite.
    fn is_finite(&self) -> bool;

    /// The inputs follow their extrapolation where the master does not set them again.
    fn sync_inputs(&mut self);

    /// logEvents after a step ended at `t`: what happened since `before`.
    fn log_events(&mut self, t: f64, before: Self::Events);

    /// logStep after a step ended at `t`: the solver's work so far.
    fn log_steps(&mut self, t: f64);

    /// The first steps of `grid` taken without stepping, where the running simulation can
    /// serve their ends from what it has computed past them (an integrator step's dense
    /// output), with the Real variables `vrs` read after each into `out` (a row of vrs.len()
    /// values per step): each exactly as [`step_until`](Self::step_until) and fmi2GetReal
    /// would give them, to the bit, and the simulation left as those would leave it; no
    /// failure is possible, a step it cannot vouch for is left to the ordinary way. Returns
    /// how many steps it took; none (the default) takes each step the ordinary way.
    fn serve(&mut self, _grid: &Grid, _vrs: &[u32], _out: &mut [f64]) -> usize {
        0
    }

    /// [`serve`](Self::serve) with what [`step_until`](Self::step_until) does after a step
    /// that succeeded: the inputs follow their extrapolation. None is served with logStep on
    /// (a line after each step); served steps cross no edge, so logEvents has nothing to say.
    fn serve_sampled(&mut self, grid: &Grid, vrs: &[u32], out: &mut [f64]) -> usize {
        if self.log().is_on(Self::STEPS) {
            return 0;
        }
        let served = self.serve(grid, vrs, out);
        if served > 0 {
            self.sync_inputs();
        }
        served
    }

    /// A communication step from the master's point `current` (the shell has checked it)
    /// towards `t_end` (the step's end as the shell computed it, so that a step continued
    /// after an event ends where the plain one does), with `at_event` ended at the first event
    /// inside it; returns the time reached. A failure leaves the state at `current`.
    fn step_until(&mut self, current: f64, t_end: f64, at_event: bool) -> FmiResult<f64> {
        // What the event log compares with, taken only when that log is on.
        let before = self.log().is_on(Self::EVENTS).then(|| self.events());
        match self.advance(current, t_end, at_event) {
            // A state that overflowed (far out on the time axis, huge inputs) is a failed step.
            Ok(_) if !self.is_finite() => Err(FmiError::error(format!(
                "fmi2DoStep from t = {current} to {t_end} failed: the state is no longer finite (times, steps or inputs beyond what the model can represent); fmi2Reset to start over"
            ))),
            Ok(reached) => {
                self.sync_inputs();
                if let Some(before) = before {
                    self.log_events(reached, before);
                }
                if self.log().is_on(Self::STEPS) {
                    self.log_steps(reached);
                }
                Ok(reached)
            }
            Err(e) => Err(FmiError::error(format!(
                "fmi2DoStep from t = {current} to {t_end} failed: {e}; the state stays at t = {current}"
            ))),
        }
    }
}
