//! The FMU driven in-process through its `fmi2*` C exports, as an importer calls them: the
//! exported symbols declared as C functions (the crate's rlib defines them), a logger that
//! records each instance's lines in the componentEnvironment it was given, and a slave that
//! owns one instance. Shared by the thread, memory and soak tests and the fuzz target
//! (fuzz/), which include this file.
#![allow(dead_code)]

use fmi2_shell::fmi2::*;
use gear_rattle::contract::{Causality, GUID, Kind, VARIABLES, vr};
use std::ffi::{CStr, CString, c_void};
use std::sync::Mutex;

/// The exports of FMI 2.0 Co-Simulation and Model Exchange, as the standard's header declares
/// them.
#[allow(non_snake_case, clippy::too_many_arguments)]
pub mod ffi {
    use fmi2_shell::fmi2::*;
    use std::ffi::c_char;
    unsafe extern "C" {
        pub fn fmi2GetTypesPlatform() -> *const c_char;
        pub fn fmi2GetVersion() -> *const c_char;
        pub fn fmi2Instantiate(
            instanceName: fmi2String,
            fmuType: fmi2Type,
            fmuGUID: fmi2String,
            fmuResourceLocation: fmi2String,
            functions: *const fmi2CallbackFunctions,
            visible: fmi2Boolean,
            loggingOn: fmi2Boolean,
        ) -> fmi2Component;
        pub fn fmi2FreeInstance(c: fmi2Component);
        pub fn fmi2SetDebugLogging(
            c: fmi2Component,
            on: fmi2Boolean,
            n: usize,
            categories: *const fmi2String,
        ) -> fmi2Status;
        pub fn fmi2SetupExperiment(
            c: fmi2Component,
            toleranceDefined: fmi2Boolean,
            tolerance: fmi2Real,
            startTime: fmi2Real,
            stopTimeDefined: fmi2Boolean,
            stopTime: fmi2Real,
        ) -> fmi2Status;
        pub fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status;
        pub fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status;
        pub fn fmi2Terminate(c: fmi2Component) -> fmi2Status;
        pub fn fmi2Reset(c: fmi2Component) -> fmi2Status;
        pub fn fmi2GetReal(
            c: fmi2Component,
            vr: *const fmi2ValueReference,
            n: usize,
            v: *mut fmi2Real,
        ) -> fmi2Status;
        pub fn fmi2GetInteger(
            c: fmi2Component,
            vr: *const fmi2ValueReference,
            n: usize,
            v: *mut fmi2Integer,
        ) -> fmi2Status;
        pub fn fmi2GetBoolean(
            c: fmi2Component,
            vr: *const fmi2ValueReference,
            n: usize,
            v: *mut fmi2Boolean,
        ) -> fmi2Status;
        pub fn fmi2GetString(
            c: fmi2Component,
            vr: *const fmi2ValueReference,
            n: usize,
            v: *mut fmi2String,
        ) -> fmi2Status;
        pub fn fmi2SetReal(
            c: fmi2Component,
            vr: *const fmi2ValueReference,
            n: usize,
            v: *const fmi2Real,
        ) -> fmi2Status;
        pub fn fmi2SetInteger(
            c: fmi2Component,
            vr: *const fmi2ValueReference,
            n: usize,
            v: *const fmi2Integer,
        ) -> fmi2Status;
        pub fn fmi2SetBoolean(
            c: fmi2Component,
            vr: *const fmi2ValueReference,
            n: usize,
            v: *const fmi2Boolean,
        ) -> fmi2Status;
        pub fn fmi2SetString(
            c: fmi2Component,
            vr: *const fmi2ValueReference,
            n: usize,
            v: *const fmi2String,
        ) -> fmi2Status;
        pub fn fmi2SetRealInputDerivatives(
            c: fmi2Component,
            vr: *const fmi2ValueReference,
            n: usize,
            order: *const fmi2Integer,
            v: *const fmi2Real,
        ) -> fmi2Status;
        pub fn fmi2GetRealOutputDerivatives(
            c: fmi2Component,
            vr: *const fmi2ValueReference,
            n: usize,
            order: *const fmi2Integer,
            v: *mut fmi2Real,
        ) -> fmi2Status;
        pub fn fmi2GetDirectionalDerivative(
            c: fmi2Component,
            unknowns: *const fmi2ValueReference,
            nUnknown: usize,
            knowns: *const fmi2ValueReference,
            nKnown: usize,
            dvKnown: *const fmi2Real,
            dvUnknown: *mut fmi2Real,
        ) -> fmi2Status;
        pub fn fmi2DoStep(
            c: fmi2Component,
            t: fmi2Real,
            h: fmi2Real,
            noSetPrior: fmi2Boolean,
        ) -> fmi2Status;
        pub fn fmi2CancelStep(c: fmi2Component) -> fmi2Status;
        pub fn fmi2GetStatus(c: fmi2Component, s: fmi2StatusKind, v: *mut fmi2Status)
        -> fmi2Status;
        pub fn fmi2GetRealStatus(
            c: fmi2Component,
            s: fmi2StatusKind,
            v: *mut fmi2Real,
        ) -> fmi2Status;
        pub fn fmi2GetIntegerStatus(
            c: fmi2Component,
            s: fmi2StatusKind,
            v: *mut fmi2Integer,
        ) -> fmi2Status;
        pub fn fmi2GetBooleanStatus(
            c: fmi2Component,
            s: fmi2StatusKind,
            v: *mut fmi2Boolean,
        ) -> fmi2Status;
        pub fn fmi2GetStringStatus(
            c: fmi2Component,
            s: fmi2StatusKind,
            v: *mut fmi2String,
        ) -> fmi2Status;
        pub fn fmi2GetFMUstate(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status;
        pub fn fmi2SetFMUstate(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status;
        pub fn fmi2FreeFMUstate(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status;
        pub fn fmi2SerializedFMUstateSize(
            c: fmi2Component,
            state: fmi2FMUstate,
            size: *mut usize,
        ) -> fmi2Status;
        pub fn fmi2SerializeFMUstate(
            c: fmi2Component,
            state: fmi2FMUstate,
            bytes: *mut fmi2Byte,
            size: usize,
        ) -> fmi2Status;
        pub fn fmi2DeSerializeFMUstate(
            c: fmi2Component,
            bytes: *const fmi2Byte,
            size: usize,
            state: *mut fmi2FMUstate,
        ) -> fmi2Status;
        pub fn fmi2SetTime(c: fmi2Component, time: fmi2Real) -> fmi2Status;
        pub fn fmi2SetContinuousStates(
            c: fmi2Component,
            x: *const fmi2Real,
            nx: usize,
        ) -> fmi2Status;
        pub fn fmi2GetContinuousStates(c: fmi2Component, x: *mut fmi2Real, nx: usize)
        -> fmi2Status;
        pub fn fmi2GetNominalsOfContinuousStates(
            c: fmi2Component,
            x_nominal: *mut fmi2Real,
            nx: usize,
        ) -> fmi2Status;
        pub fn fmi2GetDerivatives(c: fmi2Component, dx: *mut fmi2Real, nx: usize) -> fmi2Status;
        pub fn fmi2GetEventIndicators(c: fmi2Component, z: *mut fmi2Real, ni: usize) -> fmi2Status;
        pub fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status;
        pub fn fmi2NewDiscreteStates(c: fmi2Component, info: *mut fmi2EventInfo) -> fmi2Status;
        pub fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status;
        pub fn fmi2CompletedIntegratorStep(
            c: fmi2Component,
            noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
            enterEventMode: *mut fmi2Boolean,
            terminateSimulation: *mut fmi2Boolean,
        ) -> fmi2Status;
    }
}

/// One line the FMU handed to the logger.
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    pub status: fmi2Status,
    pub instance: String,
    pub category: String,
    pub message: String,
}

/// What each instance's componentEnvironment points to: its lines.
#[derive(Default)]
pub struct Env {
    pub lines: Mutex<Vec<Line>>,
}

/// Lossy text of a C string the FMU passed (NULL as "<NULL>").
unsafe fn text(s: fmi2String) -> String {
    if s.is_null() {
        return "<NULL>".into();
    }
    // SAFETY: the FMU passes NUL-terminated strings valid for the call.
    unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned()
}

/// The logger: appends the line to the Env its componentEnvironment points to. The message
/// is a printf format whose '%' the FMU escapes, so it carries no variadic arguments and this
/// function takes the five named ones only (on x86-64 and AArch64 Linux a variadic call
/// passes them as to a function with exactly those parameters).
unsafe extern "C" fn record(
    env: fmi2ComponentEnvironment,
    instance: fmi2String,
    status: fmi2Status,
    category: fmi2String,
    message: fmi2String,
) {
    // SAFETY: every componentEnvironment given to the FMU here is an `Env` that outlives it.
    let env = unsafe { &*(env as *const Env) };
    let line = unsafe {
        Line {
            status,
            instance: text(instance),
            category: text(category),
            message: text(message),
        }
    };
    env.lines.lock().unwrap().push(line);
}

type Fixed =
    unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String);

/// The callback table for one instance whose lines go to `env`.
pub fn callbacks(env: *const Env) -> fmi2CallbackFunctions {
    // SAFETY: see `record`: the same five leading parameters, no variadic argument read.
    let logger = unsafe {
        std::mem::transmute::<
            Fixed,
            unsafe extern "C" fn(
                fmi2ComponentEnvironment,
                fmi2String,
                fmi2Status,
                fmi2String,
                fmi2String,
                ...
            ),
        >(record)
    };
    fmi2CallbackFunctions {
        logger: Some(logger),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: env as *mut c_void,
    }
}

/// The outputs of the contract of one type, in its order.
pub fn outputs(kind: Kind) -> Vec<u32> {
    VARIABLES
        .iter()
        .filter(|v| v.kind == kind && v.causality == Causality::Output)
        .map(|v| v.vr)
        .collect()
}

/// One instance, freed when dropped. Its Env is boxed so that its address, the
/// componentEnvironment, stays put.
pub struct Slave {
    pub c: fmi2Component,
    pub env: Box<Env>,
    pub name: String,
}

// One thread at a time uses an instance, as FMI 2.0 allows.
unsafe impl Send for Slave {}

/// Panics with the call, the status and the instance's last log line unless `status` is OK.
pub fn ok(slave: &Slave, call: &str, status: fmi2Status) {
    if status != fmi2Status_fmi2OK {
        let last = slave.env.lines.lock().unwrap().last().cloned();
        panic!(
            "{}: {call} returned {status}; last log line {last:?}",
            slave.name
        );
    }
}

impl Slave {
    /// A Co-Simulation instance.
    pub fn new(name: &str, logging_on: bool) -> Slave {
        Slave::of_type(name, fmi2Type_fmi2CoSimulation, logging_on)
    }

