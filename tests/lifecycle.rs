//! Whole lifecycles through the C API, every kind of call and its error paths, for the memory
//! checks (`make check-memory`: valgrind memcheck and AddressSanitizer run this file) as well
//! as for `cargo test`: instantiate, set up, step in the three drive modes, read, take and
//! restore FMU states, serialize and deserialize them, refuse bad calls, reset, free.

mod capi;

use capi::{Env, Slave, callbacks, ffi, ok, outputs, s1_start};
use fmi2_shell::fmi2::*;
use gear_rattle::contract::{GUID, Kind, vr};
use std::ffi::CString;
use std::ptr::{null, null_mut};

fn refused(slave: &Slave, call: &str, status: fmi2Status) {
    assert!(
        status == fmi2Status_fmi2Error || status == fmi2Status_fmi2Discard,
        "{call} should be refused, returned {status}"
    );
    let last = slave.lines().pop().expect("a refused call logs why");
    assert!(last.message.contains(call), "{call}: {}", last.message);
}

/// Takes, serializes, deserializes, restores and frees FMU states; returns nothing but
/// leaves the instance where it was.
fn fmu_states(slave: &Slave, t: f64) {
    let c = slave.c;
    let mut saved = null_mut();
    unsafe {
        ok(
            slave,
            "fmi2GetFMUstate",
            ffi::fmi2GetFMUstate(c, &mut saved),
        );
        let before = slave.output_bits();
        ok(slave, "fmi2DoStep", ffi::fmi2DoStep(c, t, 1e-3, 0));
        ok(slave, "fmi2SetFMUstate", ffi::fmi2SetFMUstate(c, saved));
        assert_eq!(slave.output_bits(), before, "restored state");
        let mut size = 0;
        ok(
            slave,
            "fmi2SerializedFMUstateSize",
            ffi::fmi2SerializedFMUstateSize(c, saved, &mut size),
        );
        let mut bytes = vec![0u8; size];
        let out = bytes.as_mut_ptr() as *mut fmi2Byte;
        refused(
            slave,
            "fmi2SerializeFMUstate",
            ffi::fmi2SerializeFMUstate(c, saved, out, size - 1),
        );
        ok(
            slave,
            "fmi2SerializeFMUstate",
            ffi::fmi2SerializeFMUstate(c, saved, out, size),
        );
        // Into a new state, then over an existing one.
        let mut back = null_mut();
        let input = bytes.as_ptr() as *const fmi2Byte;
        ok(
            slave,
            "fmi2DeSerializeFMUstate",
            ffi::fmi2DeSerializeFMUstate(c, input, size, &mut back),
        );
        ok(
            slave,
            "fmi2DeSerializeFMUstate",
            ffi::fmi2DeSerializeFMUstate(c, input, size, &mut saved),
        );
        ok(slave, "fmi2SetFMUstate", ffi::fmi2SetFMUstate(c, back));
        assert_eq!(slave.output_bits(), before, "deserialized state");
        // Corrupt bytes, a foreign pointer, NULL: refused, nothing allocated.
        bytes[size / 2] ^= 0x10;
        let mut none = null_mut();
        let input = bytes.as_ptr() as *const fmi2Byte;
        refused(
            slave,
            "fmi2DeSerializeFMUstate",
            ffi::fmi2DeSerializeFMUstate(c, input, size, &mut none),
        );
        assert!(none.is_null());
        let foreign = [0u64; 64];
        refused(
            slave,
            "fmi2SetFMUstate",
            ffi::fmi2SetFMUstate(c, foreign.as_ptr() as fmi2FMUstate),
        );
        refused(
            slave,
            "fmi2SetFMUstate",
            ffi::fmi2SetFMUstate(c, null_mut()),
        );
        ok(
            slave,
            "fmi2FreeFMUstate",
            ffi::fmi2FreeFMUstate(c, &mut saved),
        );
        ok(
            slave,
            "fmi2FreeFMUstate",
            ffi::fmi2FreeFMUstate(c, &mut back),
        );
        ok(
            slave,
            "fmi2FreeFMUstate",
            ffi::fmi2FreeFMUstate(c, &mut none),
        );
        assert!(saved.is_null() && back.is_null());
    }
}

