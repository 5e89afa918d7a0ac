//! Error norm and step-size control of DOPRI5 (Hairer's PI controller, β = 0.04).

use serde::{Deserialize, Serialize};

/// Tolerances: the error of component i is weighed by atol[i] + rtol·max(|y0_i|, |y1_i|).
/// Only the first `controlled` components enter the norm (the others are quadratures
/// carried along, like dissipated energies).
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
/// Both exponents of the PI law, 0.2 − 0.75β = 0.17 on the error and β = 0.04 on the
/// previous one, are whole multiples of this one (17 and 4 times), so one power err^UNIT per
/// step gives both by multiplications (`powers`).
const UNIT: f64 = 0.01;
/// Largest shrink (1/10) and growth (×5) of the step per step.
const MIN_FACTOR: f64 = 0.1;
const MAX_FACTOR: f64 = 5.0;
/// Floor of the previous error in the PI law (Hairer's 1e-4).
const ERROR_FLOOR: f64 = 1e-4;

/// Verdict on a step with its weighted error: accept or not, and the next step size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Verdict {
    pub accept: bool,
    pub h_next: f64,
}

/// PI step-size controller; its memory (the previous error, kept raised to β: the only form
/// in which the law uses it) is part of the solver's state.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Controller {
    /// max(previous accepted error, 1e-4)^β.
    previous_error_beta: f64,
    rejected_last: bool,
}

impl Default for Controller {
    fn default() -> Self {
        Controller {
            previous_error_beta: ERROR_FLOOR.powf(BETA),
            rejected_last: false,
        }
    }
}

/// (err^(0.2 − 0.75β), err^β) = (err^0.17, err^0.04) from the single power err^UNIT:
/// 17 = 16 + 1 and 4 by squarings.
/// Differs from two `powf` by a few ulp (17 roundings at most), far below what step control
/// can notice; costs one `powf` instead of two per accepted step.
#[inline]
fn powers(err: f64) -> (f64, f64) {
    let p = err.powf(UNIT);
    let p2 = p * p;
    let p4 = p2 * p2;
    let p16 = (p4 * p4) * (p4 * p4);
    (p16 * p, p4)
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
        let (fac11, err_beta) = powers(err);
        if err <= 1.0 {
            let fac = (fac11 / self.previous_error_beta / SAFETY)
                .clamp(1.0 / MAX_FACTOR, 1.0 / MIN_FACTOR);
            let mut h_next = h / fac;
            if self.rejected_last {
                h_next = h_next.min(h);
            }
            self.previous_error_beta = if err >= ERROR_FLOOR {
                err_beta
            } else {
                Controller::default().previous_error_beta
            };
            self.rejected_last = false;
            Verdict {
                accept: true,
                h_next,
            }
        } else {
            self.rejected_last = true;
            Verdict {
                accept: false,
                h_next: h / (fac11 / SAFETY).min(1.0 / MIN_FACTOR),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The powers from err^UNIT agree with `powf` to a few ulp, from tiny errors to huge ones.
    #[test]
    fn powers_match_powf() {
        let exponent = 0.2 - BETA * 0.75;
        assert!((17.0 * UNIT - exponent).abs() < 1e-15 && (4.0 * UNIT - BETA).abs() < 1e-15);
        for k in -300..=300 {
            let err = 10f64.powf(k as f64 * 0.1) * 1.2345;
            let (a, b) = powers(err);
            assert!((a / err.powf(exponent) - 1.0).abs() < 1e-14, "{err:e}");
            assert!((b / err.powf(BETA) - 1.0).abs() < 1e-14, "{err:e}");
        }
    }
}
