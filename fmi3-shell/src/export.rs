//! What the `fmi3*` exports ([`export_fmi3!`](crate::export_fmi3)) do beyond calling the
//! instance: instantiation of each interface, FMI 3.0's value references on the slave's
//! (Real ones as they are, Integer ones moved, arrays as their elements, the time and the
//! event indicators as variables), the answers FMI 3.0 asks through pointers, and the adjoint derivatives.
#![allow(clippy::missing_safety_doc)]

use crate::arrays;
use fmi_sys::fmi3::*;
use fmi2_shell::component::{Component, slice_mut};
use fmi2_shell::contract::fmi3::{Array, EVENT_INDICATOR_VR, INTEGER_VR_OFFSET, TIME_VR};
use fmi2_shell::contract::{Kind, unknown};
use fmi2_shell::export::{check_token, create};
use fmi2_shell::fmu::IntermediateUpdate;
use fmi2_shell::logger::Logger;
use fmi2_shell::{
    CoSimulationEvents, EventInfo, FmiError, FmiResult, FmiState, Fmu, Interface, Slave,
};

/// fmi3InstantiateModelExchange and fmi3InstantiateCoSimulation: an instance of the
/// interface `wanted` if the token is this binary's (or a packed model description's beside
/// `resource_path`) and the model offers the interface, else NULL and a log line (`wanted`
/// is the reason the caller found in the interface's own arguments to refuse).
#[allow(clippy::too_many_arguments)] // FMI 3.0's arguments, as the exports receive them
pub unsafe fn instantiate<S: Slave>(
    function: &str,
    wanted: Result<Interface, &str>,
    instance_name: fmi3String,
    token: fmi3String,
    resource_path: fmi3String,
    logging_on: bool,
    environment: fmi3InstanceEnvironment,
    log_message: fmi3LogMessageCallback,
) -> fmi3Instance {
    let check = || {
        let interface = wanted.map_err(FmiError::error)?;
        if interface == Interface::ModelExchange && !S::IDENTITY.model_exchange {
            return Err(FmiError::error(format!(
                "{} does not offer Model Exchange",
                S::IDENTITY.model_identifier
            )));
        }
        // SAFETY: the importer's string arguments.
        let starts = unsafe { check_token::<S>(token, resource_path) }?;
        Ok((interface, starts))
    };
    // SAFETY: the importer's arguments.
    unsafe {
        create::<S>(
            function,
            instance_name,
            |name| Logger::fmi3(log_message, environment, name),
            check,
            logging_on,
        )
    }
}

/// fmi3InstantiateCoSimulation: an instance as [`instantiate`] makes it, with the events the
/// importer allows (eventModeUsed refused for a model whose steps do not end at events) and
/// its intermediateUpdate callback (NULL: none).
#[allow(clippy::too_many_arguments)] // FMI 3.0's arguments, as the exports receive them
pub unsafe fn instantiate_co_simulation<S: Slave>(
    instance_name: fmi3String,
    token: fmi3String,
    resource_path: fmi3String,
    logging_on: bool,
    event_mode_used: bool,
    early_return_allowed: bool,
    environment: fmi3InstanceEnvironment,
    log_message: fmi3LogMessageCallback,
    intermediate_update: fmi3IntermediateUpdateCallback,
) -> fmi3Instance {
    let wanted = match event_mode_used && !S::STEPS_TO_EVENTS {
        false => Ok(Interface::CoSimulation),
        true => Err(
            "eventModeUsed = true refused: hasEventMode is false (events are handled inside fmi3DoStep)",
        ),
    };
    // SAFETY: the importer's arguments.
    let instance = unsafe {
        instantiate::<S>(
            "fmi3InstantiateCoSimulation",
            wanted,
            instance_name,
            token,
            resource_path,
            logging_on,
            environment,
            log_message,
        )
    };
    // SAFETY: NULL, or the instance just made by fmi2-shell's `create`, a Component<S>.
    if let Some(component) = unsafe { (instance as *mut Component<S>).as_mut() } {
        component.fmu.events = CoSimulationEvents {
            early_return_allowed,
            event_mode_used,
            intermediate_update: intermediate_update.map(|update| (update, environment)),
        };
    }
    instance
}

/// fmi3EnterEventMode: Model Exchange's, or Co-Simulation's where the importer set
/// eventModeUsed.
pub fn enter_event_mode<S: Slave>(fmu: &mut Fmu<S>) -> FmiResult {
    if fmu.interface() == Interface::CoSimulation && !fmu.events.event_mode_used {
        return Err(FmiError::error(
            "fmi3EnterEventMode in Co-Simulation needs eventModeUsed = true at instantiation",
        ));
    }
    fmu.enter_event_mode()
}

/// fmi3EnterStepMode: from Co-Simulation's event mode back to stepping.
pub fn enter_step_mode<S: Slave>(fmu: &mut Fmu<S>) -> FmiResult {
    if fmu.interface() != Interface::CoSimulation {
        return Err(FmiError::error(
            "fmi3EnterStepMode: a Model Exchange instance has no step mode",
        ));
    }
    fmu.state = FmiState::StepComplete;
    Ok(())
}

