//! The first DOPRI5 step into a piece after an edge. The step size carried over the edge is
//! the one the old piece allowed, which can be far from what the new one allows. A piece is
//! entered the same way again and again (a rattling gear enters each band from the gap and
//! from the contact at every impact), so the solver remembers, per piece and per edge it was
//! entered through, the ratio of the step size its controller wanted there to a base, and
//! starts the next entry from the base times that ratio. The base is the time to cross the
//! piece at the rate it is entered with where the piece is bounded (a band: ε/|ξ'|), else
//! the step carried in. From the crossing time the first step into a band stays short where
//! the band starts non-smooth (the force grows like δ^(10/3) from the gap's edge), an error
//! that the step's own estimate does not see. Evidence: docs/DECISIONS.md, D4 and D5.

use serde::{Deserialize, Serialize};

use super::Crossing;
use super::options::OPTIONS;

const SLOTS: usize = OPTIONS.entry_slots;

/// A piece as the integrator sees it: its guard's bounds, and the edge of the piece left
/// behind (with its guard).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub(super) struct Entry {
    pub lo: f64,
    pub hi: f64,
    pub through: Crossing,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct Slot {
    entry: Entry,
    /// ln of the ratio wanted / carried, averaged over the entries so far (each new one
    /// weighs half).
    log_ratio: f64,
}

/// The ratios learnt so far, oldest overwritten first.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct Entries {
    slots: [Option<Slot>; SLOTS],
    next: usize,
}

impl Entries {
    /// The factor to apply to the step size carried into `entry` (1 for a new one).
    pub fn ratio(&self, entry: &Entry) -> f64 {
        self.slots
            .iter()
            .flatten()
            .find(|s| s.entry == *entry)
            .map_or(1.0, |s| s.log_ratio.exp())
    }

    /// The controller, having judged the first step into `entry`, wants `wanted` where the
    /// base was `carried`.
    pub fn learn(&mut self, entry: &Entry, carried: f64, wanted: f64) {
        let observed = (wanted / carried)
            .clamp(OPTIONS.entry_ratio_min, OPTIONS.entry_ratio_max)
            .ln();
        if !observed.is_finite() {
            return;
        }
        match self.slots.iter_mut().flatten().find(|s| s.entry == *entry) {
            Some(slot) => slot.log_ratio = 0.5 * (slot.log_ratio + observed),
            None => {
                self.slots[self.next] = Some(Slot {
                    entry: *entry,
                    log_ratio: observed,
                });
                self.next = (self.next + 1) % SLOTS;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::Edge;

    fn entry(lo: f64, edge: Edge) -> Entry {
        Entry {
            lo,
            hi: lo + 1.0,
            through: Crossing { guard: 0, edge },
        }
    }

    /// A new piece keeps the carried step; a learnt one moves halfway towards each new
    /// observation, within bounds; pieces and edges are told apart; the oldest is forgotten.
    #[test]
    fn learns_per_piece_and_edge() {
        let mut e = Entries::default();
        let a = entry(0.0, Edge::Lower);
        assert_eq!(e.ratio(&a), 1.0);
        e.learn(&a, 1e-4, 0.5e-4);
        assert!((e.ratio(&a) - 0.5).abs() < 1e-15);
        e.learn(&a, 1e-4, 2e-4);
        assert!(
            (e.ratio(&a) - 1.0).abs() < 1e-15,
            "geometric mean of 0.5 and 2"
        );
        e.learn(&a, 1e-4, 1.0);
        assert!(
            (e.ratio(&a) - 5f64.sqrt()).abs() < 1e-14,
            "growth capped at 5"
        );
        assert_eq!(e.ratio(&entry(0.0, Edge::Upper)), 1.0);
        let other_guard = Entry {
            through: Crossing {
                guard: 1,
                edge: Edge::Lower,
            },
            ..a
        };
        assert_eq!(e.ratio(&other_guard), 1.0, "guards are told apart");
        for k in 1..=SLOTS {
            e.learn(&entry(k as f64, Edge::Upper), 1.0, 2.0);
        }
        assert_eq!(e.ratio(&a), 1.0, "the oldest is forgotten");
        assert!((e.ratio(&entry(SLOTS as f64, Edge::Upper)) - 2.0).abs() < 1e-15);
        e.learn(&a, 1.0, f64::NAN);
        assert_eq!(e.ratio(&a), 1.0, "nothing learnt from NaN");
    }
}
