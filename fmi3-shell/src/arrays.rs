//! FMI 3.0's array variables on the slave's scalar ones: an array's value reference stands
//! for its first n elements (n the value of its structural parameter, set in configuration
//! mode), the continuous states in FMI 3.0's order (an array's elements together) on the
//! slave's (element by element), and the structural parameters themselves (UInt64).
//!
//! The layout is the contract's ([`Array`], generated as `FMI3_ARRAYS`); a model without
//! arrays has none, and every reference stands for itself.

use fmi2_shell::contract::fmi3::{Array, INTEGER_VR_OFFSET};
use fmi2_shell::contract::{Kind, unknown};
use fmi2_shell::{FmiError, FmiResult, FmiState, Fmu, Slave};

/// The array's current length: its structural parameter's value.
fn length<S: Slave>(fmu: &mut Fmu<S>, a: &Array) -> FmiResult<usize> {
    let mut n = [0];
    fmu.slave.get_integer(&[a.size_vr], &mut n)?;
    Ok(n[0] as usize)
}

/// The slave's references (contract numbering) of FMI 3.0's `vrs` given as contract ones
/// of one kind: an array variable's are its first n elements', any other stands for itself.
/// `n_values` must be their number (FMI 3.0's nValues).
pub fn expand<S: Slave>(
    fmu: &mut Fmu<S>,
    arrays: &[Array],
    vrs: &[u32],
    n_values: usize,
) -> FmiResult<Vec<u32>> {
    let mut out = Vec::with_capacity(n_values);
    for &vr in vrs {
        match arrays.iter().find_map(|a| Some((a, a.offset(vr)?))) {
            Some((a, k)) => {
                let n = length(fmu, a)?;
                out.extend(a.elements(k, n));
            }
            None => out.push(vr),
        }
    }
    if out.len() == n_values {
        Ok(out)
    } else {
        Err(FmiError::error(format!(
            "nValues = {n_values} for value references {vrs:?}, which hold {} values (an array variable as many as its structural parameter says)",
            out.len()
        )))
    }
}

/// The array whose structural parameter has the FMI 3.0 reference `vr` (UInt64).
fn sized_by(arrays: &[Array], vr: u32) -> FmiResult<&Array> {
    arrays
        .iter()
        .find(|a| a.size_vr + INTEGER_VR_OFFSET == vr)
        .ok_or_else(|| {
            FmiError::error(format!(
                "unknown value reference {vr} for type UInt64: the UInt64 variables are the structural parameters"
            ))
        })
}

/// Refuses a structural parameter where an Int32 or Enumeration is read or set (contract
/// references).
pub fn no_structural_parameter(arrays: &[Array], vrs: &[u32]) -> FmiResult {
    match vrs
        .iter()
        .find(|vr| arrays.iter().any(|a| a.size_vr == **vr))
    {
        Some(vr) => Err(FmiError::error(format!(
            "value reference {} is a structural parameter, of type UInt64 (fmi3GetUInt64, fmi3SetUInt64 in configuration mode)",
            vr + INTEGER_VR_OFFSET
        ))),
        None => Ok(()),
    }
}

/// fmi3GetUInt64: the structural parameters.
pub fn get_uint64<S: Slave>(
    fmu: &mut Fmu<S>,
    arrays: &[Array],
    vrs: &[u32],
    out: &mut [u64],
) -> FmiResult {
    for (&vr, out) in vrs.iter().zip(out) {
        *out = length(fmu, sized_by(arrays, vr)?)? as u64;
    }
    Ok(())
}

/// fmi3SetUInt64: the structural parameters, in configuration mode only, each within
/// 1..=its array's size.
pub fn set_uint64<S: Slave>(
    fmu: &mut Fmu<S>,
    arrays: &[Array],
    vrs: &[u32],
    values: &[u64],
) -> FmiResult {
    for (&vr, &n) in vrs.iter().zip(values) {
        let a = sized_by(arrays, vr)?;
        let name = (S::IDENTITY.variable)(Kind::Integer, a.size_vr)?.name;
        if fmu.state != FmiState::ConfigurationMode {
            return Err(FmiError::error(format!(
                "{name} is a structural parameter: set it in configuration mode (fmi3EnterConfigurationMode after instantiation)"
            )));
        }
        if !(1..=a.size as u64).contains(&n) {
            return Err(FmiError::error(format!(
                "{name} = {n} refused: 1 <= {name} <= {}",
                a.size
            )));
        }
        fmu.set_integer(&[a.size_vr], &[n as i32])?;
    }
    Ok(())
}