/// Calls that must be refused, each leaving the instance usable.
fn refusals(slave: &Slave, t: f64) {
    let c = slave.c;
    let mut v = [0.0; 2];
    let unknown = [vr::xi, 9999];
    unsafe {
        refused(
            slave,
            "fmi2GetReal",
            ffi::fmi2GetReal(c, unknown.as_ptr(), 2, v.as_mut_ptr()),
        );
        refused(
            slave,
            "fmi2GetReal",
            ffi::fmi2GetReal(c, unknown.as_ptr(), 1, null_mut()),
        );
        let nan = [f64::NAN];
        refused(
            slave,
            "fmi2SetReal",
            ffi::fmi2SetReal(c, [vr::omega_M].as_ptr(), 1, nan.as_ptr()),
        );
        refused(
            slave,
            "fmi2SetReal",
            ffi::fmi2SetReal(c, [vr::xi].as_ptr(), 1, [0.0].as_ptr()),
        );
        refused(
            slave,
            "fmi2SetInteger",
            ffi::fmi2SetInteger(c, [vr::excitation].as_ptr(), 1, [2].as_ptr()),
        );
        refused(
            slave,
            "fmi2SetBoolean",
            ffi::fmi2SetBoolean(c, [0].as_ptr(), 1, [1].as_ptr()),
        );
        refused(
            slave,
            "fmi2SetString",
            ffi::fmi2SetString(c, [0].as_ptr(), 1, [c"%s%n".as_ptr()].as_ptr()),
        );
        refused(slave, "fmi2DoStep", ffi::fmi2DoStep(c, t, -1e-3, 0));
        refused(slave, "fmi2DoStep", ffi::fmi2DoStep(c, t, f64::NAN, 0));
        refused(slave, "fmi2DoStep", ffi::fmi2DoStep(c, t + 1.0, 1e-3, 0));
        refused(
            slave,
            "fmi2EnterInitializationMode",
            ffi::fmi2EnterInitializationMode(c),
        );
        let categories = [c"logEvents".as_ptr(), c"no%such\xffcategory".as_ptr()];
        refused(
            slave,
            "fmi2SetDebugLogging",
            ffi::fmi2SetDebugLogging(c, 1, 2, categories.as_ptr()),
        );
        refused(slave, "fmi2CancelStep", ffi::fmi2CancelStep(c));
        let mut status = 0;
        refused(
            slave,
            "fmi2GetStatus",
            ffi::fmi2GetStatus(c, fmi2StatusKind_fmi2DoStepStatus, &mut status),
        );
        let (k, o, d) = ([vr::xi], [3], [0.0]);
        let mut out = [0.0];
        refused(
            slave,
            "fmi2GetRealOutputDerivatives",
            ffi::fmi2GetRealOutputDerivatives(c, k.as_ptr(), 1, o.as_ptr(), out.as_mut_ptr()),
        );
        refused(
            slave,
            "fmi2GetDirectionalDerivative",
            ffi::fmi2GetDirectionalDerivative(
                c,
                k.as_ptr(),
                1,
                k.as_ptr(),
                1,
                d.as_ptr(),
                out.as_mut_ptr(),
            ),
        );
    }
}

/// Reads every kind of value a master reads after a step.
fn reads(slave: &Slave, t: f64) {
    let c = slave.c;
    let reals = slave.get_real(&outputs(Kind::Real));
    assert!(reals.iter().all(|x| x.is_finite()));
    let (vrs, orders) = ([vr::xi, vr::tau_M], [1, 1]);
    let mut d = [0.0; 2];
    let (knowns, dv) = ([vr::theta_M, vr::omega_M], [1.0, 0.5]);
    let mut last = 0.0;
    unsafe {
        ok(
            slave,
            "fmi2GetRealOutputDerivatives",
            ffi::fmi2GetRealOutputDerivatives(c, vrs.as_ptr(), 2, orders.as_ptr(), d.as_mut_ptr()),
        );
        ok(
            slave,
            "fmi2GetDirectionalDerivative",
            ffi::fmi2GetDirectionalDerivative(
                c,
                vrs.as_ptr(),
                2,
                knowns.as_ptr(),
                2,
                dv.as_ptr(),
                d.as_mut_ptr(),
            ),
        );
        ok(
            slave,
            "fmi2GetRealStatus",
            ffi::fmi2GetRealStatus(c, fmi2StatusKind_fmi2LastSuccessfulTime, &mut last),
        );
    }
    assert_eq!(last, t);
}

