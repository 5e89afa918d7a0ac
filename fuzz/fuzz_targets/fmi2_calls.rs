//! libFuzzer over the C API. Each input is read (`arbitrary`) as the interface of the first
//! instance (Co-Simulation or Model Exchange), whether it starts initialised, and a sequence
//! of fmi2 calls with their arguments, in any order: unknown value references, NaN, ±Inf, huge and subnormal values,
//! zero and negative steps, times and states of any value and vectors of any length,
//! serialized FMU states mutated (with their checksum mended, so that the decoder behind it
//! is reached), strings with '%' and bytes that are not UTF-8, NULL where the standard allows
//! it, and an importer's explicit Euler integration of the Model Exchange states with its
//! event iterations. The exports are called in-process (the crate's rlib), under
//! AddressSanitizer and LeakSanitizer (cargo-fuzz's default).
//!
//! Invariants, each a crash when broken:
//! - no crash, no leak, and no panic at all (libfuzzer-sys aborts on any panic, also one the
//!   guard would catch and turn into fmi2Error);
//! - every status is OK, Warning, Discard or Error; every log line is a printf format with
//!   its '%' escaped, names its own instance and reaches its own componentEnvironment;
//! - no fmi2OK with a non-finite Real handed out (values, derivatives, continuous states and
//!   their derivatives, nominals, event indicators, the next event time, status);
//! - a refused fmi2Set* (fmi2SetTime and fmi2SetContinuousStates included) changes nothing
//!   (the instance's FMU state, byte for byte); accepted states read back as set;
//! - an instance keeps the interface it was instantiated for;
//! - after any sequence, fmi2SetFMUstate takes back every state fmi2GetFMUstate gave, and
//!   fmi2Reset brings the instance back to one that runs the bench scene S1 with finite
//!   outputs (the way out the standard gives after fmi2Error), by fmi2DoStep or by Euler
//!   steps of Model Exchange.
#![no_main]

#[path = "../../tests/capi/mod.rs"]
mod capi;

use arbitrary::Arbitrary;
use capi::{Env, Line, callbacks, ffi, outputs};
use fmi2_shell::component::Component;
use fmi2_shell::fmi2::*;
use fmi2_shell::fmu_state::serialize;
use fmi2_shell::{FmiState, Interface};
use gear_rattle::contract::{GUID, Kind, LOG_CATEGORIES, VARIABLES};
use gear_rattle::instance::Instance;
use gear_rattle::instance::model_exchange::{NX, NZ};
use libfuzzer_sys::fuzz_target;
use std::ffi::CString;
use std::ptr::{null, null_mut};

/// A Real argument: the special values by name, or any bit pattern.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Num {
    Bits(u64),
    Nan,
    Inf,
    NegInf,
    Zero,
    NegZero,
    Max,
    Lowest,
    MinPositive,
    Subnormal(u32),
    /// ±m × 10^e with e in -12..=8: the range where parameters and inputs live.
    Scaled(i8, u8, bool),
    /// ±10^e with e in 100..=307.
    Huge(u8, bool),
}

impl Num {
    fn get(self) -> f64 {
        match self {
            Num::Bits(b) => f64::from_bits(b),
            Num::Nan => f64::NAN,
            Num::Inf => f64::INFINITY,
            Num::NegInf => f64::NEG_INFINITY,
            Num::Zero => 0.0,
            Num::NegZero => -0.0,
            Num::Max => f64::MAX,
            Num::Lowest => f64::MIN,
            Num::MinPositive => f64::MIN_POSITIVE,
            Num::Subnormal(m) => f64::from_bits(m as u64 + 1),
            Num::Scaled(e, m, neg) => {
                let v = (1.0 + m as f64 / 32.0) * 10f64.powi((e.rem_euclid(21) - 12) as i32);
                if neg { -v } else { v }
            }
            Num::Huge(e, neg) => {
                let v = 10f64.powi(100 + (e as i32 % 208));
                if neg { -v } else { v }
            }
        }
    }
}

/// A value reference: one of the contract's variables (any type) or any number.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Vr {
    Known(u8),
    Any(u32),
}

impl Vr {
    fn get(self) -> u32 {
        match self {
            Vr::Known(k) => VARIABLES[k as usize % VARIABLES.len()].vr,
            Vr::Any(v) => v,
        }
    }
}

/// A string argument: NULL, this model's GUID or a log category, or any bytes (a NUL ends it).
#[derive(Arbitrary, Debug, Clone)]
enum Text {
    Null,
    Guid,
    Category(u8),
    Bytes(Vec<u8>),
}

impl Text {
    fn get(&self) -> Option<CString> {
        let bytes = match self {
            Text::Null => return None,
            Text::Guid => GUID.as_bytes().to_vec(),
            Text::Category(k) => LOG_CATEGORIES[*k as usize % LOG_CATEGORIES.len()]
                .0
                .as_bytes()
                .to_vec(),
            Text::Bytes(b) => b.iter().copied().take_while(|&c| c != 0).collect(),
        };
        Some(CString::new(bytes).expect("no NUL"))
    }
}

fn ptr(s: &Option<CString>) -> *const i8 {
    s.as_ref().map_or(null(), |s| s.as_ptr())
}

/// The communication point of fmi2DoStep or the time of fmi2SetTime: the instance's last
/// successful time, a step after it, or any value.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum When {
    Now,
    Ahead(Size),
    At(Num),
}

/// A step size: a usual one (10^-7 to 10^-2 s) or any value.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Size {
    Usual(u8),
    Any(Num),
}

/// The longest step fmi2DoStep is asked for below 1e12 s. A longer one is legitimate but runs
/// the integrator for minutes under AddressSanitizer (S1 takes 2 s for 1000 s in release),
/// past libFuzzer's timeout, through no path a short one misses; from 1e12 s on, a step of
/// S1 fails at once (the resolution of time at its end).
const LONGEST_STEP: f64 = 0.1;

