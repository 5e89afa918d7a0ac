//! Error norm and step-size control of DOPRI5: Hairer's PI controller (β = 0.04), capped by
//! Gustafsson's predictive controller.

use serde::{Deserialize, Serialize};

use super::options::OPTIONS;
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

const SAFETY: f64 = OPTIONS.safety;
const BETA: f64 = OPTIONS.beta;
const EXPONENT: f64 = 0.2 - BETA * 0.75;
const MIN_FACTOR: f64 = OPTIONS.min_factor;
const MAX_FACTOR: f64 = OPTIONS.max_factor;
/// 1/(q + 1) for the embedded estimate's order q = 4: the exponent of Gustafsson's
/// predictive step (Hairer & Wanner, Solving ODEs II, IV.8, as in RADAU5).
const PREDICTIVE_EXPONENT: f64 = 0.2;
/// Floors of the last accepted error: 1e-4 in the PI step (Hairer's), 1e-2 in the
/// predictive one (RADAU5's), with their log2.
const PI_FLOOR: f64 = 1e-4;
const PREDICTIVE_FLOOR: f64 = 1e-2;
const LOG2_PI_FLOOR: f64 = math::log2_coarse(PI_FLOOR);
const LOG2_PREDICTIVE_FLOOR: f64 = math::log2_coarse(PREDICTIVE_FLOOR);

/// Verdict on a step with its weighted error: accept or not, and the next step size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Verdict {
    pub accept: bool,
    pub h_next: f64,
}

/// PI step-size controller capped by Gustafsson's predictive one; its memory (the previous
/// error, the last accepted step) is part of the solver's state.
///
/// The predictive step h²/h_acc · SAFETY · (err_acc / err²)^(1/5) extrapolates the trend of
/// the error from one accepted step to the next, where the PI step only reads the error
/// level. Through a smoothing band the contact stiffens with every step, and the cap keeps
/// the PI controller from growing steps that would then be rejected (fewer rejections and a
/// lower error at loose tolerances; at equal error the CPU is unchanged: docs/DECISIONS.md,
/// D7). The last accepted step is kept across edges: the first step into a band is then
/// capped by how the previous band's last step went.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Controller {
    /// log2 of the last accepted step's error, which both controllers read, each with its
    /// own floor (the PI floor before the first step).
    log_err_acc: f64,
    rejected_last: bool,
    /// The last accepted step; 0 before the first.
    h_acc: f64,
}

impl Default for Controller {
    fn default() -> Self {
        Controller {
            log_err_acc: LOG2_PI_FLOOR,
            rejected_last: false,
            h_acc: 0.0,
        }
    }
}

impl Controller {
    /// log2 of the last accepted error floored at the error whose log2 is `log2_floor`
    /// (log2_coarse increases with its argument, but for its rounding: its cubic's slope
    /// stays positive on [1, 2)).
    #[inline]
    fn floored(&self, log2_floor: f64) -> f64 {
        self.log_err_acc.max(log2_floor)
    }

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
            let log_previous = self.floored(LOG2_PI_FLOOR);
            // SAFETY / fac, fac = err^EXPONENT / previous^BETA / SAFETY clamped to [1/5, 10].
            let growth = (SAFETY * math::exp2_coarse(BETA * log_previous - EXPONENT * log_err))
                .clamp(MIN_FACTOR, MAX_FACTOR);
            let mut h_next = h * growth;
            if self.h_acc > 0.0 {
                let log_err_acc = self.floored(LOG2_PREDICTIVE_FLOOR);
                let trend = math::exp2_coarse(PREDICTIVE_EXPONENT * (log_err_acc - 2.0 * log_err));
                let predicted = h * (h / self.h_acc) * SAFETY * trend;
                h_next = h_next.min(predicted.clamp(h * MIN_FACTOR, h * MAX_FACTOR));
            }
            self.h_acc = h;
            self.log_err_acc = log_err;
            if self.rejected_last {
                h_next = h_next.min(h);
            }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// PI step factor SAFETY · previous^β / err^(1/5 − 0.75β), computed with powf.
    fn pi_factor(previous: f64, err: f64) -> f64 {
        SAFETY * previous.powf(BETA) / err.powf(EXPONENT)
    }

    /// After two accepted steps of equal size, an error rising from 0.1 to 0.5 (a contact
    /// stiffening) gives the predictive step SAFETY · (0.1 / 0.5²)^(1/5), shorter than the PI
    /// step; an error falling from 0.5 to 0.1 gives the PI step, the predictive one (longer)
    /// only capping it. The coarse log2/exp2 hold both within 1e-3.
    #[test]
    fn a_rising_error_is_foreseen_a_falling_one_left_to_the_pi_step() {
        let h = 1e-5;
        let mut rising = Controller::default();
        assert!(rising.judge(0.1, h).accept);
        let next = rising.judge(0.5, h).h_next / h;
        let predictive = SAFETY * (0.1_f64 / 0.25).powf(0.2);
        assert!(predictive < pi_factor(0.1, 0.5));
        assert!(
            (next - predictive).abs() < 1e-3 * predictive,
            "{next} vs {predictive}"
        );

        let mut falling = Controller::default();
        assert!(falling.judge(0.5, h).accept);
        let next = falling.judge(0.1, h).h_next / h;
        let pi = pi_factor(0.5, 0.1);
        assert!(pi < SAFETY * (0.5_f64 / 0.01).powf(0.2));
        assert!((next - pi).abs() < 1e-3 * pi, "{next} vs {pi}");
    }
}
