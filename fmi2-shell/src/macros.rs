//! [`export_co_simulation!`](crate::export_co_simulation) and
//! [`export_model_exchange!`](crate::export_model_exchange): the exported `fmi2*` symbols of a
//! model's cdylib, each a one-line call of the generic body in [`export`](crate::export).

/// Exports every function of FMI 2.0 Co-Simulation for the slave type `$slave` (importers
/// such as fmpy load all of them by name). Invoke once, in the model's cdylib crate.
#[macro_export]
macro_rules! export_co_simulation {
    ($slave:ty) => {
        mod fmi2_exports {
            #![allow(non_snake_case, clippy::missing_safety_doc)]
            use super::*;
            use ::std::ffi::c_char;
            use $crate::export as e;
            use $crate::fmi2::*;
            type S = $slave;

            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
                e::types_platform()
            }
            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2GetVersion() -> *const c_char {
                e::version()
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2Instantiate(
                instanceName: fmi2String,
                fmuType: fmi2Type,
                fmuGUID: fmi2String,
                _fmuResourceLocation: fmi2String,
                functions: *const fmi2CallbackFunctions,
                _visible: fmi2Boolean,
                loggingOn: fmi2Boolean,
            ) -> fmi2Component {
                unsafe { e::instantiate::<S>(instanceName, fmuType, fmuGUID, functions, loggingOn) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
                unsafe { e::free_instance::<S>(c) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetDebugLogging(
                c: fmi2Component,
                loggingOn: fmi2Boolean,
                nCategories: usize,
                categories: *const fmi2String,
            ) -> fmi2Status {
                unsafe { e::set_debug_logging::<S>(c, loggingOn, nCategories, categories) }
            }
            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2SetupExperiment(
                c: fmi2Component,
                toleranceDefined: fmi2Boolean,
                tolerance: fmi2Real,
                startTime: fmi2Real,
                _stopTimeDefined: fmi2Boolean,
                _stopTime: fmi2Real,
            ) -> fmi2Status {
                e::setup_experiment::<S>(c, toleranceDefined, tolerance, startTime)
            }
            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
                e::enter_initialization_mode::<S>(c)
            }
            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
                e::exit_initialization_mode::<S>(c)
            }
            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
                e::terminate::<S>(c)
            }
            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
                e::reset_instance::<S>(c)
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetReal(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                nvr: usize,
                value: *mut fmi2Real,
            ) -> fmi2Status {
                unsafe { e::get_real::<S>(c, vr, nvr, value) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetInteger(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                nvr: usize,
                value: *mut fmi2Integer,
            ) -> fmi2Status {
                unsafe { e::get_integer::<S>(c, vr, nvr, value) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetBoolean(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                nvr: usize,
                _value: *mut fmi2Boolean,
            ) -> fmi2Status {
                unsafe {
                    e::no_variables::<S>(
                        c,
                        "fmi2GetBoolean",
                        $crate::state::allowed::GET,
                        "Boolean",
                        vr,
                        nvr,
                    )
                }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetString(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                nvr: usize,
                _value: *mut fmi2String,
            ) -> fmi2Status {
                unsafe {
                    e::no_variables::<S>(
                        c,
                        "fmi2GetString",
                        $crate::state::allowed::GET,
                        "String",
                        vr,
                        nvr,
                    )
                }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetReal(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                nvr: usize,
                value: *const fmi2Real,
            ) -> fmi2Status {
                unsafe { e::set_real::<S>(c, vr, nvr, value) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetInteger(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                nvr: usize,
                value: *const fmi2Integer,
            ) -> fmi2Status {
                unsafe { e::set_integer::<S>(c, vr, nvr, value) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetBoolean(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                nvr: usize,
                _value: *const fmi2Boolean,
            ) -> fmi2Status {
                unsafe {
                    e::no_variables::<S>(
                        c,
                        "fmi2SetBoolean",
                        $crate::state::allowed::SET,
                        "Boolean",
                        vr,
                        nvr,
                    )
                }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetString(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                nvr: usize,
                _value: *const fmi2String,
            ) -> fmi2Status {
                unsafe {
                    e::no_variables::<S>(
                        c,
                        "fmi2SetString",
                        $crate::state::allowed::SET,
                        "String",
                        vr,
                        nvr,
                    )
                }
            }
            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2DoStep(
                c: fmi2Component,
                currentCommunicationPoint: fmi2Real,
                communicationStepSize: fmi2Real,
                _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
            ) -> fmi2Status {
                e::do_step::<S>(c, currentCommunicationPoint, communicationStepSize)
            }
            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
                e::cancel_step::<S>(c)
            }
            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2GetStatus(
                c: fmi2Component,
                s: fmi2StatusKind,
                _value: *mut fmi2Status,
            ) -> fmi2Status {
                e::get_status::<S>(c, "fmi2GetStatus", s)
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetRealStatus(
                c: fmi2Component,
                s: fmi2StatusKind,
                value: *mut fmi2Real,
            ) -> fmi2Status {
                unsafe { e::get_real_status::<S>(c, s, value) }
            }
            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2GetIntegerStatus(
                c: fmi2Component,
                s: fmi2StatusKind,
                _value: *mut fmi2Integer,
            ) -> fmi2Status {
                e::get_status::<S>(c, "fmi2GetIntegerStatus", s)
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetBooleanStatus(
                c: fmi2Component,
                s: fmi2StatusKind,
                value: *mut fmi2Boolean,
            ) -> fmi2Status {
                unsafe { e::get_boolean_status::<S>(c, s, value) }
            }
            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2GetStringStatus(
                c: fmi2Component,
                s: fmi2StatusKind,
                _value: *mut fmi2String,
            ) -> fmi2Status {
                e::get_status::<S>(c, "fmi2GetStringStatus", s)
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetFMUstate(
                c: fmi2Component,
                state: *mut fmi2FMUstate,
            ) -> fmi2Status {
                unsafe { e::get_fmu_state::<S>(c, state) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetFMUstate(
                c: fmi2Component,
                state: fmi2FMUstate,
            ) -> fmi2Status {
                unsafe { e::set_fmu_state::<S>(c, state) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2FreeFMUstate(
                c: fmi2Component,
                state: *mut fmi2FMUstate,
            ) -> fmi2Status {
                unsafe { e::free_fmu_state::<S>(c, state) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
                c: fmi2Component,
                state: fmi2FMUstate,
                size: *mut usize,
            ) -> fmi2Status {
                unsafe { e::serialized_fmu_state_size::<S>(c, state, size) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SerializeFMUstate(
                c: fmi2Component,
                state: fmi2FMUstate,
                bytes: *mut fmi2Byte,
                size: usize,
            ) -> fmi2Status {
                unsafe { e::serialize_fmu_state::<S>(c, state, bytes, size) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
                c: fmi2Component,
                bytes: *const fmi2Byte,
                size: usize,
                state: *mut fmi2FMUstate,
            ) -> fmi2Status {
                unsafe { e::deserialize_fmu_state::<S>(c, bytes, size, state) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
                c: fmi2Component,
                vUnknown_ref: *const fmi2ValueReference,
                nUnknown: usize,
                vKnown_ref: *const fmi2ValueReference,
                nKnown: usize,
                dvKnown: *const fmi2Real,
                dvUnknown: *mut fmi2Real,
            ) -> fmi2Status {
                unsafe {
                    e::get_directional_derivative::<S>(
                        c,
                        vUnknown_ref,
                        nUnknown,
                        vKnown_ref,
                        nKnown,
                        dvKnown,
                        dvUnknown,
                    )
                }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                nvr: usize,
                order: *const fmi2Integer,
                value: *const fmi2Real,
            ) -> fmi2Status {
                unsafe { e::set_real_input_derivatives::<S>(c, vr, nvr, order, value) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                nvr: usize,
                order: *const fmi2Integer,
                value: *mut fmi2Real,
            ) -> fmi2Status {
                unsafe { e::get_real_output_derivatives::<S>(c, vr, nvr, order, value) }
            }
        }
    };
}

/// Exports the functions of FMI 2.0 Model Exchange for the slave type `$slave`, beside
/// those of [`export_co_simulation!`] (invoke both, once each, in the model's cdylib).
#[macro_export]
macro_rules! export_model_exchange {
    ($slave:ty) => {
        mod fmi2_model_exchange_exports {
            #![allow(non_snake_case, clippy::missing_safety_doc)]
            use super::*;
            use $crate::export as e;
            use $crate::fmi2::*;
            use $crate::slave::Slave as _;
            type S = $slave;

            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2SetTime(c: fmi2Component, time: fmi2Real) -> fmi2Status {
                e::set_time::<S>(c, time)
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetContinuousStates(
                c: fmi2Component,
                x: *const fmi2Real,
                nx: usize,
            ) -> fmi2Status {
                unsafe { e::set_continuous_states::<S>(c, x, nx) }
            }
            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status {
                e::enter_event_mode::<S>(c)
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2NewDiscreteStates(
                c: fmi2Component,
                info: *mut fmi2EventInfo,
            ) -> fmi2Status {
                unsafe { e::new_discrete_states::<S>(c, info) }
            }
            #[unsafe(no_mangle)]
            pub extern "C" fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status {
                e::enter_continuous_time_mode::<S>(c)
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2CompletedIntegratorStep(
                c: fmi2Component,
                _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
                enterEventMode: *mut fmi2Boolean,
                terminateSimulation: *mut fmi2Boolean,
            ) -> fmi2Status {
                unsafe { e::completed_integrator_step::<S>(c, enterEventMode, terminateSimulation) }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetDerivatives(
                c: fmi2Component,
                derivatives: *mut fmi2Real,
                nx: usize,
            ) -> fmi2Status {
                unsafe {
                    e::get_vector::<S>(c, "fmi2GetDerivatives", derivatives, nx, S::get_derivatives)
                }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetEventIndicators(
                c: fmi2Component,
                eventIndicators: *mut fmi2Real,
                ni: usize,
            ) -> fmi2Status {
                unsafe {
                    e::get_vector::<S>(
                        c,
                        "fmi2GetEventIndicators",
                        eventIndicators,
                        ni,
                        S::get_event_indicators,
                    )
                }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetContinuousStates(
                c: fmi2Component,
                x: *mut fmi2Real,
                nx: usize,
            ) -> fmi2Status {
                unsafe {
                    e::get_vector::<S>(
                        c,
                        "fmi2GetContinuousStates",
                        x,
                        nx,
                        S::get_continuous_states,
                    )
                }
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetNominalsOfContinuousStates(
                c: fmi2Component,
                x_nominal: *mut fmi2Real,
                nx: usize,
            ) -> fmi2Status {
                unsafe {
                    e::get_vector::<S>(
                        c,
                        "fmi2GetNominalsOfContinuousStates",
                        x_nominal,
                        nx,
                        S::get_nominals_of_continuous_states,
                    )
                }
            }
        }
    };
}