impl Size {
    fn get(self) -> f64 {
        match self {
            Size::Usual(k) => 10f64.powf(-7.0 + 5.0 * k as f64 / 255.0),
            Size::Any(x) => x.get(),
        }
    }
}

/// The length of a vector of Model Exchange: the model's, or any other (0 to 31).
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Length {
    Model,
    Other(u8),
}

impl Length {
    fn of(self, model: usize) -> usize {
        match self {
            Length::Model => model,
            Length::Other(n) => n as usize % 32,
        }
    }
}

/// The states given to fmi2SetContinuousStates.
#[derive(Arbitrary, Debug, Clone)]
enum States {
    /// The instance's own (fmi2GetContinuousStates), some of them replaced.
    Own(Vec<(u8, Num)>),
    /// An explicit Euler step from the instance's own: x + h dx/dt.
    Euler(Size),
    Any(Vec<Num>),
}

/// A Model Exchange getter of a Real vector.
type Getter = unsafe extern "C" fn(fmi2Component, *mut fmi2Real, usize) -> fmi2Status;

/// The four getters, with their names and the model's lengths (`STATES`, `DERIVATIVES` and
/// `INDICATORS` index it).
const STATES: usize = 0;
const DERIVATIVES: usize = 2;
const INDICATORS: usize = 3;
const GETTERS: [(&str, Getter, usize); 4] = [
    ("fmi2GetContinuousStates", ffi::fmi2GetContinuousStates, NX),
    (
        "fmi2GetNominalsOfContinuousStates",
        ffi::fmi2GetNominalsOfContinuousStates,
        NX,
    ),
    ("fmi2GetDerivatives", ffi::fmi2GetDerivatives, NX),
    ("fmi2GetEventIndicators", ffi::fmi2GetEventIndicators, NZ),
];

/// What is done to a serialized FMU state kept by the harness.
#[derive(Arbitrary, Debug, Clone)]
enum Mutation {
    Flip {
        at: u16,
        bit: u8,
    },
    Byte {
        at: u16,
        value: u8,
    },
    /// Eight bytes replaced by a Real (postcard writes f64 as eight raw bytes).
    Real {
        at: u16,
        value: Num,
    },
    Truncate(u16),
    Append(Vec<u8>),
    /// The length field and the CRC-32 made to match the bytes again.
    Mend,
}

#[derive(Arbitrary, Debug, Clone)]
enum Op {
    Instantiate {
        name: Text,
        fmu_type: u8,
        guid: Text,
        no_functions: bool,
        logging: bool,
    },
    FreeInstance,
    SetDebugLogging {
        on: bool,
        categories: Vec<Text>,
        null_array: bool,
    },
    SetupExperiment {
        tolerance: Option<Num>,
        start: Num,
        stop: Option<Num>,
    },
    EnterInitializationMode,
    ExitInitializationMode,
    Terminate,
    Reset,
    GetReal {
        vrs: Vec<Vr>,
        null_values: bool,
    },
    GetInteger {
        vrs: Vec<Vr>,
    },
    GetBoolean {
        vrs: Vec<Vr>,
    },
    GetString {
        vrs: Vec<Vr>,
    },
    SetReal {
        values: Vec<(Vr, Num)>,
        null_values: bool,
    },
    SetInteger {
        values: Vec<(Vr, i32)>,
    },
    SetBoolean {
        values: Vec<(Vr, i32)>,
    },
    SetString {
        values: Vec<(Vr, Text)>,
    },
    SetRealInputDerivatives {
        values: Vec<(Vr, i32, Num)>,
    },
    GetRealOutputDerivatives {
        vrs: Vec<(Vr, i32)>,
    },
    GetDirectionalDerivative {
        unknowns: Vec<Vr>,
        knowns: Vec<(Vr, Num)>,
    },
    DoStep {
        when: When,
        size: Size,
        no_set_prior: bool,
    },
    CancelStep,
    // Model Exchange.
    SetTime {
        when: When,
    },
    SetContinuousStates {
        x: States,
        length: Length,
        null_values: bool,
    },
    /// One of the four getters of `GETTERS`.
    GetVector {
        which: u8,
        length: Length,
        null_values: bool,
    },
    EnterEventMode,
    NewDiscreteStates {
        null_info: bool,
    },
    EnterContinuousTimeMode,
    CompletedIntegratorStep {
        no_set_prior: bool,
        null_enter: bool,
        null_terminate: bool,
    },
    /// An importer's integration: `steps` explicit Euler steps of size h, each completed,
    /// with an event iteration where an event indicator changes sign or the FMU asks.
    Integrate {
        steps: u8,
        size: Size,
    },
    GetStatus {
        kind: u32,
        which: u8,
    },
    GetFMUstate {
        slot: u8,
    },
    SetFMUstate {
        slot: u8,
    },
    FreeFMUstate {
        slot: u8,
    },
    /// A pointer that is none of this FMU's states: 8 zeroed bytes, as small as a tag.
    ForeignFMUstate {
        which: u8,
    },
    SerializedFMUstateSize {
        slot: u8,
    },
    Serialize {
        slot: u8,
        size_off: i8,
    },
    DeSerialize {
        buffer: u8,
        slot: u8,
    },
    Mutate {
        buffer: u8,
        how: Mutation,
    },
    Splice {
        from: u8,
        to: u8,
        at: u16,
    },
    NullComponent {
        which: u8,
    },
    Versions,
}

const SLOTS: usize = 3;

/// The harness: at most one live instance, the FMU states it holds, serialized states.
struct Harness {
    c: fmi2Component,
    /// The interface the live instance was instantiated for.
    interface: Interface,
    name: String,
    env: Box<Env>,
    /// Lines of `env` already checked.
    seen: usize,
    /// States in hand, and whether fmi2GetFMUstate (rather than a deserialization) made them.
    slots: [(fmi2FMUstate, bool); SLOTS],
    buffers: Vec<Vec<u8>>,
}