/// One run in drive mode `excitation` (0 inputs, 1 sine, 2 torque) on an instance, from
/// initialisation to fmi2Terminate.
fn run(slave: &Slave, excitation: i32) {
    let (mut reals, _) = s1_start(30.0, 0.0);
    if excitation == 2 {
        reals.push((vr::tau_in, 1.0));
    }
    slave.initialise(1e-6, &reals, &[(vr::excitation, excitation)]);
    let c = slave.c;
    let h = 2e-4;
    for k in 0..40 {
        let t = k as f64 * h;
        if excitation == 0 {
            let w = 2.0 * std::f64::consts::PI * 30.0;
            let (th, om, al) = (
                (w * t).sin() * 1e-3,
                (w * t).cos() * w * 1e-3,
                -(w * t).sin() * w * w * 1e-3,
            );
            let vrs = [vr::theta_M, vr::omega_M, vr::alpha_M];
            unsafe {
                ok(
                    slave,
                    "fmi2SetReal",
                    ffi::fmi2SetReal(c, vrs.as_ptr(), 3, [th, om, al].as_ptr()),
                )
            };
        }
        if excitation == 2 {
            let (vrs, orders, rates) = ([vr::tau_in], [1], [50.0]);
            unsafe {
                ok(
                    slave,
                    "fmi2SetRealInputDerivatives",
                    ffi::fmi2SetRealInputDerivatives(
                        c,
                        vrs.as_ptr(),
                        1,
                        orders.as_ptr(),
                        rates.as_ptr(),
                    ),
                )
            };
        }
        ok(slave, "fmi2DoStep", slave.step(t, h));
        reads(slave, t + h);
        if k % 10 == 5 {
            fmu_states(slave, t + h);
            refusals(slave, t + h);
        }
    }
    unsafe { ok(slave, "fmi2Terminate", ffi::fmi2Terminate(c)) };
}

#[test]
fn full_lifecycles_in_every_drive_mode() {
    let slave = Slave::new("lifecycle", true);
    for excitation in [1, 0, 2] {
        run(&slave, excitation);
        unsafe { ok(&slave, "fmi2Reset", ffi::fmi2Reset(slave.c)) };
    }
    let categories = [c"logEvents".as_ptr(), c"logStep".as_ptr()];
    unsafe {
        ok(
            &slave,
            "fmi2SetDebugLogging",
            ffi::fmi2SetDebugLogging(slave.c, 0, 2, categories.as_ptr()),
        )
    };
    run(&slave, 1);
    // Freed in every state.
    for steps in 0..3 {
        let other = Slave::new("freed early", false);
        if steps > 0 {
            other.initialise(1e-6, &s1_start(30.0, 0.0).0, &[(vr::excitation, 1)]);
        }
        if steps > 1 {
            ok(&other, "fmi2DoStep", other.step(0.0, 1e-3));
        }
    }
}

/// fmi2Instantiate with a bad argument returns NULL after logging why; NULL callbacks and a
/// NULL logger are accepted.
#[test]
fn instantiation_errors_allocate_nothing() {
    let env = Box::<Env>::default();
    let functions = callbacks(&*env);
    let guid = CString::new(GUID).unwrap();
    let attempts: [(*const i8, fmi2Type, *const i8); 4] = [
        (c"x".as_ptr(), 7, guid.as_ptr()),
        (
            c"x".as_ptr(),
            fmi2Type_fmi2CoSimulation,
            c"{not the GUID}".as_ptr(),
        ),
        (c"x".as_ptr(), fmi2Type_fmi2CoSimulation, null()),
        (null(), fmi2Type_fmi2CoSimulation, guid.as_ptr()),
    ];
    for (name, kind, g) in attempts {
        let c = unsafe { ffi::fmi2Instantiate(name, kind, g, null(), &functions, 0, 0) };
        assert!(c.is_null());
    }
    assert_eq!(
        env.lines.lock().unwrap().len(),
        attempts.len(),
        "one line per refusal"
    );
    for functions in [
        null(),
        &fmi2CallbackFunctions {
            logger: None,
            ..functions
        } as *const _,
    ] {
        let c = unsafe {
            ffi::fmi2Instantiate(
                c"quiet".as_ptr(),
                fmi2Type_fmi2CoSimulation,
                guid.as_ptr(),
                null(),
                functions,
                0,
                1,
            )
        };
        assert!(!c.is_null());
        let mut v = [0.0];
        assert_eq!(
            unsafe { ffi::fmi2GetReal(c, [9999].as_ptr(), 1, v.as_mut_ptr()) },
            fmi2Status_fmi2Error
        );
        unsafe { ffi::fmi2FreeInstance(c) };
    }
    unsafe { ffi::fmi2FreeInstance(null_mut()) };
}

