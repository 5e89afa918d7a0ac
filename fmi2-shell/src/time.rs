//! The checks of FMI's time arguments, the same for every model: fmi2SetupExperiment's start
//! time and tolerance, fmi2DoStep's communication point and step size against the instance's
//! time, fmi2SetTime's time.

use crate::status::{FmiError, FmiResult};

/// Why fmi2DoStep refuses a step ([`check_step`]).
#[derive(Clone, Copy, Debug)]
enum StepRefusal {
    /// h not finite and > 0.
    Size,
    /// The communication point is not the instance's time.
    Time,
    /// t + h − t misses h by more than 0.1 % (the value it has).
    Resolution(f64),
}

/// A finite step h > 0 from the instance's time t, that the time axis can represent there to
/// 0.1 %. The communication point may miss t by 1e-9 relative (masters accumulate it, so
/// rounding drift is accepted). Late in a long run a small step may not exist (at t = 1e9 s
/// the spacing of doubles is 1.2e-7 s), and is refused rather than stretched or shrunk.
#[inline]
pub fn check_step(current: f64, h: f64, t: f64) -> FmiResult {
    match accepted(current, h, t) {
        true => Ok(()),
        false => Err(step_refused(current, h, t)),
    }
}

/// The three tests of [`check_step`] in plain comparisons, run at every fmi2DoStep: each is
/// written so that a NaN fails it (a comparison with NaN is false), and an infinite h or
/// current fails the drift or the resolution test (∞ − ∞ is NaN), t being finite (the start
/// time, then the ends of accepted steps). `is_finite` and `f64::max` would cost several
/// times these instructions; the reason of a refusal is sought apart ([`refusal`]).
#[inline]
fn accepted(current: f64, h: f64, t: f64) -> bool {
    let t_abs = t.abs();
    let scale = if h > t_abs { h } else { t_abs };
    let scale = if scale > 1e-3 { scale } else { 1e-3 };
    let resolved = (current + h) - current;
    h > 0.0 && (current - t).abs() <= 1e-9 * scale && (resolved - h).abs() <= 1e-3 * h
}

/// Why [`accepted`] refuses a step: the first test it fails.
fn refusal(current: f64, h: f64, t: f64) -> StepRefusal {
    if !(h > 0.0 && h.is_finite()) {
        return StepRefusal::Size;
    }
    if !current.is_finite() || (current - t).abs() > 1e-9 * t.abs().max(h).max(1e-3) {
        return StepRefusal::Time;
    }
    StepRefusal::Resolution((current + h) - current)
}

/// The message of a refused step (kept off the path of a valid one).
#[cold]
#[inline(never)]
fn step_refused(current: f64, h: f64, t: f64) -> FmiError {
    FmiError::error(match refusal(current, h, t) {
        StepRefusal::Size => format!(
            "communicationStepSize = {h:e} at t = {current} refused: it must be finite and > 0"
        ),
        StepRefusal::Time => {
            format!("currentCommunicationPoint = {current} does not match the instance's time {t}")
        }
        StepRefusal::Resolution(resolved) => format!(
            "communicationStepSize = {h:e} at t = {current} is below the resolution of time there (t + h - t = {resolved:e} s): refused"
        ),
    })
}

/// fmi2SetupExperiment: a finite start time and, if defined, a relative tolerance in (0, 1).
pub fn check_experiment(tolerance: Option<f64>, start_time: f64) -> FmiResult {
    if !start_time.is_finite() {
        return Err(FmiError::error(format!(
            "startTime = {start_time} must be finite"
        )));
    }
    match tolerance {
        Some(tol) if !(tol > 0.0 && tol < 1.0) => Err(FmiError::error(format!(
            "tolerance = {tol:e} must lie in (0, 1)"
        ))),
        _ => Ok(()),
    }
}

/// fmi2SetTime: a finite time.
pub fn check_time(t: f64) -> FmiResult {
    if t.is_finite() {
        Ok(())
    } else {
        Err(FmiError::error(format!(
            "time = {t} refused: it must be finite"
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refused(current: f64, h: f64, t: f64) -> String {
        check_step(current, h, t).unwrap_err().message
    }

    /// Steps that are not finite and positive, from another time, or below the resolution of
    /// time are refused with their reason; a communication point that drifted by rounding is
    /// accepted.
    #[test]
    fn steps_are_checked_against_the_instance_time() {
        assert!(refused(0.0, 0.0, 0.0).contains("finite and > 0"));
        assert!(refused(0.0, f64::NAN, 0.0).contains("finite and > 0"));
        assert!(refused(0.0, f64::INFINITY, 0.0).contains("finite and > 0"));
        assert!(refused(1.0, 1e-3, 0.5).contains("does not match"));
        assert!(refused(f64::NAN, 1e-3, 0.5).contains("does not match"));
        assert!(refused(f64::NEG_INFINITY, 1e-3, 0.5).contains("does not match"));
        assert!(refused(-1e-3, f64::NAN, 0.0).contains("finite and > 0"));
        assert!(refused(1e9, 1e-7, 1e9).contains("resolution of time"));
        let drifted = (0..1000).fold(0.0, |t, _| t + 1e-4);
        check_step(drifted, 1e-4, 0.1).unwrap();
        check_step(0.1, 1e-4, drifted).unwrap();
    }

    /// The comparisons of the accepted path agree with the tests written with `is_finite`
    /// and `f64::max`, over finite, infinite and NaN arguments and the edges of each test.
    #[test]
    fn the_fast_test_agrees_with_the_plain_one() {
        let values = [
            0.0,
            -0.0,
            1e-300,
            1e-9,
            1e-4,
            1e-3,
            0.1,
            0.1 + 1e-12,
            0.5,
            1.0,
            1e9,
            1e9 + 1e-7,
            -1e-4,
            -1.0,
            f64::MAX,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for &current in &values {
            for &h in &values {
                for t in values.into_iter().filter(|t| t.is_finite()) {
                    let plain = h > 0.0
                        && h.is_finite()
                        && current.is_finite()
                        && (current - t).abs() <= 1e-9 * t.abs().max(h).max(1e-3)
                        && (((current + h) - current) - h).abs() <= 1e-3 * h;
                    assert_eq!(accepted(current, h, t), plain, "{current} {h} {t}");
                }
            }
        }
    }

    #[test]
    fn experiment_and_time_are_finite() {
        assert!(check_experiment(None, f64::NAN).is_err());
        assert!(check_experiment(Some(0.0), 0.0).is_err());
        assert!(check_experiment(Some(1.0), 0.0).is_err());
        check_experiment(Some(1e-6), -1.0).unwrap();
        assert!(check_time(f64::INFINITY).is_err());
        check_time(-3.0).unwrap();
    }
}