    pub fn of_type(name: &str, fmu_type: fmi2Type, logging_on: bool) -> Slave {
        let env = Box::<Env>::default();
        let functions = callbacks(&*env);
        let (cname, guid) = (CString::new(name).unwrap(), CString::new(GUID).unwrap());
        // SAFETY: valid C strings and callback table, alive for the call.
        let c = unsafe {
            ffi::fmi2Instantiate(
                cname.as_ptr(),
                fmu_type,
                guid.as_ptr(),
                c"file:///nowhere".as_ptr(),
                &functions,
                0,
                logging_on as fmi2Boolean,
            )
        };
        assert!(!c.is_null(), "fmi2Instantiate({name}) returned NULL");
        Slave {
            c,
            env,
            name: name.to_string(),
        }
    }

    /// setup, initialisation with these start values, exit: ready to step from t = 0.
    pub fn initialise(&self, tolerance: f64, reals: &[(u32, f64)], integers: &[(u32, i32)]) {
        unsafe {
            ok(
                self,
                "fmi2SetupExperiment",
                ffi::fmi2SetupExperiment(self.c, 1, tolerance, 0.0, 0, 0.0),
            );
            ok(
                self,
                "fmi2EnterInitializationMode",
                ffi::fmi2EnterInitializationMode(self.c),
            );
            let (vr, v): (Vec<u32>, Vec<i32>) = integers.iter().copied().unzip();
            ok(
                self,
                "fmi2SetInteger",
                ffi::fmi2SetInteger(self.c, vr.as_ptr(), vr.len(), v.as_ptr()),
            );
            let (vr, v): (Vec<u32>, Vec<f64>) = reals.iter().copied().unzip();
            ok(
                self,
                "fmi2SetReal",
                ffi::fmi2SetReal(self.c, vr.as_ptr(), vr.len(), v.as_ptr()),
            );
            ok(
                self,
                "fmi2ExitInitializationMode",
                ffi::fmi2ExitInitializationMode(self.c),
            );
        }
    }

