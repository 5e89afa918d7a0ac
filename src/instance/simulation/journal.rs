//! What puts a failed step of a simulation back as it was, for the price of one copy of the
//! simulation every `ENTRIES` changes instead of one before each step: the copy, and the
//! changes made since (each step's start, end time and `at_impact`, each new input).
//! Replayed from the copy, they give the state before the failed step to the bit: a step
//! depends on nothing else. Model Exchange, which moves the state from outside, never steps.
//! GearRattle's [`Simulation`](super::Simulation) keeps one of [`Entry`]s, GearboxRattle's
//! one of its own.

use crate::physics::Shaft;

/// How many changes GearRattle's journal records before it takes a new copy.
pub(super) const ENTRIES: usize = 64;

/// A change of GearRattle's simulation since the journal's copy, in the order made.
#[derive(Clone, Copy, Debug)]
pub(super) enum Entry {
    /// A step from `from` to `to` that succeeded (`Simulation::step_until`).
    Step { from: f64, to: f64, at_impact: bool },
    /// New inputs of the main shaft (`Simulation::set_shaft`).
    Shaft(Shaft),
    /// A new torque on the main shaft (`Simulation::set_torque`).
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
    /// Before a change of the simulation: a new copy of it (`copy`) if the journal has none
    /// or is full.
    #[inline]
    pub fn before(&mut self, copy: impl FnOnce() -> C) {
        if self.copy.is_none() || self.len == ENTRIES {
            self.copy = Some(copy());
            self.len = 0;
        }
    }

    /// After the change `entry`, made since [`before`](Self::before).
    #[inline]
    pub fn record(&mut self, entry: E) {
        self.entries[self.len] = Some(entry);
        self.len += 1;
    }

    /// The copy and the changes since it, in the order made.
    pub fn replay(&self) -> (&C, impl Iterator<Item = E> + '_) {
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
