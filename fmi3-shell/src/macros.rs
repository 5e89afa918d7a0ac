//! [`export_fmi3!`](crate::export_fmi3): the exported `fmi3*` symbols of a model's cdylib,
//! each written once through fmi2-shell's `exports!` (the guard with this crate's
//! [`allowed`](crate::state::allowed) table), beside the `fmi2*` ones of the same slave.

/// Exports every function of FMI 3.0 (Model Exchange and Co-Simulation; scheduled
/// execution, clocks and configuration mode refused) for the slave type `$slave`, whose
/// generated contract module `$contract` gives the continuous states (STATES) and the number of event
/// indicators. Invoke once, in the model's cdylib crate, beside fmi2-shell's exports.
#[macro_export]
macro_rules! export_fmi3 {
    ($slave:ty, $contract:path) => {
        $crate::__fmi3_exports!($slave, $contract);
    };
}

/// The body of [`export_fmi3!`] with fmi2-shell's path passed in, for its `exports!`.
#[doc(hidden)]
#[macro_export]
macro_rules! __fmi3_exports {
    ($slave:ty, $contract:path) => {
        ::fmi2_shell::exports! { mod fmi3_exports for $slave; use $crate::fmi3, $crate::state::allowed; {
            use ::std::ffi::c_char;
            use ::fmi2_shell::fmu_state;
            use ::fmi2_shell::Interface;
            use $crate::export as e3;
            use $crate::arrays as ar;
            use $contract as contract;

            #[unsafe(no_mangle)]
            pub extern "C" fn fmi3GetVersion() -> *const c_char {
                c"3.0".as_ptr()
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3InstantiateModelExchange(
                instanceName: fmi3String,
                instantiationToken: fmi3String,
                resourcePath: fmi3String,
                _visible: fmi3Boolean,
                loggingOn: fmi3Boolean,
                instanceEnvironment: fmi3InstanceEnvironment,
                logMessage: fmi3LogMessageCallback,
            ) -> fmi3Instance {
                unsafe {
                    e3::instantiate::<S>("fmi3InstantiateModelExchange", Ok(Interface::ModelExchange),
                        instanceName, instantiationToken, resourcePath, loggingOn, instanceEnvironment, logMessage)
                }
            }
            // The model's early return at its events (where it offers them), event mode and
            // the intermediate update at each event as the importer asks for them (no
            // intermediate variables: none is required).
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
                instanceName: fmi3String,
                instantiationToken: fmi3String,
                resourcePath: fmi3String,
                _visible: fmi3Boolean,
                loggingOn: fmi3Boolean,
                eventModeUsed: fmi3Boolean,
                earlyReturnAllowed: fmi3Boolean,
                _requiredIntermediateVariables: *const fmi3ValueReference,
                _nRequiredIntermediateVariables: usize,
                instanceEnvironment: fmi3InstanceEnvironment,
                logMessage: fmi3LogMessageCallback,
                intermediateUpdate: fmi3IntermediateUpdateCallback,
            ) -> fmi3Instance {
                unsafe {
                    e3::instantiate_co_simulation::<S>(instanceName, instantiationToken, resourcePath,
                        loggingOn, eventModeUsed, earlyReturnAllowed, instanceEnvironment, logMessage,
                        intermediateUpdate)
                }
            }
            /// Scheduled execution is not offered: no instance.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
                _instanceName: fmi3String,
                _instantiationToken: fmi3String,
                _resourcePath: fmi3String,
                _visible: fmi3Boolean,
                _loggingOn: fmi3Boolean,
                _instanceEnvironment: fmi3InstanceEnvironment,
                _logMessage: fmi3LogMessageCallback,
                _clockUpdate: fmi3ClockUpdateCallback,
                _lockPreemption: fmi3LockPreemptionCallback,
                _unlockPreemption: fmi3UnlockPreemptionCallback,
            ) -> fmi3Instance {
                ::std::ptr::null_mut()
            }
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3FreeInstance(c: fmi3Instance) {
                unsafe { ::fmi2_shell::export::free_instance::<S>(c) }
            }
            }

            fn fmi3SetDebugLogging(loggingOn: fmi3Boolean, nCategories: usize, categories: *const fmi3String)
                SET_DEBUG_LOGGING |s| {
                    let names = unsafe { e::category_names(categories, nCategories) }?;
                    s.log().set_debug_logging(loggingOn, &names)
                };
            fn fmi3EnterInitializationMode(toleranceDefined: fmi3Boolean, tolerance: fmi3Float64,
                startTime: fmi3Float64, _stopTimeDefined: fmi3Boolean, _stopTime: fmi3Float64)
                ENTER_INITIALIZATION_MODE |s| {
                    s.setup_experiment(toleranceDefined.then_some(tolerance), startTime)?;
                    s.enter_initialization_mode()
                };
            fn fmi3ExitInitializationMode() EXIT_INITIALIZATION_MODE |s| s.exit_initialization_mode();
            fn fmi3EnterEventMode() ENTER_EVENT_MODE |s| e3::enter_event_mode(s);
            fn fmi3Terminate() TERMINATE |s| s.terminate();
            fn fmi3Reset() RESET |s| s.reset();

            // nValues values for the nvr references: an array's as many as its length.
            fn fmi3GetFloat64(vr: *const fmi3ValueReference, nvr: usize, value: *mut fmi3Float64, nValues: usize)
                GET |s| e3::get_float64(s, contract::FMI3_ARRAYS, array!(vr, nvr), array!(mut value, nValues),
                    contract::EVENT_INDICATORS);
            fn fmi3GetInt32(vr: *const fmi3ValueReference, nvr: usize, value: *mut fmi3Int32, nValues: usize)
                GET |s| e3::get_integer(s, contract::FMI3_ARRAYS, array!(vr, nvr), array!(mut value, nValues));
            fn fmi3GetInt64(vr: *const fmi3ValueReference, nvr: usize, value: *mut fmi3Int64, nValues: usize)
                GET |s| e3::get_integer(s, contract::FMI3_ARRAYS, array!(vr, nvr), array!(mut value, nValues));
            fn fmi3SetFloat64(vr: *const fmi3ValueReference, nvr: usize, value: *const fmi3Float64, nValues: usize)
                SET |s| e3::set_float64(s, contract::FMI3_ARRAYS, array!(vr, nvr), array!(value, nValues));
            fn fmi3SetInt32(vr: *const fmi3ValueReference, nvr: usize, value: *const fmi3Int32, nValues: usize)
                SET |s| e3::set_integer(s, contract::FMI3_ARRAYS, array!(vr, nvr), array!(value, nValues));
            fn fmi3SetInt64(vr: *const fmi3ValueReference, nvr: usize, value: *const fmi3Int64, nValues: usize)
                SET |s| e3::set_integer(s, contract::FMI3_ARRAYS, array!(vr, nvr), array!(value, nValues));
            // The structural parameters (set in configuration mode).
            fn fmi3GetUInt64(vr: *const fmi3ValueReference, nvr: usize, value: *mut fmi3UInt64, nValues: usize)
                GET_STRUCTURAL |s| {
                    e3::scalars(nvr, nValues)?;
                    ar::get_uint64(s, contract::FMI3_ARRAYS, array!(vr, nvr), array!(mut value, nvr))
                };
            fn fmi3SetUInt64(vr: *const fmi3ValueReference, nvr: usize, value: *const fmi3UInt64, nValues: usize)
                SET_STRUCTURAL |s| {
                    e3::scalars(nvr, nValues)?;
                    ar::set_uint64(s, contract::FMI3_ARRAYS, array!(vr, nvr), array!(value, nvr))
                };
            // Types the model has no variables of.
            fn fmi3GetFloat32(vr: *const fmi3ValueReference, nvr: usize, _v: *mut fmi3Float32, _n: usize)
                GET |_| no_variables("Float32", array!(vr, nvr));
            fn fmi3GetInt8(vr: *const fmi3ValueReference, nvr: usize, _v: *mut fmi3Int8, _n: usize)
                GET |_| no_variables("Int8", array!(vr, nvr));
            fn fmi3GetUInt8(vr: *const fmi3ValueReference, nvr: usize, _v: *mut fmi3UInt8, _n: usize)
                GET |_| no_variables("UInt8", array!(vr, nvr));
            fn fmi3GetInt16(vr: *const fmi3ValueReference, nvr: usize, _v: *mut fmi3Int16, _n: usize)
                GET |_| no_variables("Int16", array!(vr, nvr));
            fn fmi3GetUInt16(vr: *const fmi3ValueReference, nvr: usize, _v: *mut fmi3UInt16, _n: usize)
                GET |_| no_variables("UInt16", array!(vr, nvr));
            fn fmi3GetUInt32(vr: *const fmi3ValueReference, nvr: usize, _v: *mut fmi3UInt32, _n: usize)
                GET |_| no_variables("UInt32", array!(vr, nvr));
            fn fmi3GetBoolean(vr: *const fmi3ValueReference, nvr: usize, _v: *mut fmi3Boolean, _n: usize)
                GET |_| no_variables("Boolean", array!(vr, nvr));
            fn fmi3GetString(vr: *const fmi3ValueReference, nvr: usize, _v: *mut fmi3String, _n: usize)
                GET |_| no_variables("String", array!(vr, nvr));
            fn fmi3GetBinary(vr: *const fmi3ValueReference, nvr: usize, _sizes: *mut usize,
                _v: *mut fmi3Binary, _n: usize)
                GET |_| no_variables("Binary", array!(vr, nvr));
            fn fmi3SetFloat32(vr: *const fmi3ValueReference, nvr: usize, _v: *const fmi3Float32, _n: usize)
                SET |_| no_variables("Float32", array!(vr, nvr));
            fn fmi3SetInt8(vr: *const fmi3ValueReference, nvr: usize, _v: *const fmi3Int8, _n: usize)
                SET |_| no_variables("Int8", array!(vr, nvr));
            fn fmi3SetUInt8(vr: *const fmi3ValueReference, nvr: usize, _v: *const fmi3UInt8, _n: usize)
                SET |_| no_variables("UInt8", array!(vr, nvr));
            fn fmi3SetInt16(vr: *const fmi3ValueReference, nvr: usize, _v: *const fmi3Int16, _n: usize)
                SET |_| no_variables("Int16", array!(vr, nvr));
            fn fmi3SetUInt16(vr: *const fmi3ValueReference, nvr: usize, _v: *const fmi3UInt16, _n: usize)
                SET |_| no_variables("UInt16", array!(vr, nvr));
            fn fmi3SetUInt32(vr: *const fmi3ValueReference, nvr: usize, _v: *const fmi3UInt32, _n: usize)
                SET |_| no_variables("UInt32", array!(vr, nvr));
            fn fmi3SetBoolean(vr: *const fmi3ValueReference, nvr: usize, _v: *const fmi3Boolean, _n: usize)
                SET |_| no_variables("Boolean", array!(vr, nvr));
            fn fmi3SetString(vr: *const fmi3ValueReference, nvr: usize, _v: *const fmi3String, _n: usize)
                SET |_| no_variables("String", array!(vr, nvr));
            fn fmi3SetBinary(vr: *const fmi3ValueReference, nvr: usize, _sizes: *const usize,
                _v: *const fmi3Binary, _n: usize)
                SET |_| no_variables("Binary", array!(vr, nvr));

            // Dependencies are declared in the model description only.
            fn fmi3GetNumberOfVariableDependencies(_vr: fmi3ValueReference, _n: *mut usize)
                GET |_| e3::not_offered("fmi3GetNumberOfVariableDependencies: dependencies at run time are");
            fn fmi3GetVariableDependencies(_dependent: fmi3ValueReference, _elements: *mut usize,
                _independents: *mut fmi3ValueReference, _independentElements: *mut usize,
                _kinds: *mut fmi3DependencyKind, _n: usize)
                GET |_| e3::not_offered("fmi3GetVariableDependencies: dependencies at run time are");

            fn fmi3GetFMUState(state: *mut fmi3FMUState)
                FMU_STATE |s| unsafe { fmu_state::store(state, s.snapshot()) };
            fn fmi3SetFMUState(state: fmi3FMUState)
                FMU_STATE |s| s.restore(&unsafe { fmu_state::get::<S>(state) }?.fmu);
            fn fmi3FreeFMUState(state: *mut fmi3FMUState)
                FMU_STATE |_| unsafe { fmu_state::free::<S>(state) };
            fn fmi3SerializedFMUStateSize(state: fmi3FMUState, size: *mut usize)
                FMU_STATE |_| unsafe { fmu_state::serialized_size::<S>(state, size) };
            fn fmi3SerializeFMUState(state: fmi3FMUState, bytes: *mut fmi3Byte, size: usize)
                FMU_STATE |_| unsafe { fmu_state::serialize_into::<S>(state, bytes, size, "fmi3SerializedFMUStateSize") };
            fn fmi3DeserializeFMUState(bytes: *const fmi3Byte, size: usize, state: *mut fmi3FMUState)
                FMU_STATE |_| unsafe { fmu_state::deserialize_from::<S>(bytes, size, state) };

            fn fmi3GetDirectionalDerivative(unknowns: *const fmi3ValueReference, nUnknowns: usize,
                knowns: *const fmi3ValueReference, nKnowns: usize, seed: *const fmi3Float64, nSeed: usize,
                sensitivity: *mut fmi3Float64, nSensitivity: usize)
                DERIVATIVES |s| {
                    e3::scalars(nKnowns, nSeed)?;
                    e3::scalars(nUnknowns, nSensitivity)?;
                    s.slave.directional_derivative(array!(unknowns, nUnknowns), array!(knowns, nKnowns),
                        array!(seed, nKnowns), array!(mut sensitivity, nUnknowns))
                };
            fn fmi3GetAdjointDerivative(unknowns: *const fmi3ValueReference, nUnknowns: usize,
                knowns: *const fmi3ValueReference, nKnowns: usize, seed: *const fmi3Float64, nSeed: usize,
                sensitivity: *mut fmi3Float64, nSensitivity: usize)
                DERIVATIVES |s| {
                    e3::scalars(nUnknowns, nSeed)?;
                    e3::scalars(nKnowns, nSensitivity)?;
                    e3::adjoint_derivative(s, array!(unknowns, nUnknowns), array!(knowns, nKnowns),
                        array!(seed, nUnknowns), array!(mut sensitivity, nKnowns))
                };

            // Configuration mode, where the model has structural parameters; clocks: not offered.
            fn fmi3EnterConfigurationMode() EXPLAINED_REFUSAL
                |s| ar::configuration_mode(s, contract::FMI3_ARRAYS, true);
            fn fmi3ExitConfigurationMode() EXPLAINED_REFUSAL
                |s| ar::configuration_mode(s, contract::FMI3_ARRAYS, false);
            fn fmi3GetClock(_vr: *const fmi3ValueReference, _nvr: usize, _v: *mut fmi3Clock)
                EXPLAINED_REFUSAL |_| e3::not_offered("fmi3GetClock: clocks are");
            fn fmi3SetClock(_vr: *const fmi3ValueReference, _nvr: usize, _v: *const fmi3Clock)
                EXPLAINED_REFUSAL |_| e3::not_offered("fmi3SetClock: clocks are");
            fn fmi3GetIntervalDecimal(_vr: *const fmi3ValueReference, _nvr: usize, _i: *mut fmi3Float64,
                _q: *mut fmi3IntervalQualifier)
                EXPLAINED_REFUSAL |_| e3::not_offered("fmi3GetIntervalDecimal: clocks are");
            fn fmi3GetIntervalFraction(_vr: *const fmi3ValueReference, _nvr: usize, _counters: *mut fmi3UInt64,
                _r: *mut fmi3UInt64, _q: *mut fmi3IntervalQualifier)
                EXPLAINED_REFUSAL |_| e3::not_offered("fmi3GetIntervalFraction: clocks are");
            fn fmi3GetShiftDecimal(_vr: *const fmi3ValueReference, _nvr: usize, _s: *mut fmi3Float64)
                EXPLAINED_REFUSAL |_| e3::not_offered("fmi3GetShiftDecimal: clocks are");
            fn fmi3GetShiftFraction(_vr: *const fmi3ValueReference, _nvr: usize, _counters: *mut fmi3UInt64,
                _r: *mut fmi3UInt64)
                EXPLAINED_REFUSAL |_| e3::not_offered("fmi3GetShiftFraction: clocks are");
            fn fmi3SetIntervalDecimal(_vr: *const fmi3ValueReference, _nvr: usize, _i: *const fmi3Float64)
                EXPLAINED_REFUSAL |_| e3::not_offered("fmi3SetIntervalDecimal: clocks are");
            fn fmi3SetIntervalFraction(_vr: *const fmi3ValueReference, _nvr: usize, _counters: *const fmi3UInt64,
                _r: *const fmi3UInt64)
                EXPLAINED_REFUSAL |_| e3::not_offered("fmi3SetIntervalFraction: clocks are");
            fn fmi3SetShiftDecimal(_vr: *const fmi3ValueReference, _nvr: usize, _s: *const fmi3Float64)
                EXPLAINED_REFUSAL |_| e3::not_offered("fmi3SetShiftDecimal: clocks are");
            fn fmi3SetShiftFraction(_vr: *const fmi3ValueReference, _nvr: usize, _counters: *const fmi3UInt64,
                _r: *const fmi3UInt64)
                EXPLAINED_REFUSAL |_| e3::not_offered("fmi3SetShiftFraction: clocks are");
            fn fmi3ActivateModelPartition(_clock: fmi3ValueReference, _t: fmi3Float64)
                EXPLAINED_REFUSAL |_| e3::not_offered("fmi3ActivateModelPartition: clocks are");
            // Without clocks there is nothing to evaluate.
            fn fmi3EvaluateDiscreteStates() EVALUATE_DISCRETE_STATES |_| Ok(());

            // Model Exchange.
            fn fmi3UpdateDiscreteStates(discreteStatesNeedUpdate: *mut fmi3Boolean,
                terminateSimulation: *mut fmi3Boolean, nominalsOfContinuousStatesChanged: *mut fmi3Boolean,
                valuesOfContinuousStatesChanged: *mut fmi3Boolean, nextEventTimeDefined: *mut fmi3Boolean,
                nextEventTime: *mut fmi3Float64)
                UPDATE_DISCRETE_STATES |s| {
                    let info = e3::new_discrete_states(s)?;
                    unsafe {
                        e3::update_discrete_states(info, discreteStatesNeedUpdate, terminateSimulation,
                            nominalsOfContinuousStatesChanged, valuesOfContinuousStatesChanged,
                            nextEventTimeDefined, nextEventTime)
                    };
                    Ok(())
                };
            fn fmi3EnterContinuousTimeMode() ENTER_CONTINUOUS_TIME_MODE |s| s.enter_continuous_time_mode();
            fn fmi3CompletedIntegratorStep(_noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
                enterEventMode: *mut fmi3Boolean, terminateSimulation: *mut fmi3Boolean)
                COMPLETED_INTEGRATOR_STEP |s| {
                    let event = s.completed_integrator_step()?;
                    unsafe {
                        e3::answer(enterEventMode, event);
                        e3::answer(terminateSimulation, false);
                    }
                    Ok(())
                };
            fn fmi3SetTime(time: fmi3Float64) SET_TIME |s| s.set_time(time);
            // The continuous states in FMI 3.0's order (an array's elements together).
            fn fmi3SetContinuousStates(x: *const fmi3Float64, nx: usize) SET_CONTINUOUS_STATES
                |s| ar::set_continuous_states(s, contract::FMI3_ARRAYS, contract::STATES, array!(x, nx));
            fn fmi3GetContinuousStateDerivatives(derivatives: *mut fmi3Float64, nx: usize) GET_CONTINUOUS
                |s| ar::gather(s, contract::FMI3_ARRAYS, contract::STATES, array!(mut derivatives, nx),
                    |fmu, v| fmu.get_derivatives(v));
            fn fmi3GetEventIndicators(eventIndicators: *mut fmi3Float64, ni: usize) GET_CONTINUOUS
                |s| s.get_event_indicators(array!(mut eventIndicators, ni));
            fn fmi3GetContinuousStates(x: *mut fmi3Float64, nx: usize) GET_CONTINUOUS
                |s| ar::gather(s, contract::FMI3_ARRAYS, contract::STATES, array!(mut x, nx),
                    |fmu, v| fmu.get_continuous_states(v));
            fn fmi3GetNominalsOfContinuousStates(nominals: *mut fmi3Float64, nx: usize) GET_CONTINUOUS
                |s| ar::gather(s, contract::FMI3_ARRAYS, contract::STATES, array!(mut nominals, nx),
                    |fmu, v| fmu.get_nominals_of_continuous_states(v));
            fn fmi3GetNumberOfEventIndicators(n: *mut usize) GET_NUMBER_OF
                |_| unsafe { e3::number(n, contract::EVENT_INDICATORS) };
            fn fmi3GetNumberOfContinuousStates(n: *mut usize) GET_NUMBER_OF
                |s| {
                    let states = ar::state_order(s, contract::FMI3_ARRAYS, contract::STATES)?.len();
                    unsafe { e3::number(n, states) }
                };

            // Co-Simulation.
            fn fmi3EnterStepMode() ENTER_STEP_MODE |s| e3::enter_step_mode(s);
            fn fmi3GetOutputDerivatives(vr: *const fmi3ValueReference, nvr: usize, order: *const fmi3Int32,
                value: *mut fmi3Float64, nValues: usize)
                GET_OUTPUT_DERIVATIVES |s| {
                    e3::scalars(nvr, nValues)?;
                    s.slave.get_output_derivatives(array!(vr, nvr), array!(order, nvr), array!(mut value, nvr))
                };
            fn fmi3DoStep(currentCommunicationPoint: fmi3Float64, communicationStepSize: fmi3Float64,
                _noSetFMUStatePriorToCurrentPoint: fmi3Boolean, eventHandlingNeeded: *mut fmi3Boolean,
                terminateSimulation: *mut fmi3Boolean, earlyReturn: *mut fmi3Boolean,
                lastSuccessfulTime: *mut fmi3Float64)
                DO_STEP |s| unsafe {
                    e3::do_step(s, currentCommunicationPoint, communicationStepSize, eventHandlingNeeded,
                        terminateSimulation, earlyReturn, lastSuccessfulTime)
                };
        }
    };
}
