//! Model Exchange's vectors between the importer and a model: the states it sets, the
//! states, nominals, derivatives and event indicators it reads, checked for their length
//! and finiteness in the terms of FMI 2.0 §3.2.

use crate::status::{FmiError, FmiResult};

/// The importer's vector `x` as the model's K states: refused if its length is not K or a
/// value is not finite.
pub fn states<const K: usize>(x: &[f64]) -> FmiResult<&[f64; K]> {
    let x: &[f64; K] = x.try_into().map_err(|_| length_error("x", x.len(), K))?;
    match x.iter().position(|v| !v.is_finite()) {
        Some(bad) => Err(FmiError::error(format!(
            "x[{bad}] = {} refused: the continuous states must be finite",
            x[bad]
        ))),
        None => Ok(x),
    }
}

/// Copies a vector of the model into the importer's array, refused if the lengths differ.
/// A value that overflowed (states or a time beyond what the model can represent) is
/// fmi2Discard, which asks the importer's solver for a smaller step (FMI 2.0 §2.1.3).
pub fn fill<const K: usize>(what: &str, out: &mut [f64], value: [f64; K]) -> FmiResult {
    if out.len() != K {
        return Err(length_error(what, out.len(), K));
    }
    if let Some(bad) = value.iter().position(|v| !v.is_finite()) {
        return Err(FmiError::discard(format!(
            "{what}[{bad}] = {} at these states and time: they are beyond what the model can represent; take a smaller step",
            value[bad]
        )));
    }
    out.copy_from_slice(&value);
    Ok(())
}

fn length_error(what: &str, n: usize, expected: usize) -> FmiError {
    FmiError::error(format!("{what} has {n} elements: the model has {expected}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths_and_values_are_checked() {
        assert_eq!(states::<2>(&[1.0, 2.0]).unwrap(), &[1.0, 2.0]);
        assert!(
            states::<2>(&[1.0])
                .unwrap_err()
                .message
                .contains("1 elements")
        );
        assert!(
            states::<2>(&[1.0, f64::NAN])
                .unwrap_err()
                .message
                .contains("x[1]")
        );
        let mut out = [0.0; 2];
        fill("z", &mut out, [3.0, 4.0]).unwrap();
        assert_eq!(out, [3.0, 4.0]);
        assert!(fill("z", &mut [0.0; 3], [3.0, 4.0]).is_err());
        assert!(fill("z", &mut out, [f64::INFINITY, 4.0]).is_err());
    }
}