/// fmi3UpdateDiscreteStates: Model Exchange's event iteration; in Co-Simulation's event mode
/// the step has handled the event already (an impact changes no discrete state the importer
/// sets), so nothing is left to update.
pub fn new_discrete_states<S: Slave>(fmu: &mut Fmu<S>) -> FmiResult<EventInfo> {
    match fmu.interface() {
        Interface::CoSimulation => Ok(EventInfo::default()),
        Interface::ModelExchange => fmu.slave.new_discrete_states(),
    }
}

/// FMI 3.0's nValues for scalar variables: one value per reference.
pub fn scalars(n_vr: usize, n_values: usize) -> FmiResult {
    if n_vr == n_values {
        Ok(())
    } else {
        Err(FmiError::error(format!(
            "nValues = {n_values} for {n_vr} value references: every variable is a scalar"
        )))
    }
}

/// The contract's Integer references of FMI 3.0's ones (Int32 and Enumeration variables).
fn contract_integers(vrs: &[u32]) -> FmiResult<Vec<u32>> {
    vrs.iter()
        .map(|&vr| {
            vr.checked_sub(INTEGER_VR_OFFSET)
                .filter(|v| *v < INTEGER_VR_OFFSET)
                .ok_or_else(|| unknown(Kind::Integer, vr))
        })
        .collect()
}

/// The slave's Integer references of FMI 3.0's Int32 and Enumeration ones, `n_values` in all
/// ([`arrays::expand`]); a structural parameter is none of them.
fn integer_vrs<S: Slave>(
    fmu: &mut Fmu<S>,
    arrays: &[Array],
    vrs: &[u32],
    n_values: usize,
) -> FmiResult<Vec<u32>> {
    let vrs = contract_integers(vrs)?;
    arrays::no_structural_parameter(arrays, &vrs)?;
    arrays::expand(fmu, arrays, &vrs, n_values)
}

/// fmi3SetFloat64: the slave's Reals (an array's as its elements).
pub fn set_float64<S: Slave>(
    fmu: &mut Fmu<S>,
    arrays: &[Array],
    vrs: &[u32],
    values: &[f64],
) -> FmiResult {
    let vrs = arrays::expand(fmu, arrays, vrs, values.len())?;
    fmu.set_real(&vrs, values)
}

/// fmi3GetFloat64: the slave's Real variables (an array's as its elements,
/// [`arrays::expand`]), the time and the event indicators (the slave's whole vector of
/// `indicators` computed once if any is asked).
pub fn get_float64<S: Slave>(
    fmu: &mut Fmu<S>,
    arrays: &[Array],
    vrs: &[u32],
    out: &mut [f64],
    indicators: usize,
) -> FmiResult {
    let vrs = &arrays::expand(fmu, arrays, vrs, out.len())?;
    if vrs.iter().all(|&vr| vr < TIME_VR) {
        return fmu.slave.get_real(vrs, out);
    }
    let mut z: Option<Vec<f64>> = None;
    for (&vr, out) in vrs.iter().zip(out) {
        let k = vr.wrapping_sub(EVENT_INDICATOR_VR) as usize;
        *out = match vr {
            TIME_VR => fmu.time(),
            _ if vr >= EVENT_INDICATOR_VR && k < indicators => {
                if z.is_none() {
                    let mut values = vec![0.0; indicators];
                    fmu.get_event_indicators(&mut values)?;
                    z = Some(values);
                }
                z.as_ref().expect("computed")[k]
            }
            _ => {
                let mut value = [0.0];
                fmu.slave.get_real(&[vr], &mut value)?;
                value[0]
            }
        };
    }
    Ok(())
}

/// fmi3GetInt32 (Int32 variables) and fmi3GetInt64 (Enumerations): the slave's Integers
/// (an array's as its elements).
pub fn get_integer<S: Slave, T: From<i32>>(
    fmu: &mut Fmu<S>,
    arrays: &[Array],
    vrs: &[u32],
    out: &mut [T],
) -> FmiResult {
    let vrs = integer_vrs(fmu, arrays, vrs, out.len())?;
    let mut values = vec![0; vrs.len()];
    fmu.slave.get_integer(&vrs, &mut values)?;
    for (out, v) in out.iter_mut().zip(values) {
        *out = v.into();
    }
    Ok(())
}

/// fmi3SetInt32 and fmi3SetInt64: the slave's Integers (an array's as its elements), a
/// value beyond Int32 refused.
pub fn set_integer<S: Slave, T: Copy + std::fmt::Display>(
    fmu: &mut Fmu<S>,
    arrays: &[Array],
    vrs: &[u32],
    values: &[T],
) -> FmiResult
where
    i32: TryFrom<T>,
{
    let vrs = integer_vrs(fmu, arrays, vrs, values.len())?;
    let values = values
        .iter()
        .map(|&v| {
            i32::try_from(v)
                .map_err(|_| FmiError::error(format!("{v} is beyond the variables' range")))
        })
        .collect::<FmiResult<Vec<i32>>>()?;
    fmu.set_integer(&vrs, &values)
}

