//! Where the last call of the solver left its caller, for what the solver keeps from one call
//! to the next (the DOPRI5 step taken past the end time, the passage through a piece with an
//! exact solution): a call that starts from anywhere else drops it.

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub(super) struct LeftOff<const N: usize> {
    t: f64,
    #[serde(with = "super::serde_array")]
    y: [f64; N],
}

impl<const N: usize> LeftOff<N> {
    pub fn at(t: f64, y: &[f64; N]) -> Self {
        LeftOff { t, y: *y }
    }

    /// Whether a call from (t, y) continues from here. The time may come back rounded
    /// differently (a master passing k·h where t_end was (k−1)·h + h): a few ulps are the
    /// same point; the state must be the same bits.
    pub fn continued_by(&self, t: f64, y: &[f64; N]) -> bool {
        same_time(self.t, t) && *y == self.y
    }
}

/// Whether a call from t continues one that left off at `left`, as far as time goes (see
/// [`LeftOff::continued_by`]).
#[inline]
pub(super) fn same_time(left: f64, t: f64) -> bool {
    (t - left).abs() <= 4.0 * f64::EPSILON * left.abs()
}