/// An instance name that is not UTF-8 (an importer's code page) is accepted and handed back to
/// the logger byte for byte; it was refused as "missing or empty" (found by the fuzzer).
#[test]
fn an_instance_name_in_a_code_page_is_kept_as_given() {
    let env = Box::<Env>::default();
    let functions = callbacks(&*env);
    let guid = CString::new(GUID).unwrap();
    let name = c"Zahnrad_\xe4%s";
    let c = unsafe {
        ffi::fmi2Instantiate(
            name.as_ptr(),
            fmi2Type_fmi2CoSimulation,
            guid.as_ptr(),
            null(),
            &functions,
            0,
            0,
        )
    };
    assert!(!c.is_null(), "refused: {:?}", env.lines.lock().unwrap());
    let mut v = [0.0];
    assert_eq!(
        unsafe { ffi::fmi2GetReal(c, [9999].as_ptr(), 1, v.as_mut_ptr()) },
        fmi2Status_fmi2Error
    );
    unsafe { ffi::fmi2FreeInstance(c) };
    let lines = env.lines.lock().unwrap();
    assert_eq!(lines[0].instance, name.to_string_lossy());
}

/// A seed vector with ±Inf or NaN, or one whose product with the Jacobian overflows, is
/// refused: fmi2OK came with NaN (found by the fuzzer).
#[test]
fn directional_derivatives_are_finite_or_refused() {
    let slave = Slave::new("seed", false);
    // Inputs mode: the main shaft's outputs follow its inputs.
    slave.initialise(1e-6, &[], &[(vr::excitation, 0)]);
    let unknowns = [vr::theta_M_out, vr::tau_M];
    let mut out = [0.0; 2];
    let call = |knowns: &[u32], dv: &[f64], out: &mut [f64; 2]| unsafe {
        ffi::fmi2GetDirectionalDerivative(
            slave.c,
            unknowns.as_ptr(),
            2,
            knowns.as_ptr(),
            knowns.len(),
            dv.as_ptr(),
            out.as_mut_ptr(),
        )
    };
    for bad in [f64::NEG_INFINITY, f64::INFINITY, f64::NAN] {
        refused(
            &slave,
            "fmi2GetDirectionalDerivative",
            call(&[vr::theta_M], &[bad], &mut out),
        );
    }
    let twice = [vr::theta_M, vr::theta_M];
    refused(
        &slave,
        "fmi2GetDirectionalDerivative",
        call(&twice, &[1e308, 1e308], &mut out),
    );
    ok(
        &slave,
        "fmi2GetDirectionalDerivative",
        call(&twice, &[1.0, 0.5], &mut out),
    );
    assert_eq!(out[0], 1.5, "theta_M_out follows theta_M one for one");
}

/// A run started at t = -1.8e308 and stepped to 0 in one step of 1.8e308 s, then by a
/// subnormal step of 1.6e-314 s, overflows on the next step: that step fails with fmi2Error
/// and no read hands out the NaN with fmi2OK (fmi2DoStep then fmi2GetReal returned fmi2OK
/// with NaN: found by the fuzzer).
#[test]
fn a_step_that_overflows_fails_and_nothing_non_finite_is_read() {
    let slave = Slave::new("overflow", false);
    let c = slave.c;
    unsafe {
        ok(
            &slave,
            "fmi2SetupExperiment",
            ffi::fmi2SetupExperiment(c, 0, 0.0, f64::MIN, 0, 0.0),
        );
        ok(
            &slave,
            "fmi2EnterInitializationMode",
            ffi::fmi2EnterInitializationMode(c),
        );
        ok(
            &slave,
            "fmi2ExitInitializationMode",
            ffi::fmi2ExitInitializationMode(c),
        );
    }
    let tiny = 1.6394752844e-314;
    ok(&slave, "fmi2DoStep", slave.step(f64::MIN, f64::MAX));
    ok(&slave, "fmi2DoStep", slave.step(0.0, tiny));
    // From a communication point a rounding error away, as a master may give it.
    refused(
        &slave,
        "fmi2DoStep",
        slave.step(f64::from_bits(4291151302), 1e-7),
    );
    let vrs = outputs(Kind::Real);
    let mut out = vec![0.0; vrs.len()];
    let s = unsafe { ffi::fmi2GetReal(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
    assert!(
        s != fmi2Status_fmi2OK || out.iter().all(|x| x.is_finite()),
        "fmi2OK with {out:?}"
    );
    let (orders, mut d) = ([1, 1], [0.0; 2]);
    let xi = [vr::xi, vr::xi_dot];
    let s = unsafe {
        ffi::fmi2GetRealOutputDerivatives(c, xi.as_ptr(), 2, orders.as_ptr(), d.as_mut_ptr())
    };
    assert!(
        s != fmi2Status_fmi2OK || d.iter().all(|x| x.is_finite()),
        "fmi2OK with {d:?}"
    );
    unsafe { ok(&slave, "fmi2Reset", ffi::fmi2Reset(c)) };
}