/// fmi3GetAdjointDerivative: sensitivity_j = sum_i seed_i dUnknown_i/dKnown_j, each column
/// of the Jacobian one directional derivative of the slave along known j.
pub fn adjoint_derivative<S: Slave>(
    fmu: &mut Fmu<S>,
    unknowns: &[u32],
    knowns: &[u32],
    seed: &[f64],
    sensitivity: &mut [f64],
) -> FmiResult {
    let mut column = vec![0.0; unknowns.len()];
    for (known, out) in knowns.iter().zip(sensitivity) {
        fmu.slave
            .directional_derivative(unknowns, &[*known], &[1.0], &mut column)?;
        *out = column.iter().zip(seed).map(|(j, v)| j * v).sum();
    }
    Ok(())
}

/// Writes `value` where the importer's pointer points (a NULL one is not written).
pub unsafe fn answer<T>(out: *mut T, value: T) {
    // SAFETY: NULL or the importer's pointer to one value.
    if let Some(out) = unsafe { out.as_mut() } {
        *out = value;
    }
}

/// fmi3DoStep: the step and its last successful time; it never asks for the end of the
/// simulation. Without an intermediateUpdate callback it ends early at the model's first
/// event inside it where the importer allowed early return; with one it calls it at each
/// event and ends early there where the importer requests it (event handling then needed if
/// it uses event mode).
pub unsafe fn do_step<S: Slave>(
    fmu: &mut Fmu<S>,
    current: f64,
    h: f64,
    event_handling_needed: *mut bool,
    terminate_simulation: *mut bool,
    early_return: *mut bool,
    last_successful_time: *mut f64,
) -> FmiResult {
    let done = match fmu.events.intermediate_update {
        None => fmu.do_step_to_event(current, h),
        Some(update) => {
            let can_return_early = fmu.events.early_return_allowed;
            fmu.do_step_through_events(current, h, |t| {
                // SAFETY: the importer's callback and environment.
                unsafe { intermediate_update(update, t, can_return_early) }
            })
        }
    };
    let early = done.as_ref().is_ok_and(|&reached| reached < current + h);
    // SAFETY: the importer's pointers.
    unsafe {
        answer(event_handling_needed, early && fmu.events.event_mode_used);
        answer(terminate_simulation, false);
        answer(early_return, early);
        answer(last_successful_time, fmu.last_successful_time());
    }
    done.map(|_| ())
}

/// The importer's intermediateUpdate at the event at `t`, the step there finished (the
/// intermediate variables neither set nor got); whether it requests the return there (only
/// where `can_return_early`). A later earlyReturnTime is not integrated to: the FMU returns
/// at the event, which FMI 3.0 allows.
unsafe fn intermediate_update(
    (update, environment): (IntermediateUpdate, *mut std::ffi::c_void),
    t: f64,
    can_return_early: bool,
) -> bool {
    let (mut requested, mut early_return_time) = (false, t);
    // SAFETY: the importer's callback with its environment and two pointers to locals.
    unsafe {
        update(
            environment,
            t,
            false,
            false,
            true,
            can_return_early,
            &mut requested,
            &mut early_return_time,
        )
    };
    can_return_early && requested
}

/// fmi3UpdateDiscreteStates's answers.
pub unsafe fn update_discrete_states(
    e: EventInfo,
    needs_update: *mut bool,
    terminate_simulation: *mut bool,
    nominals_changed: *mut bool,
    values_changed: *mut bool,
    next_event_time_defined: *mut bool,
    next_event_time: *mut f64,
) {
    // SAFETY: the importer's pointers.
    unsafe {
        answer(needs_update, e.new_discrete_states_needed);
        answer(terminate_simulation, e.terminate_simulation);
        answer(nominals_changed, e.nominals_of_continuous_states_changed);
        answer(values_changed, e.values_of_continuous_states_changed);
        answer(next_event_time_defined, e.next_event_time.is_some());
        answer(next_event_time, e.next_event_time.unwrap_or(0.0));
    }
}

/// fmi3GetNumberOf{ContinuousStates,EventIndicators}.
pub unsafe fn number(out: *mut usize, n: usize) -> FmiResult {
    // SAFETY: the importer's pointer to one value.
    unsafe { slice_mut(out, 1, "number") }?[0] = n;
    Ok(())
}

/// The error of a function of what this FMU does not offer.
pub fn not_offered(what: &str) -> FmiResult {
    Err(FmiError::error(format!(
        "{what} not offered: the model description declares none"
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// FMI 3.0's Integer references are the contract's moved by the offset; a Real's, the
    /// time's or an indicator's is no Integer.
    #[test]
    fn integer_references_are_moved_by_the_offset() {
        assert_eq!(
            contract_integers(&[INTEGER_VR_OFFSET + 102, INTEGER_VR_OFFSET]).unwrap(),
            [102, 0]
        );
        for vr in [102, TIME_VR, EVENT_INDICATOR_VR + 1] {
            assert!(contract_integers(&[vr]).is_err(), "{vr}");
        }
        assert!(scalars(3, 3).is_ok() && scalars(3, 4).is_err());
    }
}
