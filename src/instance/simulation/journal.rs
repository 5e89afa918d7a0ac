//! What puts a failed step of a simulation back as it was, for the price of one copy of the
//! simulation every `ENTRIES` changes instead of one before each step: the copy, and the
//! changes made since (each step's start, end time and `at_impact`, each new input).
//! Replayed from the copy, they give the state before the failed step to the bit: a step
//! depends on nothing else. Model Exchange, which moves the state from outside, never steps.
//! A simulation makes its changes through [`Journaled`]: GearRattle's
//! [`Simulation`](super::Simulation) with its [`Input`]s, GearboxRattle's with its own.

use crate::integrator::SolverError;
use crate::physics::Shaft;

/// How many changes GearRattle's journal records before it takes a new copy.
pub const ENTRIES: usize = 64;

/// A change of a simulation since the journal's copy, in the order made: a step, or new
/// inputs `I` of the model's own kind.
#[derive(Clone, Copy, Debug)]
pub enum Change<I> {
    /// A step from `from` to `to` that succeeded ([`Journaled::step_until`]).
    Step { from: f64, to: f64, at_impact: bool },
    /// New inputs.
    Input(I),
}

/// New inputs of GearRattle's simulation.
#[derive(Clone, Copy, Debug)]
pub enum Input {
    /// Of the main shaft (`Simulation::set_shaft`).
    Shaft(Shaft),
    /// A torque on the main shaft (`Simulation::set_torque`).
    Torque { tau: f64, rate: f64 },
}

/// The copy `C` of what a simulation's changes move, and the changes `E` since; no part of
/// the simulation's state (not serialized, not compared).
#[derive(Clone, Copy, Debug)]
pub struct Journal<C, E, const ENTRIES: usize> {
    copy: Option<C>,
    entries: [Option<E>; ENTRIES],
    len: usize,
}

impl<C, E: Copy, const ENTRIES: usize> Default for Journal<C, E, ENTRIES> {
    fn default() -> Self {
        Journal {
            copy: None,
            entries: [None; ENTRIES],
            len: 0,
        }
    }
}

/// Two simulations in the same state are equal whatever their journals.
impl<C, E, const ENTRIES: usize> PartialEq for Journal<C, E, ENTRIES> {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl<C, E: Copy, const ENTRIES: usize> Journal<C, E, ENTRIES> {
    /// Whether the next change needs a new copy first: the journal has none or is full.
    #[inline]
    fn is_due(&self) -> bool {
        self.copy.is_none() || self.len == ENTRIES
    }

    /// A new copy, taken before the next change, and no changes since.
    fn start(&mut self, copy: C) {
        self.copy = Some(copy);
        self.len = 0;
    }

    /// After the change `entry`, made since the copy.
    #[inline]
    fn record(&mut self, entry: E) {
        self.entries[self.len] = Some(entry);
        self.len += 1;
    }

    /// The copy and the changes since it, in the order made.
    fn replay(&self) -> (&C, impl Iterator<Item = E> + '_) {
        let copy = self.copy.as_ref().expect("taken before the first change");
        (copy, self.entries[..self.len].iter().flatten().copied())
    }

    /// How many changes it holds.
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// A simulation whose changes a journal of `ENTRIES` records: each step and each new input
/// made through it ([`step_until`](Self::step_until), [`change`](Self::change)), a failed
/// step put back by [`replay`](Self::replay).
pub trait Journaled<const ENTRIES: usize> {
    /// What the journal copies: what the changes move.
    type Copy;
    /// New inputs.
    type Input: Copy;

    fn journal(&mut self) -> &mut Journal<Self::Copy, Change<Self::Input>, ENTRIES>;

    /// A copy of what the changes move.
    fn copy(&self) -> Self::Copy;

    /// Back to `copy`.
    fn restore(&mut self, copy: &Self::Copy);

    /// The simulation's time.
    fn time(&mut self) -> &mut f64;

    /// Advances from the simulation's time to t_end without the journal, with `at_impact`
    /// stopping at the first impact before it: returns the time reached. A failure leaves
    /// the simulation where it failed.
    fn advance(&mut self, t_end: f64, at_impact: bool) -> Result<f64, SolverError>;

    /// Takes new inputs without the journal.
    fn take(&mut self, input: Self::Input);

    /// Advances to t_end, or with `at_impact` to the first impact before it (its instant as
    /// the integrator locates it); returns the time reached. On failure the simulation is
    /// left as it was.
    fn step_until(&mut self, t_end: f64, at_impact: bool) -> Result<f64, SolverError>
    where
        Self: Sized,
    {
        let from = *self.time();
        self.journaled(Change::Step {
            from,
            to: t_end,
            at_impact,
        })
    }

    /// Takes new inputs and records them.
    fn change(&mut self, input: Self::Input)
    where
        Self: Sized,
    {
        self.journaled(Change::Input(input))
            .expect("a change of inputs does not step");
    }

    /// Calls of [`step_until`](Self::step_until) without `at_impact`, the first from `from`,
    /// each continuing where the one before ends, that `serve` takes without stepping (the
    /// solver serving their ends from its kept step: [`Solver::serve_run`]) and counts.
    /// Recorded as one step from `from` to the time they reach, which, replayed, the solver
    /// serves from the same kept step to the same state (serving moves no counter).
    ///
    /// [`Solver::serve_run`]: crate::integrator::Solver::serve_run
    fn served(&mut self, from: f64, serve: impl FnOnce(&mut Self) -> usize) -> usize
    where
        Self: Sized,
    {
        if self.journal().is_due() {
            let copy = self.copy();
            self.journal().start(copy);
        }
        let taken = serve(self);
        if taken > 0 {
            let to = *self.time();
            self.journal().record(Change::Step {
                from,
                to,
                at_impact: false,
            });
        }
        taken
    }

    /// Makes the change without the journal; returns the time reached.
    fn apply(&mut self, change: Change<Self::Input>) -> Result<f64, SolverError> {
        match change {
            Change::Step {
                from,
                to,
                at_impact,
            } => {
                *self.time() = from;
                self.advance(to, at_impact)
            }
            Change::Input(input) => {
                self.take(input);
                Ok(*self.time())
            }
        }
    }

    /// Makes the change and records it; if it fails (a step), puts the simulation back as
    /// it was before. Returns the time reached.
    #[inline]
    fn journaled(&mut self, change: Change<Self::Input>) -> Result<f64, SolverError>
    where
        Self: Sized,
    {
        if self.journal().is_due() {
            let copy = self.copy();
            self.journal().start(copy);
        }
        match self.apply(change) {
            Ok(reached) => {
                self.journal().record(change);
                Ok(reached)
            }
            Err(e) => {
                self.replay();
                Err(e)
            }
        }
    }

    /// Back to the state before the change that failed: the journal's copy, then the
    /// changes made since.
    #[cold]
    fn replay(&mut self)
    where
        Self: Sized,
    {
        let mut journal = Journal::default();
        std::mem::swap(self.journal(), &mut journal);
        let (copy, entries) = journal.replay();
        self.restore(copy);
        for change in entries {
            self.apply(change)
                .expect("a change that succeeded succeeds again from the same state");
        }
        *self.journal() = journal;
    }
}
