//! What puts a failed step of a [`Simulation`](super::Simulation) back as it was, for the
//! price of one copy of the simulation every [`ENTRIES`] changes instead of one before each
//! step: the copy, and the changes made since (each step's start, end time and `at_impact`,
//! each new input). Replayed from the copy, they give the state before the failed step to
//! the bit: a step depends on nothing else. Model Exchange, which moves the state from
//! outside, never steps.

use super::{Drive, Gear};
use crate::physics::Shaft;

/// How many changes a journal records before it takes a new copy.
pub(super) const ENTRIES: usize = 64;

/// A change of the simulation since the journal's copy, in the order made.
#[derive(Clone, Copy, Debug)]
pub(super) enum Entry {
    /// A step from `from` to `to` that succeeded (`Simulation::step_until`).
    Step { from: f64, to: f64, at_impact: bool },
    /// New inputs of the main shaft (`Simulation::set_shaft`).
    Shaft(Shaft),
    /// A new torque on the main shaft (`Simulation::set_torque`).
    Torque { tau: f64, rate: f64 },
}

/// The copy and the changes since; no part of the simulation's state (not serialized, not
/// compared).
#[derive(Clone, Copy, Debug)]
pub(super) struct Journal {
    copy: Option<(Gear, f64, Drive)>,
    entries: [Entry; ENTRIES],
    len: usize,
}

impl Default for Journal {
    fn default() -> Self {
        Journal {
            copy: None,
            entries: [Entry::Torque {
                tau: 0.0,
                rate: 0.0,
            }; ENTRIES],
            len: 0,
        }
    }
}

/// Two simulations in the same state are equal whatever their journals.
impl PartialEq for Journal {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Journal {
    /// Before a change of the simulation (gear, t, drive): a new copy of it if the journal
    /// has none or is full.
    #[inline]
    pub(super) fn before(&mut self, gear: &Gear, t: f64, drive: &Drive) {
        if self.copy.is_none() || self.len == ENTRIES {
            self.copy = Some((*gear, t, *drive));
            self.len = 0;
        }
    }

    /// After the change `entry`, made since [`before`](Self::before).
    #[inline]
    pub(super) fn record(&mut self, entry: Entry) {
        self.entries[self.len] = entry;
        self.len += 1;
    }

    /// The copy and the changes since it.
    pub(super) fn replay(&self) -> ((Gear, f64, Drive), &[Entry]) {
        let copy = self.copy.expect("taken before the first change");
        (copy, &self.entries[..self.len])
    }

    /// How many changes it holds.
    #[cfg(test)]
    pub(super) fn len(&self) -> usize {
        self.len
    }
}
