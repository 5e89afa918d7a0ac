//! The built shared library through the C API, loaded the way a compiled importer loads it
//! (the `fmi` crate): its export table, a run of scene S1, and the state machine refusing
//! illegal calls without harm. The FMU is packaged here from the cdylib cargo just built.

use fmi::fmi2::import::Fmi2Import;
use fmi::fmi2::instance::{CoSimulation, Common};
use gear_rattle::contract::vr;
use packaging::{Binary, models, write_fmu};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The cdylib under test: GEAR_RATTLE_CDYLIB (`make test` names the FMU's linux64 binary),
/// else target/release/libgear_rattle.so, found from this test executable's path
/// (target/<profile>/deps/…).
fn cdylib() -> PathBuf {
    let lib = std::env::var_os("GEAR_RATTLE_CDYLIB").map_or_else(
        || {
            let exe = std::env::current_exe().unwrap();
            exe.ancestors().nth(3).unwrap().join("release/libgear_rattle.so")
        },
        PathBuf::from,
    );
    assert!(
        lib.exists(),
        "{} is missing: build it first with `cargo rustc --release -p gear_rattle --lib --crate-type cdylib` (make test builds the FMU's linux64 binary)",
        lib.display()
    );
    lib
}

/// The FMU packaged once per test process: the tests of this file run in parallel threads,
/// and each rewriting one shared zip while another reads it gave "incomplete deflate stream".
fn fmu() -> &'static Path {
    static FMU: OnceLock<PathBuf> = OnceLock::new();
    FMU.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("gear_rattle_test_{}", std::process::id()));
        let fmu = dir.join("GearRattle.fmu");
        write_fmu(
            &fmu,
            &models::gear_rattle(),
            &[Binary {
                platform: "linux64",
                extension: "so",
                path: &cdylib(),
            }],
        )
        .unwrap();
        fmu
    })
}

/// Each call extracts the FMU into a directory of its own (the `fmi` crate's temp dir).
fn import() -> Fmi2Import {
    fmi::import::from_path(fmu()).unwrap()
}

/// The library exports exactly the functions of FMI 2.0 and FMI 3.0 (the lists the
/// portable and Windows checks read), nothing of its dependencies.
#[test]
fn exactly_the_fmi2_and_fmi3_functions_are_exported() {
    let out = std::process::Command::new("nm")
        .args(["-D", "--defined-only"])
        .arg(cdylib())
        .output()
        .expect("nm (binutils) runs");
    let text = String::from_utf8(out.stdout).unwrap();
    let mut symbols: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split_whitespace().nth(2))
        .collect();
    symbols.sort();
    let lists = [
        include_str!("fmi2_functions.txt"),
        include_str!("fmi3_functions.txt"),
    ];
    let mut expected: Vec<&str> = lists
        .iter()
        .flat_map(|l| l.lines())
        .filter(|l| !l.starts_with('#'))
        .collect();
    expected.sort();
    assert_eq!(symbols, expected);
}

#[test]
fn scene_s1_runs_through_the_c_api() {
    let import = import();
    let mut inst = import.instantiate_cs("s1", false, false).unwrap();
    inst.setup_experiment(Some(1e-6), 0.0, None).unwrap();
    inst.enter_initialization_mode().unwrap();
    inst.set_integer(&[vr::excitation], &[1]).unwrap();
    inst.exit_initialization_mode().unwrap();
    let h = 1e-3;
    let g = 25e-6;
    let (mut min_xi, mut max_xi) = (f64::MAX, f64::MIN);
    for k in 0..200 {
        inst.do_step(k as f64 * h, h, true).unwrap();
        let mut xi = [0.0];
        inst.get_real(&[vr::xi], &mut xi).unwrap();
        min_xi = min_xi.min(xi[0]);
        max_xi = max_xi.max(xi[0]);
    }
    let mut counts = [0, 0];
    inst.get_integer(&[vr::impacts_Fplus, vr::impacts_Fminus], &mut counts)
        .ok()
        .unwrap();
    // 0.2 s of S1: the first runs of docs/MODEL.md's pattern (4, then 5 per flank) on both flanks,
    // and ξ goes into both flanks by micrometres only.
    assert!(counts[0] >= 9 && counts[1] >= 5, "impacts {counts:?}");
    assert!(min_xi < 0.0 && min_xi > -0.5 * g, "min xi {min_xi:e}");
    assert!(max_xi > g && max_xi < 1.5 * g, "max xi {max_xi:e}");
}

#[test]
fn illegal_calls_are_refused_and_the_instance_stays_usable() {
    let import = import();
    let mut inst = import.instantiate_cs("misuse", false, false).unwrap();
    // DoStep before initialisation: refused.
    assert!(inst.do_step(0.0, 1e-3, true).is_err());
    inst.setup_experiment(None, 0.0, None).unwrap();
    inst.enter_initialization_mode().unwrap();
    // An invalid parameter is refused at exit, and can be corrected in place.
    inst.set_real(&[vr::G], &[0.0]).unwrap();
    assert!(inst.exit_initialization_mode().is_err());
    inst.set_real(&[vr::G], &[25e-6]).unwrap();
    inst.exit_initialization_mode().unwrap();
    // Unknown value reference, NaN input, negative step, output set: refused, no harm.
    let mut v = [0.0];
    assert!(inst.get_real(&[9999], &mut v).is_err());
    assert!(inst.set_real(&[vr::omega_M], &[f64::NAN]).is_err());
    assert!(inst.set_real(&[vr::xi], &[0.0]).is_err());
    assert!(inst.set_real(&[vr::I_L], &[1.0]).is_err());
    assert!(inst.do_step(0.0, -1e-3, true).is_err());
    inst.do_step(0.0, 1e-3, true).unwrap();
    inst.get_real(&[vr::xi], &mut v).unwrap();
    assert!(v[0].is_finite());
    // Reset returns to start values; a new run initialises again.
    inst.reset().unwrap();
    inst.setup_experiment(None, 0.0, None).unwrap();
    inst.enter_initialization_mode().unwrap();
    inst.exit_initialization_mode().unwrap();
    inst.get_real(&[vr::xi], &mut v).unwrap();
    assert_eq!(v[0], 0.5 * 25e-6);
}
