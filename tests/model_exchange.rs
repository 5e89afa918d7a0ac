//! Model Exchange through the C API, where the fuzzer (fuzz/, docs/RELIABILITY.md) found the
//! FMU handing out or accepting what it should not: each test drives an instance the way an
//! importer's solver does and checks the answer FMI 2.0 asks for.

mod capi;

use capi::{Slave, ffi, ok, s1_start};
use fmi2_shell::fmi2::*;
use gear_rattle::instance::model_exchange::NX;
use std::ptr::null_mut;

/// An instance of S1 in continuous-time mode at t = 0.
fn continuous_s1(name: &str) -> Slave {
    let slave = Slave::of_type(name, fmi2Type_fmi2ModelExchange, false);
    let (reals, integers) = s1_start(30.0, 0.0);
    slave.initialise(1e-6, &reals, &integers);
    let mut info = fmi2EventInfo {
        newDiscreteStatesNeeded: 0,
        terminateSimulation: 0,
        nominalsOfContinuousStatesChanged: 0,
        valuesOfContinuousStatesChanged: 0,
        nextEventTimeDefined: 0,
        nextEventTime: 0.0,
    };
    unsafe {
        ok(
            &slave,
            "fmi2NewDiscreteStates",
            ffi::fmi2NewDiscreteStates(slave.c, &mut info),
        );
        ok(
            &slave,
            "fmi2EnterContinuousTimeMode",
            ffi::fmi2EnterContinuousTimeMode(slave.c),
        );
    }
    slave
}

fn states(slave: &Slave) -> Vec<f64> {
    let mut x = vec![0.0; NX];
    ok(slave, "fmi2GetContinuousStates", unsafe {
        ffi::fmi2GetContinuousStates(slave.c, x.as_mut_ptr(), NX)
    });
    x
}

fn set_states(slave: &Slave, x: &[f64]) {
    ok(slave, "fmi2SetContinuousStates", unsafe {
        ffi::fmi2SetContinuousStates(slave.c, x.as_ptr(), x.len())
    });
}

/// The derivatives into an array first filled with 7.0, and the status.
fn derivatives(slave: &Slave) -> (fmi2Status, Vec<f64>) {
    let mut dx = vec![7.0; NX];
    let s = unsafe { ffi::fmi2GetDerivatives(slave.c, dx.as_mut_ptr(), NX) };
    (s, dx)
}

/// A solver's trial point far out (ξ = 1e300 m, deep in the contact: the force overflows)
/// is accepted as finite states, but its derivatives are not finite: fmi2GetDerivatives
/// answers fmi2Discard (a smaller step, FMI 2.0 §2.1.3), logs why, writes nothing, and the
/// instance goes on from the states of the smaller step.
#[test]
fn derivatives_that_overflow_are_discarded_not_handed_out() {
    let slave = continuous_s1("overflow");
    let good = states(&slave);
    let (s, dx) = derivatives(&slave);
    assert!(s == fmi2Status_fmi2OK && dx.iter().all(|v| v.is_finite()));

    let mut far = good.clone();
    far[0] = 1e300;
    set_states(&slave, &far);
    let (s, dx) = derivatives(&slave);
    assert_eq!(
        s, fmi2Status_fmi2Discard,
        "derivatives at xi = 1e300: {dx:?}"
    );
    assert_eq!(dx, vec![7.0; NX], "a discarded call writes nothing");
    let last = slave.lines().pop().expect("a discarded call logs why");
    assert!(
        last.message.starts_with("fmi2GetDerivatives: derivatives[")
            && last.message.contains("smaller step"),
        "{}",
        last.message
    );

    set_states(&slave, &good);
    let (s, dx) = derivatives(&slave);
    assert!(s == fmi2Status_fmi2OK && dx.iter().all(|v| v.is_finite()));
    let mut enter = 0;
    ok(&slave, "fmi2CompletedIntegratorStep", unsafe {
        ffi::fmi2CompletedIntegratorStep(slave.c, 1, &mut enter, null_mut())
    });
}

/// A time where the sine's phase w t overflows (|t| > 1.8e308 / w, 9.5e305 s at 30 Hz)
/// leaves the main shaft's speed NaN: fmi2SetTime refuses it and keeps the time it had, so
/// that the states set next, and read back, stay the importer's.
#[test]
fn a_time_beyond_the_sine_phase_is_refused() {
    let slave = continuous_s1("far time");
    let x = states(&slave);
    let s = unsafe { ffi::fmi2SetTime(slave.c, 1e307) };
    assert_eq!(s, fmi2Status_fmi2Error);
    let last = slave.lines().pop().expect("a refused call logs why");
    assert!(
        last.message
            .starts_with("fmi2SetTime: time = 1e307 refused"),
        "{}",
        last.message
    );
    assert_eq!(states(&slave), x, "a refused time changes no state");
    set_states(&slave, &x);
    assert_eq!(states(&slave), x, "the states read back as set, at t = 0");
    ok(&slave, "fmi2SetTime", unsafe {
        ffi::fmi2SetTime(slave.c, 1e-3)
    });
}

/// An FMU state holds its instance's interface: one taken from a Co-Simulation instance and
/// set into a Model Exchange one would turn it into a Co-Simulation instance. It is refused,
/// and the instance stays as it was.
#[test]
fn a_state_of_the_other_interface_is_refused() {
    let me = continuous_s1("model exchange");
    let cs = Slave::new("co-simulation", false);
    let (reals, integers) = s1_start(30.0, 0.0);
    cs.initialise(1e-6, &reals, &integers);
    let mut state = null_mut();
    unsafe {
        ok(
            &cs,
            "fmi2GetFMUstate",
            ffi::fmi2GetFMUstate(cs.c, &mut state),
        );
        assert_eq!(ffi::fmi2SetFMUstate(me.c, state), fmi2Status_fmi2Error);
        ok(
            &cs,
            "fmi2FreeFMUstate",
            ffi::fmi2FreeFMUstate(cs.c, &mut state),
        );
        assert_eq!(ffi::fmi2DoStep(me.c, 0.0, 1e-3, 1), fmi2Status_fmi2Error);
    }
    let last = me.lines().pop().unwrap();
    assert!(
        last.message.contains("illegal call sequence"),
        "{}",
        last.message
    );
    assert_eq!(derivatives(&me).0, fmi2Status_fmi2OK);
}