/// fmi3EnterConfigurationMode (from Instantiated) and fmi3ExitConfigurationMode (back to it),
/// for a model with structural parameters.
pub fn configuration_mode<S: Slave>(fmu: &mut Fmu<S>, arrays: &[Array], enter: bool) -> FmiResult {
    let function = match enter {
        true => "fmi3EnterConfigurationMode",
        false => "fmi3ExitConfigurationMode",
    };
    if arrays.is_empty() {
        return crate::export::not_offered(&format!("{function}: structural parameters are"));
    }
    let (from, to) = match enter {
        true => (FmiState::Instantiated, FmiState::ConfigurationMode),
        false => (FmiState::ConfigurationMode, FmiState::Instantiated),
    };
    if fmu.state != from {
        return Err(FmiError::error(format!(
            "{function} is allowed in state {from:?} only, not {:?}",
            fmu.state
        )));
    }
    fmu.state = to;
    Ok(())
}

/// FMI 3.0's continuous-state vector as indices into the slave's (`states`, the contract's
/// state references in the slave's order): the states in order of first appearance, an
/// array's elements 1..n together where it first appears.
pub fn state_order<S: Slave>(
    fmu: &mut Fmu<S>,
    arrays: &[Array],
    states: &[u32],
) -> FmiResult<Vec<usize>> {
    let mut order = Vec::with_capacity(states.len());
    let mut seen: Vec<(usize, u32)> = Vec::new();
    for &vr in states {
        let Some((j, a, k)) = arrays
            .iter()
            .enumerate()
            .find_map(|(j, a)| Some((j, a, a.element_offset(vr)?)))
        else {
            order.push(vr);
            continue;
        };
        if !seen.contains(&(j, k)) {
            seen.push((j, k));
            let n = length(fmu, a)?;
            order.extend(a.elements(k, n));
        }
    }
    order
        .iter()
        .map(|vr| {
            states
                .iter()
                .position(|s| s == vr)
                .ok_or_else(|| unknown(Kind::Real, *vr))
        })
        .collect()
}

/// Checks the importer's vector length against FMI 3.0's number of states.
fn states_length(order: &[usize], n: usize) -> FmiResult {
    if order.len() == n {
        Ok(())
    } else {
        Err(FmiError::error(format!(
            "{n} values for {} continuous states",
            order.len()
        )))
    }
}

/// One of the model's state-sized vectors (`read` fills it, fmi2-shell's checks) in FMI
/// 3.0's order.
pub fn gather<S: Slave>(
    fmu: &mut Fmu<S>,
    arrays: &[Array],
    states: &[u32],
    out: &mut [f64],
    read: impl FnOnce(&mut Fmu<S>, &mut [f64]) -> FmiResult,
) -> FmiResult {
    let order = state_order(fmu, arrays, states)?;
    states_length(&order, out.len())?;
    let mut all = vec![0.0; states.len()];
    read(fmu, &mut all)?;
    for (out, &i) in out.iter_mut().zip(&order) {
        *out = all[i];
    }
    Ok(())
}

/// fmi3SetContinuousStates: FMI 3.0's states in the slave's vector, the others (elements
/// beyond n) as they are.
pub fn set_continuous_states<S: Slave>(
    fmu: &mut Fmu<S>,
    arrays: &[Array],
    states: &[u32],
    x: &[f64],
) -> FmiResult {
    let order = state_order(fmu, arrays, states)?;
    states_length(&order, x.len())?;
    let mut all = vec![0.0; states.len()];
    fmu.get_continuous_states(&mut all)?;
    for (&x, &i) in x.iter().zip(&order) {
        all[i] = x;
    }
    fmu.set_continuous_states(&all)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The gearbox's layout: gear i's variable of offset k at 1000 + 100 i + k.
    const GEAR: Array = Array {
        size_vr: 1,
        size: 8,
        vr_base: 1000,
        vr_stride: 100,
    };

    #[test]
    fn an_array_reference_stands_for_its_first_elements() {
        assert_eq!(GEAR.offset(1020), Some(20));
        assert_eq!(GEAR.offset(1120), None);
        assert_eq!(GEAR.element_offset(1320), Some(20));
        assert_eq!(GEAR.element_offset(1020), None);
        assert_eq!(GEAR.element_offset(1900), None);
        assert_eq!(GEAR.elements(20, 3).collect::<Vec<_>>(), [1120, 1220, 1320]);
        assert!(no_structural_parameter(&[GEAR], &[2, 1102]).is_ok());
        assert!(no_structural_parameter(&[GEAR], &[2, 1]).is_err());
        assert!(sized_by(&[GEAR], INTEGER_VR_OFFSET + 1).is_ok());
        assert!(sized_by(&[GEAR], 1).is_err());
    }
}
