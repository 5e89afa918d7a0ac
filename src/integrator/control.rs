//! Error norm and step-size control of DOPRI5 (Hairer's PI controller, β = 0.04).

use serde::{Deserialize, Serialize};

use crate::math;

/// Tolerances: the error of component i is weighed by atol[i] + rtol·max(|y0_i|, |y1_i|).
/// Only the first `controlled` components enter the norm. The others are quadratures
/// carried along, like dissipated energies: the right-hand side must not read them (DOPRI5's
/// stages do not form them, see `dopri5::step`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tolerance<const N: usize> {
    pub rtol: f64,
    #[serde(with = "super::serde_array")]
    pub atol: [f64; N],
    pub controlled: usize,
}

impl<const N: usize> Tolerance<N> {
    /// RMS of the weighted local error; ≤ 1 means the step is accurate enough.
    pub fn norm(&self, y0: &[f64; N], y1: &[f64; N], err: &[f64; N]) -> f64 {
        let mut sum = 0.0;
        for i in 0..self.controlled {
            let scale = self.atol[i] + self.rtol * y0[i].abs().max(y1[i].abs());
            let e = err[i] / scale;
            sum += e * e;
        }
        (sum / self.controlled as f64).sqrt()
    }
}

const SAFETY: f64 = 0.9;
const BETA: f64 = 0.04;
const EXPONENT: f64 = 0.2 - BETA * 0.75;
/// Largest shrink (1/10) and growth (×5) of the step per step.
const MIN_FACTOR: f64 = 0.1;
const MAX_FACTOR: f64 = 5.0;

/// Verdict on a step with its weighted error: accept or not, and the next step size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Verdict {
    pub accept: bool,
    pub h_next: f64,
}

/// PI step-size controller; its memory (the previous error) is part of the solver's state.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Controller {
    previous_error: f64,
    rejected_last: bool,
}

impl Default for Controller {
    fn default() -> Self {
        Controller {
            previous_error: 1e-4,
            rejected_last: false,
        }
    }
}

impl Controller {
    pub fn judge(&mut self, err: f64, h: f64) -> Verdict {
        if !err.is_finite() {
            self.rejected_last = true;
            return Verdict {
                accept: false,
                h_next: h * MIN_FACTOR,
            };
        }
        // err^EXPONENT and the PI term to 1e-4 through `math`'s coarse log2 and exp2, not
        // powf: the next step waits for them, and their accuracy does not matter.
        let log_err = math::log2_coarse(err);
        if err <= 1.0 {
            let log_previous = math::log2_coarse(self.previous_error);
            // SAFETY / fac, fac = err^EXPONENT / previous^BETA / SAFETY clamped to [1/5, 10].
            let growth = (SAFETY * math::exp2_coarse(BETA * log_previous - EXPONENT * log_err))
                .clamp(MIN_FACTOR, MAX_FACTOR);
            let mut h_next = h * growth;
            if self.rejected_last {
                h_next = h_next.min(h);
            }
            self.previous_error = err.max(1e-4);
            self.rejected_last = false;
            Verdict {
                accept: true,
                h_next,
            }
        } else {
            self.rejected_last = true;
            Verdict {
                accept: false,
                h_next: h * (SAFETY * math::exp2_coarse(-EXPONENT * log_err)).max(MIN_FACTOR),
            }
        }
    }
}
