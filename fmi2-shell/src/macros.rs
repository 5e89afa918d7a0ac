//! [`export_co_simulation!`](crate::export_co_simulation) and
//! [`export_model_exchange!`](crate::export_model_exchange): the exported `fmi2*` symbols of a
//! model's cdylib (a generic function cannot be exported, and the symbols must live in the
//! library the importer loads). Each function is written once, as in the Reference-FMUs'
//! `fmi2Functions.c`: its C arguments, the states it may be called in ([`allowed`]), and what
//! it does with the instance ([`Fmu`]: FMI's rules, then the model's slave), run through the
//! [`guard`].
//!
//! [`allowed`]: crate::state::allowed
//! [`guard`]: crate::component::guard
//! [`Fmu`]: crate::fmu::Fmu

/// `array!(p, n)`: the importer's array `p` of `n` elements as a slice (`array!(mut p, n)`: a
/// mutable one), or the call's error naming `p` if it is NULL (see
/// [`slice`](crate::component::slice)).
#[doc(hidden)]
#[macro_export]
macro_rules! array {
    ($p:ident, $n:expr) => {
        unsafe { $crate::component::slice($p, $n, stringify!($p)) }?
    };
    (mut $p:ident, $n:expr) => {
        unsafe { $crate::component::slice_mut($p, $n, stringify!($p)) }?
    };
}

/// Defines the module `$module` of exports for the slave type `$slave` with the C types of
/// `$bindings` (fmi-sys's `fmi2` or `fmi3`, whose instance pointers and statuses are the
/// same C types): the `items` as they are, then each
/// `fn fmiName(args after the instance) ALLOWED |fmu| body;` as `fmiName(instance, args)`,
/// which runs `body` on the instance (`Fmu<$slave>`) through the guard under the name
/// "fmiName" with the mask `$allowed::ALLOWED` (`$allowed` the edition's table). Pointer arguments are the importer's, each
/// valid for the length the call gives (FMI's contract); the bodies turn them into slices
/// with [`array!`](crate::array), which refuses a NULL one.
#[doc(hidden)]
#[macro_export]
macro_rules! exports {
    (mod $module:ident for $slave:ty; use $bindings:path, $table:path; { $($items:item)* } $(
        fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $allowed:ident |$s:pat_param| $body:expr;
    )*) => {
        mod $module {
            #![allow(non_snake_case, clippy::missing_safety_doc)]
            use super::*;
            use $crate::array;
            use $crate::contract::no_variables;
            use $crate::export as e;
            use $bindings::*;
            use $crate::fmu::Fmu;
            use $crate::slave::Slave as _;
            use $crate::status::FmiError;
            type S = $slave;

            $($items)*
            $(
                #[unsafe(no_mangle)]
                pub unsafe extern "C" fn $name(c: *mut ::std::ffi::c_void, $($arg: $ty),*) -> ::std::ffi::c_uint {
                    use $table as allowed;
                    $crate::component::guard(c, stringify!($name), allowed::$allowed, |$s: &mut Fmu<S>| $body)
                }
            )*
        }
    };
}

