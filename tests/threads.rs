//! Many instances per process (the model description's canBeInstantiatedOnlyOncePerProcess
//! = false): eight instances, each its own scene, stepped at once on eight threads through the
//! C API, each giving the same bits at every communication point and the same log lines as
//! that scene run alone, and every log line reaching its own instance's componentEnvironment.

mod capi;

use capi::{Line, Slave, s1_start};
use std::sync::{Arc, Barrier};

const INSTANCES: usize = 8;
const H: f64 = 1e-4;
const STEPS: usize = 1000;

/// What one run gives: every output's bits after every step, and the log.
struct Trace {
    outputs: Vec<Vec<u64>>,
    lines: Vec<Line>,
}

/// Runs scene k on a fresh instance named `name`, with every log category on: S1 in sine mode
/// with its own excitation frequency and start in the backlash, so that instances mixing
/// their states would show. `ready` holds the first step until all threads are there.
fn run(k: usize, name: &str, ready: Option<&Barrier>) -> Trace {
    let slave = Slave::new(name, true);
    let (reals, integers) = s1_start(30.0 + 5.0 * k as f64, 0.04 * k as f64);
    slave.initialise(1e-6, &reals, &integers);
    if let Some(b) = ready {
        b.wait();
    }
    let outputs = (0..STEPS)
        .map(|i| {
            capi::ok(&slave, "fmi2DoStep", slave.step(i as f64 * H, H));
            slave.output_bits()
        })
        .collect();
    Trace {
        outputs,
        lines: slave.lines(),
    }
}

#[test]
fn eight_instances_on_eight_threads_match_each_run_alone() {
    let alone: Vec<Trace> = (0..INSTANCES)
        .map(|k| run(k, &format!("scene{k}"), None))
        .collect();
    let barrier = Arc::new(Barrier::new(INSTANCES));
    let threads: Vec<_> = (0..INSTANCES)
        .map(|k| {
            let barrier = Arc::clone(&barrier);
            std::thread::spawn(move || run(k, &format!("scene{k}"), Some(&barrier)))
        })
        .collect();
    let together: Vec<Trace> = threads.into_iter().map(|t| t.join().unwrap()).collect();

    for (k, (a, t)) in alone.iter().zip(&together).enumerate() {
        let first = a.outputs.iter().zip(&t.outputs).position(|(x, y)| x != y);
        assert_eq!(
            first, None,
            "scene {k}: outputs differ from step {first:?} on"
        );
        assert!(
            !t.lines.is_empty(),
            "scene {k}: no log line with every category on"
        );
        let name = format!("scene{k}");
        let foreign: Vec<_> = t.lines.iter().filter(|l| l.instance != name).collect();
        assert!(
            foreign.is_empty(),
            "scene {k}'s environment got lines of other instances: {:?}",
            &foreign[..1]
        );
        assert_eq!(
            a.lines, t.lines,
            "scene {k}: log lines differ from the run alone"
        );
    }
    // The scenes do differ, so a mix-up between instances could not go unseen.
    for k in 1..INSTANCES {
        assert_ne!(
            alone[0].outputs.last(),
            alone[k].outputs.last(),
            "scenes 0 and {k} end alike"
        );
    }
}
