//! Taylor-series steps, for pieces whose solution has Taylor coefficients that the system can
//! form ([`super::Piecewise::series`]): one step is the series about its start, as long as
//! its last two terms allow for the tolerance (Jorba and Zou's rule), and its polynomial is
//! its own dense output, so an edge inside it is reached by evaluating it there, not by a
//! redone step.

use serde::{Deserialize, Serialize};

use super::options::OPTIONS;
use super::{Dense, Tolerance};
use crate::math;

/// Number of Taylor coefficients per component ([`OPTIONS`]`.taylor_terms`).
pub const TERMS: usize = OPTIONS.taylor_terms;

/// y_i(t + τ) = Σ_k c[k][i] τ^k, k < [`TERMS`].
pub type Coefficients<const N: usize> = [[f64; N]; TERMS];

/// Share of the error weights given to a step's last two terms ([`OPTIONS`]`.taylor_share`).
const SHARE: f64 = OPTIONS.taylor_share;

/// One step of length h from its coefficients, with its end.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Step<const N: usize> {
    pub h: f64,
    #[serde(with = "super::serde_array::rows")]
    c: Coefficients<N>,
    #[serde(with = "super::serde_array")]
    pub y1: [f64; N],
}

impl<const N: usize> Step<N> {
    /// The step of length h from the series `c` about its start.
    #[inline]
    pub fn new(c: Coefficients<N>, h: f64) -> Self {
        let mut step = Step { h, c, y1: [0.0; N] };
        step.set_length(h);
        step
    }

    /// A step to write in place: its series by [`series_mut`](Self::series_mut), then its
    /// length by [`set_length`](Self::set_length).
    pub fn blank() -> Self {
        Step {
            h: 0.0,
            c: [[0.0; N]; TERMS],
            y1: [0.0; N],
        }
    }

    /// Its series about its start.
    pub fn series(&self) -> &Coefficients<N> {
        &self.c
    }

    /// Its series, to write.
    pub fn series_mut(&mut self) -> &mut Coefficients<N> {
        &mut self.c
    }

    /// The step ends at h, its end computed from its series.
    #[inline]
    pub fn set_length(&mut self, h: f64) {
        self.h = h;
        self.y1 = self.at(1.0);
    }

    /// Whether every component stays below `bound` in magnitude for θ ∈ [0, 1], each of
    /// Horner's partial sums too: Σ_k |c_k| |h|^k does.
    pub fn bounded(&self, bound: f64) -> bool {
        let h = self.h.abs();
        (0..N).all(|i| self.c.iter().rev().fold(0.0, |acc, c| acc * h + c[i].abs()) < bound)
    }

    /// The same series cut to end at θ ∈ [0, 1] of the step.
    pub fn cut(&self, theta: f64) -> Self {
        Step::new(self.c, theta * self.h)
    }

    /// The longest step for the tolerance: for each controlled component with weight
    /// w = atol + rtol·|y0|, the last two terms |c_k| τ^k must stay within SHARE·w.
    pub fn length(c: &Coefficients<N>, tol: &Tolerance<N>) -> f64 {
        // min over the terms of (w / |c_k|)^(1/k), in log2 (coarse, as the step-size
        // controller's powers: the length needs no more than a few digits).
        let mut log_h = f64::INFINITY;
        for (i, atol) in tol.atol.iter().enumerate().take(tol.controlled) {
            let log_w = math::log2_coarse(SHARE * (atol + tol.rtol * c[0][i].abs()));
            for k in [TERMS - 2, TERMS - 1] {
                let ck = c[k][i].abs();
                if ck > 0.0 {
                    log_h = log_h.min((log_w - math::log2_coarse(ck)) * math::INVERSES[k]);
                }
            }
        }
        if log_h.is_finite() {
            math::exp2_coarse(log_h)
        } else {
            f64::INFINITY
        }
    }

    /// The state at t + θh, θ ∈ [0, 1]: Horner's scheme on all components at once (the
    /// same operations, component by component, as `dense`).
    #[inline]
    pub fn at(&self, theta: f64) -> [f64; N] {
        let tau = theta * self.h;
        let mut y = [0.0; N];
        for row in self.c.iter().rev() {
            for (yi, ci) in y.iter_mut().zip(row) {
                *yi = *yi * tau + ci;
            }
        }
        y
    }
}

impl<const N: usize> Dense<N> for Step<N> {
    fn ends(&self) -> (&[f64; N], &[f64; N]) {
        (&self.c[0], &self.y1)
    }

    fn dense(&self, i: usize, theta: f64) -> f64 {
        let tau = theta * self.h;
        self.c.iter().rev().fold(0.0, |acc, c| acc * tau + c[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = e^(−t), y' = −y: c_k = (−1)^k / k!; a step reproduces e^(−h) within the weight
    /// its length was chosen for, and its dense output e^(−θh).
    #[test]
    fn exponential_within_the_weight() {
        let mut c = [[0.0; 1]; TERMS];
        let mut term = 1.0;
        for (k, ck) in c.iter_mut().enumerate() {
            ck[0] = term;
            term *= -1.0 / (k + 1) as f64;
        }
        let tol = Tolerance {
            rtol: 1e-10,
            atol: [1e-10],
            controlled: 1,
        };
        let h = Step::length(&c, &tol);
        assert!(h > 0.1 && h < 1.0, "{h}");
        let step = Step::new(c, h);
        assert!((step.y1[0] - (-h).exp()).abs() <= SHARE * 2e-10);
        assert!((step.dense(0, 0.5) - (-0.5 * h).exp()).abs() <= SHARE * 2e-10);
        assert_eq!(step.ends().0, &[1.0]);
    }
}