    pub fn step(&self, t: f64, h: f64) -> fmi2Status {
        unsafe { ffi::fmi2DoStep(self.c, t, h, 1) }
    }

    pub fn get_real(&self, vrs: &[u32]) -> Vec<f64> {
        let mut out = vec![0.0; vrs.len()];
        ok(self, "fmi2GetReal", unsafe {
            ffi::fmi2GetReal(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
        });
        out
    }

    pub fn get_integer(&self, vrs: &[u32]) -> Vec<i32> {
        let mut out = vec![0; vrs.len()];
        ok(self, "fmi2GetInteger", unsafe {
            ffi::fmi2GetInteger(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
        });
        out
    }

    /// Every output at once, as bits (Real outputs, then Integer ones).
    pub fn output_bits(&self) -> Vec<u64> {
        let reals = self
            .get_real(&outputs(Kind::Real))
            .into_iter()
            .map(f64::to_bits);
        let integers = self
            .get_integer(&outputs(Kind::Integer))
            .into_iter()
            .map(|i| i as u64);
        reals.chain(integers).collect()
    }

    pub fn lines(&self) -> Vec<Line> {
        self.env.lines.lock().unwrap().clone()
    }
}

impl Drop for Slave {
    fn drop(&mut self) {
        // SAFETY: an instance of ours, freed once.
        unsafe { ffi::fmi2FreeInstance(self.c) }
    }
}

/// Start values: (value reference, value) of Real and of Integer variables.
pub type Start = (Vec<(u32, f64)>, Vec<(u32, i32)>);

/// Start values of the paper's bench scene S1 in sine mode (docs/MODEL.md §5; f_exc = 30 Hz), or of
/// a scene like it at another excitation frequency, with ξ(0) moved by `shift` × G, so that
/// scenes differ from one another.
pub fn s1_start(f_exc: f64, shift: f64) -> Start {
    (
        vec![
            (vr::f_exc, f_exc),
            (vr::A_rms, 300.0),
            (vr::gap_start, 0.5 + shift),
        ],
        vec![(vr::excitation, 1)],
    )
}