fn status_ok(s: fmi2Status) -> bool {
    s == fmi2Status_fmi2OK
}

fn check_status(call: &str, s: fmi2Status) -> fmi2Status {
    assert!(
        [
            fmi2Status_fmi2OK,
            fmi2Status_fmi2Warning,
            fmi2Status_fmi2Discard,
            fmi2Status_fmi2Error
        ]
        .contains(&s),
        "{call} returned status {s}"
    );
    s
}

fn check_finite(call: &str, s: fmi2Status, values: &[f64]) {
    if status_ok(s) {
        assert!(
            values.iter().all(|v| v.is_finite()),
            "{call} returned fmi2OK with {values:?}"
        );
    }
}

/// Runs a getter of `n` Reals into an array of `n` (NULL with `null`), checks its status
/// and that fmi2OK hands out finite values only.
fn get_reals(
    call: &str,
    n: usize,
    null: bool,
    get: impl FnOnce(*mut f64) -> fmi2Status,
) -> (fmi2Status, Vec<f64>) {
    let mut out = vec![0.0; n];
    let dest = if null { null_mut() } else { out.as_mut_ptr() };
    let s = check_status(call, get(dest));
    check_finite(call, s, &out);
    (s, out)
}

fn is_boolean(b: fmi2Boolean) -> bool {
    b == 0 || b == 1
}

/// Whether an event indicator changed sign (the importer's test for a state event).
fn crossed(before: &[f64], after: &[f64]) -> bool {
    before
        .iter()
        .zip(after)
        .any(|(a, b)| (*a > 0.0) != (*b > 0.0))
}

/// A printf format without a conversion: every '%' is doubled.
fn printf_safe(message: &str) -> bool {
    let mut chars = message.chars();
    while let Some(c) = chars.next() {
        if c == '%' && chars.next() != Some('%') {
            return false;
        }
    }
    true
}

impl Harness {
    /// A harness holding one instance, as an importer has it after fmi2Instantiate.
    fn new(interface: Interface) -> Self {
        let env = Box::<Env>::default();
        let functions = callbacks(&*env);
        let guid = CString::new(GUID).unwrap();
        // SAFETY: valid strings and callback table.
        let c = unsafe {
            ffi::fmi2Instantiate(
                c"fuzz".as_ptr(),
                match interface {
                    Interface::CoSimulation => fmi2Type_fmi2CoSimulation,
                    Interface::ModelExchange => fmi2Type_fmi2ModelExchange,
                },
                guid.as_ptr(),
                null(),
                &functions,
                0,
                0,
            )
        };
        assert!(!c.is_null(), "fmi2Instantiate with valid arguments");
        Harness {
            c,
            interface,
            name: "fuzz".into(),
            env,
            seen: 0,
            slots: [(null_mut(), false); SLOTS],
            buffers: Vec::new(),
        }
    }

    fn component(&self) -> Option<&Component<Instance>> {
        // SAFETY: a live instance of ours.
        (!self.c.is_null()).then(|| unsafe { &*(self.c as *const Component<Instance>) })
    }

    fn fmu_state_bytes(&self) -> Option<Vec<u8>> {
        self.component().map(|c| serialize(&c.fmu))
    }

    /// The log lines since the last check: printf-safe, of this instance.
    fn check_log(&mut self) {
        let lines = self.env.lines.lock().unwrap();
        for Line {
            instance, message, ..
        } in &lines[self.seen..]
        {
            assert!(
                printf_safe(message),
                "log message with a bare '%': {message:?}"
            );
            assert_eq!(
                instance, &self.name,
                "a line of another instance: {message:?}"
            );
        }
        self.seen = lines.len();
    }

    fn free_states(&mut self) {
        for k in 0..SLOTS {
            if !self.slots[k].0.is_null() {
                let s = unsafe { ffi::fmi2FreeFMUstate(self.c, &mut self.slots[k].0) };
                assert!(
                    status_ok(s) && self.slots[k].0.is_null(),
                    "fmi2FreeFMUstate of a held state: {s}"
                );
            }
        }
    }

    fn free_instance(&mut self) {
        if !self.c.is_null() {
            self.free_states();
            unsafe { ffi::fmi2FreeInstance(self.c) };
            self.c = null_mut();
        }
    }

    fn time(&self) -> f64 {
        self.component()
            .map_or(0.0, |c| c.fmu.last_successful_time())
    }

    fn read_outputs(&self, after: &str) {
        let vrs = outputs(Kind::Real);
        get_reals(
            &format!("fmi2GetReal of every output after {after}"),
            vrs.len(),
            false,
            |out| unsafe { ffi::fmi2GetReal(self.c, vrs.as_ptr(), vrs.len(), out) },
        );
    }

    fn at(&self, when: When) -> f64 {
        match when {
            When::Now => self.time(),
            When::Ahead(h) => self.time() + h.get(),
            When::At(x) => x.get(),
        }
    }

    /// One of Model Exchange's vectors (`GETTERS`), asked with any length.
    fn get_vector(&self, which: usize, length: Length, null: bool) -> (fmi2Status, Vec<f64>) {
        let (call, get, n) = GETTERS[which];
        let (c, n) = (self.c, length.of(n));
        get_reals(call, n, null, |out| unsafe { get(c, out, n) })
    }

    /// One of Model Exchange's vectors of the model's length, or None if refused.
    fn own(&self, which: usize) -> Option<Vec<f64>> {
        let (s, v) = self.get_vector(which, Length::Model, false);
        status_ok(s).then_some(v)
    }

    /// The states an importer's explicit Euler step of size h reaches (None if refused).
    fn euler(&self, h: f64) -> Option<Vec<f64>> {
        let (x, dx) = (self.own(STATES)?, self.own(DERIVATIVES)?);
        Some(x.iter().zip(&dx).map(|(x, dx)| x + h * dx).collect())
    }