/// Exports every function of FMI 2.0 Co-Simulation for the slave type `$slave` (importers
/// such as fmpy load all of them by name). Invoke once, in the model's cdylib crate.
#[macro_export]
macro_rules! export_co_simulation {
    ($slave:ty) => {
        $crate::exports! { mod fmi2_exports for $slave; use $crate::fmi2, $crate::state::allowed; {
            use ::std::ffi::c_char;
            use $crate::fmu_state;

            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
                c"default".as_ptr()
            }
            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2GetVersion() -> *const c_char {
                c"2.0".as_ptr()
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2Instantiate(
                instanceName: fmi2String,
                fmuType: fmi2Type,
                fmuGUID: fmi2String,
                fmuResourceLocation: fmi2String,
                functions: *const fmi2CallbackFunctions,
                _visible: fmi2Boolean,
                loggingOn: fmi2Boolean,
            ) -> fmi2Component {
                unsafe { e::instantiate::<S>(instanceName, fmuType, fmuGUID, fmuResourceLocation, functions, loggingOn) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
                unsafe { e::free_instance::<S>(c) }
            }
            }

            fn fmi2SetDebugLogging(loggingOn: fmi2Boolean, nCategories: usize, categories: *const fmi2String)
                SET_DEBUG_LOGGING |s| {
                    let names = unsafe { e::category_names(categories, nCategories) }?;
                    s.log().set_debug_logging(loggingOn != 0, &names)
                };
            fn fmi2SetupExperiment(toleranceDefined: fmi2Boolean, tolerance: fmi2Real, startTime: fmi2Real,
                _stopTimeDefined: fmi2Boolean, _stopTime: fmi2Real)
                SETUP_EXPERIMENT |s| s.setup_experiment((toleranceDefined != 0).then_some(tolerance), startTime);
            fn fmi2EnterInitializationMode() ENTER_INITIALIZATION_MODE |s| s.enter_initialization_mode();
            fn fmi2ExitInitializationMode() EXIT_INITIALIZATION_MODE |s| s.exit_initialization_mode();
            fn fmi2Terminate() TERMINATE |s| s.terminate();
            fn fmi2Reset() RESET |s| s.reset();

            fn fmi2GetReal(vr: *const fmi2ValueReference, nvr: usize, value: *mut fmi2Real)
                GET |s| s.slave.get_real(array!(vr, nvr), array!(mut value, nvr));
            fn fmi2GetInteger(vr: *const fmi2ValueReference, nvr: usize, value: *mut fmi2Integer)
                GET |s| s.slave.get_integer(array!(vr, nvr), array!(mut value, nvr));
            fn fmi2GetBoolean(vr: *const fmi2ValueReference, nvr: usize, _value: *mut fmi2Boolean)
                GET |_| no_variables("Boolean", array!(vr, nvr));
            fn fmi2GetString(vr: *const fmi2ValueReference, nvr: usize, _value: *mut fmi2String)
                GET |_| no_variables("String", array!(vr, nvr));
            fn fmi2SetReal(vr: *const fmi2ValueReference, nvr: usize, value: *const fmi2Real)
                SET |s| s.set_real(array!(vr, nvr), array!(value, nvr));
            fn fmi2SetInteger(vr: *const fmi2ValueReference, nvr: usize, value: *const fmi2Integer)
                SET |s| s.set_integer(array!(vr, nvr), array!(value, nvr));
            fn fmi2SetBoolean(vr: *const fmi2ValueReference, nvr: usize, _value: *const fmi2Boolean)
                SET |_| no_variables("Boolean", array!(vr, nvr));
            fn fmi2SetString(vr: *const fmi2ValueReference, nvr: usize, _value: *const fmi2String)
                SET |_| no_variables("String", array!(vr, nvr));

            fn fmi2DoStep(currentCommunicationPoint: fmi2Real, communicationStepSize: fmi2Real,
                _noSetFMUStatePriorToCurrentPoint: fmi2Boolean)
                DO_STEP |s| s.do_step(currentCommunicationPoint, communicationStepSize);
            // Outside FMI: nSamples steps of sampleInterval, the Real variables vr read after
            // each into values (nSamples rows of nvr), in one call (fmu::sampled).
            fn gearRattleDoStepSampled(currentCommunicationPoint: fmi2Real, sampleInterval: fmi2Real,
                nSamples: usize, vr: *const fmi2ValueReference, nvr: usize, values: *mut fmi2Real)
                DO_STEP |s| {
                    let len = nSamples.checked_mul(nvr).ok_or_else(|| FmiError::error(format!(
                        "nSamples = {nSamples} rows of nvr = {nvr} values overflow")))?;
                    s.do_step_sampled(currentCommunicationPoint, sampleInterval, nSamples,
                        array!(vr, nvr), array!(mut values, len))
                };
            fn fmi2CancelStep() CANCEL_STEP |_| Ok(());
            fn fmi2GetStatus(kind: fmi2StatusKind, _value: *mut fmi2Status)
                GET_STATUS |_| e::unavailable(kind);
            fn fmi2GetRealStatus(kind: fmi2StatusKind, value: *mut fmi2Real) GET_STATUS |s| unsafe {
                e::status(kind, fmi2StatusKind_fmi2LastSuccessfulTime, value, s.last_successful_time())
            };
            fn fmi2GetIntegerStatus(kind: fmi2StatusKind, _value: *mut fmi2Integer)
                GET_STATUS |_| e::unavailable(kind);
            // The slave never asks the master to end the simulation.
            fn fmi2GetBooleanStatus(kind: fmi2StatusKind, value: *mut fmi2Boolean)
                GET_STATUS |_| unsafe { e::status(kind, fmi2StatusKind_fmi2Terminated, value, 0) };
            fn fmi2GetStringStatus(kind: fmi2StatusKind, _value: *mut fmi2String)
                GET_STATUS |_| e::unavailable(kind);

            fn fmi2GetFMUstate(state: *mut fmi2FMUstate)
                FMU_STATE |s| unsafe { fmu_state::store(state, s.snapshot()) };
            fn fmi2SetFMUstate(state: fmi2FMUstate)
                FMU_STATE |s| s.restore(&unsafe { fmu_state::get::<S>(state) }?.fmu);
            fn fmi2FreeFMUstate(state: *mut fmi2FMUstate)
                FMU_STATE |_| unsafe { fmu_state::free::<S>(state) };
            fn fmi2SerializedFMUstateSize(state: fmi2FMUstate, size: *mut usize)
                FMU_STATE |_| unsafe { fmu_state::serialized_size::<S>(state, size) };
            fn fmi2SerializeFMUstate(state: fmi2FMUstate, bytes: *mut fmi2Byte, size: usize)
                FMU_STATE |_| unsafe {
                    fmu_state::serialize_into::<S>(state, bytes as *mut u8, size, "fmi2SerializedFMUstateSize")
                };
            fn fmi2DeSerializeFMUstate(bytes: *const fmi2Byte, size: usize, state: *mut fmi2FMUstate)
                FMU_STATE |_| unsafe { fmu_state::deserialize_from::<S>(bytes as *const u8, size, state) };

            fn fmi2GetDirectionalDerivative(vUnknown_ref: *const fmi2ValueReference, nUnknown: usize,
                vKnown_ref: *const fmi2ValueReference, nKnown: usize, dvKnown: *const fmi2Real,
                dvUnknown: *mut fmi2Real)
                GET |s| s.slave.directional_derivative(array!(vUnknown_ref, nUnknown), array!(vKnown_ref, nKnown),
                    array!(dvKnown, nKnown), array!(mut dvUnknown, nUnknown));
            fn fmi2SetRealInputDerivatives(vr: *const fmi2ValueReference, nvr: usize,
                order: *const fmi2Integer, value: *const fmi2Real)
                SET |s| s.set_input_derivatives(array!(vr, nvr), array!(order, nvr), array!(value, nvr));
            fn fmi2GetRealOutputDerivatives(vr: *const fmi2ValueReference, nvr: usize,
                order: *const fmi2Integer, value: *mut fmi2Real)
                GET |s| s.slave.get_output_derivatives(array!(vr, nvr), array!(order, nvr), array!(mut value, nvr));
        }
    };
}

/// Exports the functions of FMI 2.0 Model Exchange for the slave type `$slave`, beside
/// those of [`export_co_simulation!`] (invoke both, once each, in the model's cdylib).
#[macro_export]
macro_rules! export_model_exchange {
    ($slave:ty) => {
        $crate::exports! { mod fmi2_model_exchange_exports for $slave; use $crate::fmi2, $crate::state::allowed; {}
            fn fmi2SetTime(time: fmi2Real) SET_TIME |s| s.set_time(time);
            fn fmi2SetContinuousStates(x: *const fmi2Real, nx: usize)
                SET_CONTINUOUS_STATES |s| s.set_continuous_states(array!(x, nx));
            fn fmi2EnterEventMode() ENTER_EVENT_MODE |s| s.enter_event_mode();
            fn fmi2NewDiscreteStates(info: *mut fmi2EventInfo) NEW_DISCRETE_STATES |s| {
                let Some(out) = (unsafe { info.as_mut() }) else {
                    return Err(FmiError::error("fmi2EventInfo is NULL"));
                };
                e::event_info(s.slave.new_discrete_states()?, out);
                Ok(())
            };
            fn fmi2EnterContinuousTimeMode() ENTER_CONTINUOUS_TIME_MODE |s| s.enter_continuous_time_mode();
            // Pointers that are NULL are not written.
            fn fmi2CompletedIntegratorStep(_noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
                enterEventMode: *mut fmi2Boolean, terminateSimulation: *mut fmi2Boolean)
                COMPLETED_INTEGRATOR_STEP |s| {
                    let event = s.completed_integrator_step()?;
                    if let Some(out) = unsafe { enterEventMode.as_mut() } {
                        *out = event.into();
                    }
                    if let Some(out) = unsafe { terminateSimulation.as_mut() } {
                        *out = 0;
                    }
                    Ok(())
                };
            fn fmi2GetDerivatives(derivatives: *mut fmi2Real, nx: usize) GET_CONTINUOUS
                |s| s.get_derivatives(array!(mut derivatives, nx));
            fn fmi2GetEventIndicators(eventIndicators: *mut fmi2Real, ni: usize) GET_CONTINUOUS
                |s| s.get_event_indicators(array!(mut eventIndicators, ni));
            fn fmi2GetContinuousStates(x: *mut fmi2Real, nx: usize) GET_CONTINUOUS
                |s| s.get_continuous_states(array!(mut x, nx));
            fn fmi2GetNominalsOfContinuousStates(x_nominal: *mut fmi2Real, nx: usize) GET_CONTINUOUS
                |s| s.get_nominals_of_continuous_states(array!(mut x_nominal, nx));
        }
    };
}
