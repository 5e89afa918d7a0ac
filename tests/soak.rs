//! Soak (`make soak`): 100 000 instantiate → initialise → step → free cycles and 1 000 000
//! fmi2GetFMUstate → fmi2SetFMUstate → fmi2FreeFMUstate cycles (every hundredth also
//! serialized and deserialized) through the C API, with the process's resident memory read
//! from /proc after the first thousand cycles and at the end: it must stay flat (the end
//! within 3 % of the first reading, plus 64 KiB for the allocator's rounding). The figures are
//! printed (`make soak` shows them); docs/RELIABILITY.md has the last run's. One test, the
//! two soaks one after the other, so that nothing else in the process moves its memory.

mod capi;

use capi::{Slave, ffi, ok, s1_start};
use fmi2_shell::fmi2::*;
use gear_rattle::contract::vr;
use std::ptr::null_mut;
use std::time::Instant;

/// Resident set size of this process in KiB (VmRSS of /proc/self/status).
fn rss_kib() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    let line = status
        .lines()
        .find(|l| l.starts_with("VmRSS:"))
        .expect("VmRSS");
    line.split_whitespace().nth(1).unwrap().parse().unwrap()
}

/// Runs `cycle` `n` times; prints RSS after the first thousand cycles, at tenths, and at the
/// end, and checks that it stayed flat.
fn soak(what: &str, n: usize, mut cycle: impl FnMut(usize)) {
    let started = Instant::now();
    let mut first = 0;
    let mut curve = Vec::new();
    for k in 0..n {
        cycle(k);
        if k + 1 == 1000 {
            first = rss_kib();
        }
        if (k + 1) % (n / 10) == 0 {
            curve.push(rss_kib());
        }
    }
    let last = rss_kib();
    let growth = last as f64 / first as f64 - 1.0;
    println!(
        "soak {what}: {n} cycles in {:.1} s; RSS after 1000 cycles {first} KiB, at the end {last} KiB ({:+.2} %); at each tenth: {curve:?} KiB",
        started.elapsed().as_secs_f64(),
        100.0 * growth
    );
    assert!(
        last <= first + first * 3 / 100 + 64,
        "{what}: RSS grew from {first} KiB to {last} KiB over {n} cycles"
    );
}

#[test]
fn memory_stays_flat_over_instances_and_fmu_states() {
    instantiate_and_free_100_000_times();
    get_set_free_fmu_state_1_000_000_times();
}

fn instantiate_and_free_100_000_times() {
    let (reals, integers) = s1_start(30.0, 0.0);
    soak("instantiate/initialise/step/free", 100_000, |k| {
        let slave = Slave::new(&format!("soak{k}"), false);
        slave.initialise(1e-6, &reals, &integers);
        ok(&slave, "fmi2DoStep", slave.step(0.0, 1e-4));
    });
}

fn get_set_free_fmu_state_1_000_000_times() {
    let slave = Slave::new("states", false);
    let (reals, integers) = s1_start(30.0, 0.0);
    slave.initialise(1e-6, &reals, &integers);
    ok(&slave, "fmi2DoStep", slave.step(0.0, 0.01));
    let c = slave.c;
    let expected = slave.get_real(&[vr::xi, vr::xi_dot]);
    soak("get/set/free FMU state", 1_000_000, |k| unsafe {
        let mut state = null_mut();
        ok(
            &slave,
            "fmi2GetFMUstate",
            ffi::fmi2GetFMUstate(c, &mut state),
        );
        ok(&slave, "fmi2SetFMUstate", ffi::fmi2SetFMUstate(c, state));
        if k % 100 == 0 {
            let mut size = 0;
            ok(
                &slave,
                "fmi2SerializedFMUstateSize",
                ffi::fmi2SerializedFMUstateSize(c, state, &mut size),
            );
            let mut bytes = vec![0u8; size];
            let p = bytes.as_mut_ptr() as *mut fmi2Byte;
            ok(
                &slave,
                "fmi2SerializeFMUstate",
                ffi::fmi2SerializeFMUstate(c, state, p, size),
            );
            let mut back = null_mut();
            ok(
                &slave,
                "fmi2DeSerializeFMUstate",
                ffi::fmi2DeSerializeFMUstate(c, p, size, &mut back),
            );
            ok(
                &slave,
                "fmi2FreeFMUstate",
                ffi::fmi2FreeFMUstate(c, &mut back),
            );
        }
        ok(
            &slave,
            "fmi2FreeFMUstate",
            ffi::fmi2FreeFMUstate(c, &mut state),
        );
    });
    assert_eq!(
        slave.get_real(&[vr::xi, vr::xi_dot]),
        expected,
        "the state after a million restores"
    );
}