    fn states(&self, x: &States) -> Vec<f64> {
        match x {
            States::Own(edits) => {
                let mut x = self.own(STATES).unwrap_or_else(|| vec![0.0; NX]);
                for (k, v) in edits {
                    x[*k as usize % NX] = v.get();
                }
                x
            }
            States::Euler(h) => self.euler(h.get()).unwrap_or_default(),
            States::Any(values) => values.iter().map(|v| v.get()).collect(),
        }
    }

    /// fmi2SetContinuousStates; accepted, ξ and the quadratures (the states every drive
    /// mode keeps as given) read back as set.
    fn set_continuous_states(&mut self, x: &[f64], null_values: bool) -> fmi2Status {
        let c = self.c;
        let src = if null_values { null() } else { x.as_ptr() };
        let s = self.unchanged_if_refused("fmi2SetContinuousStates", || unsafe {
            ffi::fmi2SetContinuousStates(c, src, x.len())
        });
        if status_ok(s) {
            let (s, back) = self.get_vector(STATES, Length::Model, false);
            assert!(
                status_ok(s) && back[0] == x[0] && back[4..] == x[4..],
                "fmi2SetContinuousStates({x:?}) reads back as {back:?} ({s}; log {:?})",
                self.env.lines.lock().unwrap().last()
            );
        }
        s
    }

    /// fmi2NewDiscreteStates: what it reports, or None if refused.
    fn new_discrete_states(&self, null: bool) -> Option<fmi2EventInfo> {
        let mut info = fmi2EventInfo {
            newDiscreteStatesNeeded: 2,
            terminateSimulation: 2,
            nominalsOfContinuousStatesChanged: 2,
            valuesOfContinuousStatesChanged: 2,
            nextEventTimeDefined: 2,
            nextEventTime: f64::NAN,
        };
        let dest = if null { null_mut() } else { &mut info };
        let s = check_status("fmi2NewDiscreteStates", unsafe {
            ffi::fmi2NewDiscreteStates(self.c, dest)
        });
        if !status_ok(s) {
            return None;
        }
        assert!(
            [
                info.newDiscreteStatesNeeded,
                info.terminateSimulation,
                info.nominalsOfContinuousStatesChanged,
                info.valuesOfContinuousStatesChanged,
                info.nextEventTimeDefined
            ]
            .into_iter()
            .all(is_boolean)
                && (info.nextEventTimeDefined == 0 || info.nextEventTime.is_finite()),
            "fmi2NewDiscreteStates returned fmi2OK with {info:?}"
        );
        Some(info)
    }

    /// The event iteration from event mode to continuous-time mode; whether it got there.
    fn event_iteration(&self) -> bool {
        for _ in 0..4 {
            match self.new_discrete_states(false) {
                Some(info) if info.newDiscreteStatesNeeded == 0 => {
                    return status_ok(check_status("fmi2EnterContinuousTimeMode", unsafe {
                        ffi::fmi2EnterContinuousTimeMode(self.c)
                    }));
                }
                Some(_) => {}
                None => return false,
            }
        }
        false
    }

    /// fmi2CompletedIntegratorStep: whether the FMU asks for event mode, or None if refused.
    fn completed_integrator_step(&self, no_set_prior: bool, null: [bool; 2]) -> Option<bool> {
        let (mut enter, mut terminate) = (2, 2);
        let ptr = |p: &mut fmi2Boolean, null: bool| if null { null_mut() } else { p as *mut _ };
        let s = check_status("fmi2CompletedIntegratorStep", unsafe {
            ffi::fmi2CompletedIntegratorStep(
                self.c,
                no_set_prior as fmi2Boolean,
                ptr(&mut enter, null[0]),
                ptr(&mut terminate, null[1]),
            )
        });
        if !status_ok(s) {
            return None;
        }
        assert!(
            (null[0] || is_boolean(enter)) && (null[1] || is_boolean(terminate)),
            "fmi2CompletedIntegratorStep returned fmi2OK with {enter}, {terminate}"
        );
        Some(enter == 1)
    }

    /// An importer's Model Exchange loop: from event mode an event iteration, then `steps`
    /// explicit Euler steps of size h, each completed, and an event iteration where an event
    /// indicator changes sign or the FMU asks for one. Whether every call returned fmi2OK.
    fn integrate(&mut self, steps: usize, h: f64) -> bool {
        let c = self.c;
        if self
            .component()
            .is_some_and(|c| c.fmu.state == FmiState::EventMode)
            && !self.event_iteration()
        {
            return false;
        }
        let Some(mut z) = self.own(INDICATORS) else {
            return false;
        };
        for _ in 0..steps {
            let t = self.time() + h;
            let Some(x) = self.euler(h) else {
                return false;
            };
            let s = check_status("fmi2SetTime", unsafe { ffi::fmi2SetTime(c, t) });
            if !status_ok(s) || !status_ok(self.set_continuous_states(&x, false)) {
                return false;
            }
            let (Some(enter), Some(after)) = (
                self.completed_integrator_step(true, [false; 2]),
                self.own(INDICATORS),
            ) else {
                return false;
            };
            if enter || crossed(&z, &after) {
                let s = check_status("fmi2EnterEventMode", unsafe { ffi::fmi2EnterEventMode(c) });
                if !status_ok(s) || !self.event_iteration() {
                    return false;
                }
            }
            z = after;
        }
        true
    }

    fn run(&mut self, op: &Op) {
        let c = self.c;
        match op {
            Op::Instantiate {
                name,
                fmu_type,
                guid,
                no_functions,
                logging,
            } => {
                self.free_instance();
                let (n, g) = (name.get(), guid.get());
                self.env = Box::default();
                self.seen = 0;
                let functions = callbacks(&*self.env);
                // Co-Simulation, Model Exchange, or a type that is neither.
                let kind = match fmu_type % 3 {
                    0 => fmi2Type_fmi2CoSimulation,
                    1 => fmi2Type_fmi2ModelExchange,
                    _ => 2 + *fmu_type as fmi2Type,
                };
                self.name = n
                    .as_ref()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default();
                self.c = unsafe {
                    ffi::fmi2Instantiate(
                        ptr(&n),
                        kind,
                        ptr(&g),
                        c"file:///%s%n".as_ptr(),
                        if *no_functions { null() } else { &functions },
                        0,
                        *logging as fmi2Boolean,
                    )
                };
                if !self.c.is_null() {
                    assert!(g.as_deref() == Some(CString::new(GUID).unwrap().as_c_str()));
                    self.interface = if kind == fmi2Type_fmi2CoSimulation {
                        Interface::CoSimulation
                    } else {
                        assert_eq!(
                            kind, fmi2Type_fmi2ModelExchange,
                            "an instance of fmuType {kind}"
                        );
                        Interface::ModelExchange
                    };
                }
            }
            Op::FreeInstance => self.free_instance(),
            Op::SetDebugLogging {
                on,
                categories,
                null_array,
            } => {
                let owned: Vec<_> = categories.iter().map(Text::get).collect();
                let ptrs: Vec<_> = owned.iter().map(ptr).collect();
                let array = if *null_array { null() } else { ptrs.as_ptr() };
                check_status("fmi2SetDebugLogging", unsafe {
                    ffi::fmi2SetDebugLogging(c, *on as fmi2Boolean, ptrs.len(), array)
                });
            }
            Op::SetupExperiment {
                tolerance,
                start,
                stop,
            } => {
                check_status("fmi2SetupExperiment", unsafe {
                    ffi::fmi2SetupExperiment(
                        c,
                        tolerance.is_some() as fmi2Boolean,
                        tolerance.map_or(0.0, Num::get),
                        start.get(),
                        stop.is_some() as fmi2Boolean,
                        stop.map_or(0.0, Num::get),
                    )
                });
            }
            Op::EnterInitializationMode => {
                check_status("fmi2EnterInitializationMode", unsafe {
                    ffi::fmi2EnterInitializationMode(c)
                });
            }
            Op::ExitInitializationMode => {
                let s = check_status("fmi2ExitInitializationMode", unsafe {
                    ffi::fmi2ExitInitializationMode(c)
                });
                if status_ok(s) {
                    self.read_outputs("fmi2ExitInitializationMode");
                }
            }
            Op::Terminate => {
                check_status("fmi2Terminate", unsafe { ffi::fmi2Terminate(c) });
            }
            Op::Reset => {
                check_status("fmi2Reset", unsafe { ffi::fmi2Reset(c) });
            }
            Op::GetReal { vrs, null_values } => {
                let vrs: Vec<u32> = vrs.iter().map(|v| v.get()).collect();
                get_reals("fmi2GetReal", vrs.len(), *null_values, |out| unsafe {
                    ffi::fmi2GetReal(c, vrs.as_ptr(), vrs.len(), out)
                });
            }
            Op::GetInteger { vrs } => {
                let vrs: Vec<u32> = vrs.iter().map(|v| v.get()).collect();
                let mut out = vec![0; vrs.len()];
                check_status("fmi2GetInteger", unsafe {
                    ffi::fmi2GetInteger(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
                });
            }
            Op::GetBoolean { vrs } => {
                let vrs: Vec<u32> = vrs.iter().map(|v| v.get()).collect();
                let mut out = vec![0; vrs.len()];
                check_status("fmi2GetBoolean", unsafe {
                    ffi::fmi2GetBoolean(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
                });
            }
            Op::GetString { vrs } => {
                let vrs: Vec<u32> = vrs.iter().map(|v| v.get()).collect();
                let mut out = vec![null(); vrs.len()];
                check_status("fmi2GetString", unsafe {
                    ffi::fmi2GetString(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
                });
            }
            Op::SetReal {
                values,
                null_values,
            } => {
                let (vrs, v): (Vec<u32>, Vec<f64>) =
                    values.iter().map(|(r, x)| (r.get(), x.get())).unzip();
                let src = if *null_values { null() } else { v.as_ptr() };
                self.unchanged_if_refused("fmi2SetReal", || unsafe {
                    ffi::fmi2SetReal(c, vrs.as_ptr(), vrs.len(), src)
                });
            }
            Op::SetInteger { values } => {
                let (vrs, v): (Vec<u32>, Vec<i32>) =
                    values.iter().map(|(r, x)| (r.get(), *x)).unzip();
                self.unchanged_if_refused("fmi2SetInteger", || unsafe {
                    ffi::fmi2SetInteger(c, vrs.as_ptr(), vrs.len(), v.as_ptr())
                });
            }
            Op::SetBoolean { values } => {
                let (vrs, v): (Vec<u32>, Vec<i32>) =
                    values.iter().map(|(r, x)| (r.get(), *x)).unzip();
                self.unchanged_if_refused("fmi2SetBoolean", || unsafe {
                    ffi::fmi2SetBoolean(c, vrs.as_ptr(), vrs.len(), v.as_ptr())
                });
            }
            Op::SetString { values } => {
                let vrs: Vec<u32> = values.iter().map(|(r, _)| r.get()).collect();
                let owned: Vec<_> = values.iter().map(|(_, t)| t.get()).collect();
                let ptrs: Vec<_> = owned.iter().map(ptr).collect();
                self.unchanged_if_refused("fmi2SetString", || unsafe {
                    ffi::fmi2SetString(c, vrs.as_ptr(), vrs.len(), ptrs.as_ptr())
                });
            }
            Op::SetRealInputDerivatives { values } => {
                let vrs: Vec<u32> = values.iter().map(|v| v.0.get()).collect();
                let orders: Vec<i32> = values.iter().map(|v| v.1).collect();
                let v: Vec<f64> = values.iter().map(|v| v.2.get()).collect();
                self.unchanged_if_refused("fmi2SetRealInputDerivatives", || unsafe {
                    ffi::fmi2SetRealInputDerivatives(
                        c,
                        vrs.as_ptr(),
                        vrs.len(),
                        orders.as_ptr(),
                        v.as_ptr(),
                    )
                });
            }
            Op::GetRealOutputDerivatives { vrs } => {
                let (vrs, orders): (Vec<u32>, Vec<i32>) =
                    vrs.iter().map(|(r, o)| (r.get(), *o)).unzip();
                get_reals(
                    "fmi2GetRealOutputDerivatives",
                    vrs.len(),
                    false,
                    |out| unsafe {
                        ffi::fmi2GetRealOutputDerivatives(
                            c,
                            vrs.as_ptr(),
                            vrs.len(),
                            orders.as_ptr(),
                            out,
                        )
                    },
                );
            }
            Op::GetDirectionalDerivative { unknowns, knowns } => {
                let u: Vec<u32> = unknowns.iter().map(|v| v.get()).collect();
                let (k, dv): (Vec<u32>, Vec<f64>) =
                    knowns.iter().map(|(r, x)| (r.get(), x.get())).unzip();
                get_reals(
                    "fmi2GetDirectionalDerivative",
                    u.len(),
                    false,
                    |out| unsafe {
                        ffi::fmi2GetDirectionalDerivative(
                            c,
                            u.as_ptr(),
                            u.len(),
                            k.as_ptr(),
                            k.len(),
                            dv.as_ptr(),
                            out,
                        )
                    },
                );
            }
            Op::DoStep {
                when,
                size,
                no_set_prior,
            } => {
                let (t, h) = (self.at(*when), size.get());
                let h = if h > LONGEST_STEP && h < 1e12 {
                    LONGEST_STEP
                } else {
                    h
                };
                let s = check_status("fmi2DoStep", unsafe {
                    ffi::fmi2DoStep(c, t, h, *no_set_prior as fmi2Boolean)
                });
                if status_ok(s) {
                    self.read_outputs("fmi2DoStep");
                }
            }
            Op::CancelStep => {
                check_status("fmi2CancelStep", unsafe { ffi::fmi2CancelStep(c) });
            }
            Op::SetTime { when } => {
                let t = self.at(*when);
                self.unchanged_if_refused("fmi2SetTime", || unsafe { ffi::fmi2SetTime(c, t) });
            }
            Op::SetContinuousStates {
                x,
                length,
                null_values,
            } => {
                let mut x = self.states(x);
                x.resize(length.of(NX), 0.0);
                self.set_continuous_states(&x, *null_values);
            }
            Op::GetVector {
                which,
                length,
                null_values,
            } => {
                self.get_vector(*which as usize % GETTERS.len(), *length, *null_values);
            }
            Op::EnterEventMode => {
                check_status("fmi2EnterEventMode", unsafe { ffi::fmi2EnterEventMode(c) });
            }
            Op::NewDiscreteStates { null_info } => {
                self.new_discrete_states(*null_info);
            }
            Op::EnterContinuousTimeMode => {
                check_status("fmi2EnterContinuousTimeMode", unsafe {
                    ffi::fmi2EnterContinuousTimeMode(c)
                });
            }
            Op::CompletedIntegratorStep {
                no_set_prior,
                null_enter,
                null_terminate,
            } => {
                self.completed_integrator_step(*no_set_prior, [*null_enter, *null_terminate]);
            }
            Op::Integrate { steps, size } => {
                self.integrate(*steps as usize % 16 + 1, size.get());
            }
            Op::GetStatus { kind, which } => {
                let (mut s, mut r, mut i, mut b, mut t) = (0, 0.0, 0, 0, null());
                let status = unsafe {
                    match which % 5 {
                        0 => ffi::fmi2GetStatus(c, *kind, &mut s),
                        1 => ffi::fmi2GetRealStatus(c, *kind, &mut r),
                        2 => ffi::fmi2GetIntegerStatus(c, *kind, &mut i),
                        3 => ffi::fmi2GetBooleanStatus(c, *kind, &mut b),
                        _ => ffi::fmi2GetStringStatus(c, *kind, &mut t),
                    }
                };
                check_finite(
                    "fmi2GetRealStatus",
                    check_status("fmi2Get*Status", status),
                    &[r],
                );
            }
            Op::GetFMUstate { slot } => {
                let k = *slot as usize % SLOTS;
                let s = check_status("fmi2GetFMUstate", unsafe {
                    ffi::fmi2GetFMUstate(c, &mut self.slots[k].0)
                });
                if status_ok(s) {
                    self.slots[k].1 = true;
                }
            }
            Op::SetFMUstate { slot } => {
                let state = self.slots[*slot as usize % SLOTS].0;
                check_status("fmi2SetFMUstate", unsafe { ffi::fmi2SetFMUstate(c, state) });
            }
            Op::FreeFMUstate { slot } => {
                let k = *slot as usize % SLOTS;
                let s = check_status("fmi2FreeFMUstate", unsafe {
                    ffi::fmi2FreeFMUstate(c, &mut self.slots[k].0)
                });
                assert!(!status_ok(s) || self.slots[k].0.is_null());
            }
            Op::ForeignFMUstate { which } => {
                let foreign = vec![0u64; 1];
                let p = foreign.as_ptr() as fmi2FMUstate;
                let mut slot = p;
                let mut size = 0;
                let s = unsafe {
                    match which % 4 {
                        0 => ffi::fmi2SetFMUstate(c, p),
                        1 => ffi::fmi2FreeFMUstate(c, &mut slot),
                        2 => ffi::fmi2GetFMUstate(c, &mut slot),
                        _ => ffi::fmi2SerializedFMUstateSize(c, p, &mut size),
                    }
                };
                assert_eq!(check_status("a foreign FMU state", s), fmi2Status_fmi2Error);
            }
            Op::SerializedFMUstateSize { slot } => {
                let mut size = 0;
                let state = self.slots[*slot as usize % SLOTS].0;
                check_status("fmi2SerializedFMUstateSize", unsafe {
                    ffi::fmi2SerializedFMUstateSize(c, state, &mut size)
                });
            }
            Op::Serialize { slot, size_off } => {
                let (state, from_get) = self.slots[*slot as usize % SLOTS];
                let mut size = 0;
                let s = unsafe { ffi::fmi2SerializedFMUstateSize(c, state, &mut size) };
                if !status_ok(check_status("fmi2SerializedFMUstateSize", s)) {
                    return;
                }
                let asked = size.saturating_add_signed(*size_off as isize);
                let mut bytes = vec![0u8; asked];
                let s = check_status("fmi2SerializeFMUstate", unsafe {
                    ffi::fmi2SerializeFMUstate(c, state, bytes.as_mut_ptr() as *mut fmi2Byte, asked)
                });
                assert_eq!(
                    status_ok(s),
                    asked == size,
                    "fmi2SerializeFMUstate of {asked} bytes ({size} needed): {s}"
                );
                if status_ok(s) {
                    if from_get {
                        self.round_trip(&bytes);
                    }
                    self.buffers.push(bytes);
                    if self.buffers.len() > 4 {
                        self.buffers.remove(0);
                    }
                }
            }
            Op::DeSerialize { buffer, slot } => {
                let Some(bytes) = self.buffer(*buffer) else {
                    return;
                };
                let bytes = bytes.clone();
                let k = *slot as usize % SLOTS;
                let s = check_status("fmi2DeSerializeFMUstate", unsafe {
                    ffi::fmi2DeSerializeFMUstate(
                        c,
                        bytes.as_ptr() as *const fmi2Byte,
                        bytes.len(),
                        &mut self.slots[k].0,
                    )
                });
                if status_ok(s) {
                    self.slots[k].1 = false;
                }
            }
            Op::Mutate { buffer, how } => {
                let n = self.buffers.len();
                if n == 0 {
                    return;
                }
                mutate(&mut self.buffers[*buffer as usize % n], how);
            }
            Op::Splice { from, to, at } => {
                let (Some(a), Some(b)) = (self.buffer(*from).cloned(), self.buffer(*to).cloned())
                else {
                    return;
                };
                let cut = *at as usize % (a.len().min(b.len()) + 1);
                self.buffers.push([&b[..cut], &a[cut..]].concat());
            }
            Op::NullComponent { which } => null_component(*which),
            Op::Versions => unsafe {
                assert_eq!(std::ffi::CStr::from_ptr(ffi::fmi2GetVersion()), c"2.0");
                assert_eq!(
                    std::ffi::CStr::from_ptr(ffi::fmi2GetTypesPlatform()),
                    c"default"
                );
            },
        }
    }

    fn buffer(&self, k: u8) -> Option<&Vec<u8>> {
        let n = self.buffers.len();
        (n > 0).then(|| &self.buffers[k as usize % n])
    }

    /// Runs a fmi2Set* call; refused with the instance still in a working state, it must
    /// have left the FMU state as it was.
    fn unchanged_if_refused(&mut self, call: &str, f: impl FnOnce() -> fmi2Status) -> fmi2Status {
        let before = self.fmu_state_bytes();
        let s = check_status(call, f());
        if !status_ok(s)
            && self
                .component()
                .is_some_and(|c| c.fmu.state != FmiState::Error)
        {
            assert!(
                self.fmu_state_bytes() == before,
                "{call} was refused ({s}) but changed the FMU state"
            );
        }
        s
    }

    /// The instance still has the interface it was instantiated for.
    fn check_interface(&self) {
        if let Some(c) = self.component() {
            assert_eq!(
                c.fmu.interface(),
                self.interface,
                "the instance changed its interface"
            );
        }
    }

    /// A state fmi2GetFMUstate made deserializes into one that serializes to the same bytes.
    fn round_trip(&mut self, bytes: &[u8]) {
        let mut state = null_mut();
        let s = unsafe {
            ffi::fmi2DeSerializeFMUstate(
                self.c,
                bytes.as_ptr() as *const fmi2Byte,
                bytes.len(),
                &mut state,
            )
        };
        assert!(
            status_ok(s),
            "fmi2DeSerializeFMUstate of a fmi2SerializeFMUstate output: {s}"
        );
        let mut again = vec![0u8; bytes.len()];
        let s = unsafe {
            ffi::fmi2SerializeFMUstate(
                self.c,
                state,
                again.as_mut_ptr() as *mut fmi2Byte,
                again.len(),
            )
        };
        assert!(
            status_ok(s) && again == bytes,
            "a serialized state did not round-trip"
        );
        assert!(status_ok(unsafe {
            ffi::fmi2FreeFMUstate(self.c, &mut state)
        }));
    }

    /// Sets up and initialises the instance from t = 0 in a drive mode (`excitation`: 0
    /// inputs, 1 sine as in the bench scene S1, 2 torque), the other values at their start.
    fn initialise(&self, excitation: i32, when: &str) {
        let c = self.c;
        let (vr, v) = ([gear_rattle::contract::vr::excitation], [excitation]);
        unsafe {
            for (call, s) in [
                (
                    "fmi2SetupExperiment",
                    ffi::fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0),
                ),
                (
                    "fmi2EnterInitializationMode",
                    ffi::fmi2EnterInitializationMode(c),
                ),
                (
                    "fmi2SetInteger",
                    ffi::fmi2SetInteger(c, vr.as_ptr(), 1, v.as_ptr()),
                ),
                (
                    "fmi2ExitInitializationMode",
                    ffi::fmi2ExitInitializationMode(c),
                ),
            ] {
                assert!(status_ok(s), "{call} {when}: {s}");
            }
        }
    }

    /// The ways back the standard gives after any sequence: the states fmi2GetFMUstate
    /// made are taken back, and fmi2Reset leads to a working run of S1 (a step of 2 ms in
    /// Co-Simulation, ten Euler steps of 1 µs in Model Exchange).
    fn check_usable(&mut self) {
        if self.c.is_null() {
            return;
        }
        let c = self.c;
        for (state, from_get) in self.slots {
            if from_get && !state.is_null() {
                let s = unsafe { ffi::fmi2SetFMUstate(c, state) };
                assert!(
                    status_ok(s),
                    "fmi2SetFMUstate of a state fmi2GetFMUstate gave: {s}"
                );
            }
        }
        assert!(status_ok(unsafe { ffi::fmi2Reset(c) }), "fmi2Reset");
        self.initialise(1, "after fmi2Reset");
        let stepped = match self.interface {
            Interface::CoSimulation => status_ok(unsafe { ffi::fmi2DoStep(c, 0.0, 2e-3, 1) }),
            Interface::ModelExchange => self.integrate(10, 1e-6),
        };
        assert!(stepped, "a step of S1 after fmi2Reset");
        self.read_outputs("fmi2Reset and a step of S1");
        let ints = outputs(Kind::Integer);
        let mut out = vec![0; ints.len()];
        assert!(status_ok(unsafe {
            ffi::fmi2GetInteger(c, ints.as_ptr(), ints.len(), out.as_mut_ptr())
        }));
    }
}

fn mutate(bytes: &mut Vec<u8>, how: &Mutation) {
    let n = bytes.len();
    match how {
        Mutation::Flip { at, bit } if n > 0 => bytes[*at as usize % n] ^= 1 << (bit % 8),
        Mutation::Byte { at, value } if n > 0 => bytes[*at as usize % n] = *value,
        Mutation::Real { at, value } if n >= 8 => {
            let k = *at as usize % (n - 7);
            bytes[k..k + 8].copy_from_slice(&value.get().to_le_bytes());
        }
        Mutation::Truncate(len) => bytes.truncate(*len as usize % (n + 1)),
        Mutation::Append(more) => bytes.extend_from_slice(more),
        Mutation::Mend if n >= 14 => {
            // Layout (src/instance/fmu_state.rs): magic(4) version(2) length(4) payload crc(4).
            let payload = n - 14;
            bytes[6..10].copy_from_slice(&(payload as u32).to_le_bytes());
            let crc = crc32fast::hash(&bytes[10..n - 4]);
            bytes[n - 4..].copy_from_slice(&crc.to_le_bytes());
        }
        _ => {}
    }
}

/// A call with a NULL component: refused with fmi2Error (fmi2FreeInstance: nothing).
fn null_component(which: u8) {
    let c = null_mut();
    let (mut r, mut i, mut state) = ([0.0], [0], null_mut());
    let vr = [0u32];
    let (mut b, mut info) = (0, std::mem::MaybeUninit::<fmi2EventInfo>::uninit());
    let s = unsafe {
        match which % 16 {
            10 => ffi::fmi2SetTime(c, 0.0),
            11 => ffi::fmi2SetContinuousStates(c, r.as_ptr(), 1),
            12 => ffi::fmi2GetDerivatives(c, r.as_mut_ptr(), 1),
            13 => ffi::fmi2NewDiscreteStates(c, info.as_mut_ptr()),
            14 => ffi::fmi2CompletedIntegratorStep(c, 0, &mut b, &mut b),
            15 => ffi::fmi2EnterEventMode(c),
            0 => ffi::fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0),
            1 => ffi::fmi2EnterInitializationMode(c),
            2 => ffi::fmi2DoStep(c, 0.0, 1e-3, 0),
            3 => ffi::fmi2GetReal(c, vr.as_ptr(), 1, r.as_mut_ptr()),
            4 => ffi::fmi2SetInteger(c, vr.as_ptr(), 1, i.as_mut_ptr()),
            5 => ffi::fmi2GetFMUstate(c, &mut state),
            6 => ffi::fmi2Reset(c),
            7 => ffi::fmi2Terminate(c),
            8 => ffi::fmi2GetRealStatus(c, fmi2StatusKind_fmi2LastSuccessfulTime, r.as_mut_ptr()),
            _ => {
                ffi::fmi2FreeInstance(c);
                fmi2Status_fmi2Error
            }
        }
    };
    assert_eq!(s, fmi2Status_fmi2Error, "a call with a NULL component");
}

/// One input: the interface of the first instance, where it starts, and the calls. `start`
/// modulo 4: 0 just instantiated, else initialised in the drive mode `start % 4 - 1` (so
/// that the calls of a running instance are reached without first finding the sequence
/// that initialises it).
#[derive(Arbitrary, Debug)]
struct Input {
    model_exchange: bool,
    start: u8,
    ops: Vec<Op>,
}

fuzz_target!(|input: Input| {
    // FUZZ_TRACE=1 (replaying a crash): each call, then the instance's state and time.
    let trace = std::env::var_os("FUZZ_TRACE").is_some();
    let mut h = Harness::new(if input.model_exchange {
        Interface::ModelExchange
    } else {
        Interface::CoSimulation
    });
    let start = input.start % 4;
    if start > 0 {
        h.initialise(start as i32 - 1, "at the start");
    }
    for op in input.ops.iter().take(64) {
        h.run(op);
        if trace {
            let now = h
                .component()
                .map(|c| (c.fmu.state, c.fmu.last_successful_time()));
            eprintln!(
                "{op:?}\n  -> {now:?}, log {:?}",
                h.env.lines.lock().unwrap()[h.seen..].to_vec()
            );
        }
        h.check_log();
        h.check_interface();
    }
    h.check_usable();
    h.check_log();
    h.free_instance();
});
