//! Work-precision benchmark: error against CPU time for the GearRattle integrator
//! called directly, the FMU through its C API, and maintained Rust ODE crates on the same
//! equations, measured side by side (interleaved repeats) in one run. On S1 the integrators
//! then run once more side by side, each at the tolerance where its error is within 1e-9 m
//! (suite `rust-equal-error` of the CSV): the targets' ratios measured, not interpolated.
//!
//!     cargo bench -p gear_rattle_bench --bench work_precision          (or `make bench`, which runs everything)
//!
//! Needs the reference of `scripts/bench_reference.py` (`make bench-reference`;
//! target/bench/reference/: the scenes, their predictable windows and an independent tight
//! solution on a 1 ms grid) and the FMU (`make fmu`). Writes target/bench/rust.csv and prints
//! a summary. Timed assertions are not made: the figures are printed and judged in
//! docs/BENCHMARKS.md.
//!
//! Environment: BENCH_QUICK=1 (one scene, three tolerances, one repeat: a smoke run),
//! BENCH_SCENES=S1-1s,S2-0.2s (a subset), BENCH_BUDGET=seconds of CPU per group of
//! interleaved configurations (default 1.5), BENCH_OUT=path of the CSV.
//! BENCH_DEBUG=gr|dopri5|dop853|tsit45 with BENCH_DEBUG_RTOL=r (and BENCH_DEBUG_SCENE, default
//! S1-0.2s): one run, printed against the reference point by point (t, ξ, Δξ, impacts).
//! BENCH_PROFILE=1 or calls: see `profile`.
#![allow(non_snake_case)]

#[path = "work_precision/peers.rs"]
mod peers;
#[path = "work_precision/profile.rs"]
mod profile;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use differential_equations::methods::ExplicitRungeKutta;
use fmi::fmi2::import::Fmi2Import;
use fmi::fmi2::instance::{CoSimulation, Common};
use fmi2_shell::values::Values;
use gear_rattle::contract::vr;
use gear_rattle::instance::{Carry, Simulation};
use gear_rattle::integrator::Solver;
use gear_rattle::physics::{Dynamics, Excitation, GearParams, Sine};
use gear_rattle::rattle::{N, Rattle, State, XI, XI_DOT};
use peers::{Model, Run, Stepper};

/// The tolerance sweep: every half decade from 1e-3 to 1e-10.
const TOLS: [f64; 15] = [
    1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 3e-10, 1e-10,
];
/// Whether the FMU runs at this tolerance too (the decades: the communication-step and FMI
/// targets are read there; the half-decades serve the interpolation at equal error).
fn fmu_tolerance(rtol: f64) -> bool {
    let decade = rtol.log10();
    (decade - decade.round()).abs() < 1e-9
}
/// Communication steps of the FMU runs.
const COMM_STEPS: [f64; 4] = [1e-2, 1e-3, 1e-4, 1e-5];
/// Spacing of the error grid (the reference is sampled there).
const GRID: f64 = 1e-3;
/// Error level at which solvers are compared, that of the targets: 1e-9 m = 4e-5 G on S1.
const TARGET_ERROR: f64 = 1e-9;
/// A tolerance counts as reaching [`TARGET_ERROR`] when the runs at it and at these factors
/// tighter do (see [`equal_error_configs`]): steps of 1.22 over most of the factor 3.2 to the
/// sweep's next tolerance, fine enough not to step over a dip of the error in rtol
/// (docs/DECISIONS.md, D18).
const PROBES: [f64; 5] = [1.0, 1.22, 1.5, 1.83, 2.25];
/// Scenes where the integrators also run side by side at equal error (each at the tolerance
/// that brings its error within [`TARGET_ERROR`]), with this budget of CPU seconds and at most
/// this many repeats: the ratios of the targets without an interpolation across groups run
/// minutes apart.
const EQUAL_ERROR_SCENES: [&str; 2] = ["S1-0.2s", "S1-1s"];
const EQUAL_ERROR_BUDGET: f64 = 4.0;
const EQUAL_ERROR_REPS: usize = 41;
/// The peers with GearRattle's RHS and event handling (an integrator comparison)...
const PEERS_SAME_RHS: [&str; 3] = [
    "differential-equations DOPRI5",
    "differential-equations DOP853",
    "diffsol Tsit45",
];
/// ...and as a user writes them: the RHS literally from docs/MODEL.md, no event handling.
const PEERS_USER_RHS: [&str; 3] = [
    "differential-equations DOPRI5 (user's RHS)",
    "differential-equations DOP853 (user's RHS)",
    "diffsol Tsit45 (user's RHS)",
];

// ---------------------------------------------------------------------------------------
// CPU time of this thread (the FMU runs in it too)
// ---------------------------------------------------------------------------------------

#[repr(C)]
struct Timespec {
    tv_sec: i64,
    tv_nsec: i64,
}

unsafe extern "C" {
    fn clock_gettime(clock: i32, tp: *mut Timespec) -> i32;
}

const CLOCK_THREAD_CPUTIME_ID: i32 = 3;

fn cpu_now() -> f64 {
    let mut ts = Timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes one timespec into the pointer it is given.
    unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

// ---------------------------------------------------------------------------------------
// Scenes and reference (from scripts/bench_reference.py)
// ---------------------------------------------------------------------------------------

#[derive(Clone, Debug)]
struct Scene {
    name: String,
    base: String,
    f_exc: f64,
    A_rms: f64,
    I_L: f64,
    C_LM: f64,
    t_end: f64,
    /// Error window [0, window]: where the scene is pointwise predictable.
    window: f64,
}

impl Scene {
    fn params(&self) -> GearParams {
        GearParams {
            I_L: self.I_L,
            C_LM: self.C_LM,
            ..GearParams::paper()
        }
    }
}

/// The independent tight solution on the 1 ms grid.
struct Reference {
    t: Vec<f64>,
    xi: Vec<f64>,
    xi_dot: Vec<f64>,
}

fn read_csv(path: &Path) -> Vec<std::collections::HashMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| {
        panic!(
            "{}: {e}; run `make bench-reference` first (or `make bench`)",
            path.display()
        )
    });
    let mut lines = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty());
    let header: Vec<String> = lines
        .next()
        .expect("header")
        .split(',')
        .map(str::to_string)
        .collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(str::to_string))
                .collect()
        })
        .collect()
}

fn num(row: &std::collections::HashMap<String, String>, key: &str) -> f64 {
    row[key]
        .parse()
        .unwrap_or_else(|_| panic!("{key} = {:?} is not a number", row[key]))
}

fn load_scenes(dir: &Path) -> Vec<Scene> {
    read_csv(&dir.join("scenes.csv"))
        .iter()
        .map(|r| Scene {
            name: r["scene"].clone(),
            base: r["base"].clone(),
            f_exc: num(r, "f_exc"),
            A_rms: num(r, "A_rms"),
            I_L: num(r, "I_L"),
            C_LM: num(r, "C_LM"),
            t_end: num(r, "t_end"),
            window: num(r, "window"),
        })
        .collect()
}

fn load_reference(dir: &Path, base: &str) -> Reference {
    let rows = read_csv(&dir.join(format!("{base}.csv")));
    Reference {
        t: rows.iter().map(|r| num(r, "t")).collect(),
        xi: rows.iter().map(|r| num(r, "xi")).collect(),
        xi_dot: rows.iter().map(|r| num(r, "xi_dot")).collect(),
    }
}

fn grid(t_end: f64) -> Vec<f64> {
    let n = (t_end / GRID).round() as usize;
    (0..=n).map(|k| (k as f64 * GRID).min(t_end)).collect()
}

fn y0(p: &GearParams) -> State {
    let mut y = [0.0; N];
    y[XI] = 0.5 * p.G;
    y
}

fn excitation(sc: &Scene) -> Excitation {
    Excitation::Sine(Sine::new(sc.A_rms, sc.f_exc, 0.0))
}

// ---------------------------------------------------------------------------------------
// The runs: each returns its samples and the CPU time of its timed part
// ---------------------------------------------------------------------------------------

/// Samples of a run on the error grid: sample j is at grid index j * stride.
struct Sampled {
    run: Run,
    stride: usize,
}

type Outcome = Result<(Sampled, f64), String>;

/// GearRattle's integrator called directly: `Solver::advance` to each 1 ms grid point, served
/// from the dense output of its natural steps (`interpolate_ends`, as the FMU does in sine
/// mode).
fn run_gearrattle(sc: &Scene, rtol: f64) -> Outcome {
    let g = grid(sc.t_end);
    let start = cpu_now();
    let p = sc.params();
    let mut rattle = Rattle::new(Dynamics::new(p), excitation(sc), 0.5 * p.G);
    let mut solver = Solver::new(rattle.tolerance(rtol));
    solver.interpolate_ends = true;
    let (mut t, mut y) = (0.0, y0(&p));
    let mut run = Run::with_capacity(g.len());
    for &tg in &g {
        if tg > t {
            solver
                .advance(&mut rattle, &mut t, &mut y, tg)
                .map_err(|e| e.to_string())?;
        }
        run.xi.push(y[XI]);
        run.xi_dot.push(y[XI_DOT]);
        run.counts.push(rattle.impacts.count);
    }
    let cpu = cpu_now() - start;
    run.rhs = solver.stats.rhs_evals;
    run.steps = solver.stats.accepted + solver.stats.rejected;
    run.edges = solver.stats.edges;
    Ok((Sampled { run, stride: 1 }, cpu))
}

fn run_peer<S: Stepper>(
    sc: &Scene,
    rtol: f64,
    model: &Model,
    stepper: &mut S,
    start: f64,
) -> Outcome {
    let p = sc.params();
    let run = peers::drive(stepper, model, y0(&p), &grid(sc.t_end), 0.1 * rtol * p.G)?;
    let cpu = cpu_now() - start;
    Ok((Sampled { run, stride: 1 }, cpu))
}

/// The model a peer integrates: GearRattle's RHS with its event handling (`user` false), or
/// the RHS as a user writes it from docs/MODEL.md without event handling (`user` true).
fn model(sc: &Scene, user: bool) -> Model {
    let p = sc.params();
    let mut m = Model::new(
        Dynamics::new(p),
        excitation(sc),
        gear_rattle::physics::ContactLaw::new(&p).classify(0.5 * p.G),
    );
    if user {
        m.user = Some(peers::UserRhs::new(p, sc.A_rms, sc.f_exc));
    }
    m
}

/// The tolerances a crate is given: the same weights as GearRattle's (ξ on the scale of G, ξ'
/// on G times the contact frequency), the quadratures of the energies left out.
fn atol(sc: &Scene, rtol: f64) -> [f64; N] {
    let p = sc.params();
    [
        rtol * p.G,
        rtol * p.G * p.contact_frequency(),
        1e30,
        1e30,
        1e30,
        1e30,
        1e30,
        1e30,
    ]
}

fn rtols(rtol: f64) -> [f64; N] {
    [rtol, rtol, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
}

/// The explicit Runge-Kutta pairs of differential-equations: DOPRI5 or DOP853.
#[derive(Clone, Copy)]
enum DeMethod {
    Dopri5,
    Dop853,
}

fn run_de(sc: &Scene, rtol: f64, which: DeMethod, user: bool) -> Outcome {
    let start = cpu_now();
    let model = model(sc, user);
    // The two pairs are different types: one builder expression, instantiated for each.
    macro_rules! run {
        ($pair:ident) => {{
            let method = ExplicitRungeKutta::$pair()
                .rtol(rtols(rtol))
                .atol(atol(sc, rtol))
                .max_steps(usize::MAX);
            let mut stepper = peers::de::De::new(method, sc.t_end);
            run_peer(sc, rtol, &model, &mut stepper, start)
        }};
    }
    match which {
        DeMethod::Dopri5 => run!(dopri5),
        DeMethod::Dop853 => run!(dop853),
    }
}

fn run_tsit45(sc: &Scene, rtol: f64, user: bool) -> Outcome {
    use diffsol::{NalgebraMat, OdeBuilder};
    let start = cpu_now();
    let model = model(sc, user);
    let p = sc.params();
    let y_start = y0(&p);
    let problem = OdeBuilder::<NalgebraMat<f64>>::new()
        .rtol(rtol)
        .atol(atol(sc, rtol))
        .rhs(|x: &[f64], _p: &[f64], t: f64, dy: &mut [f64]| {
            let y: &State = x.try_into().expect("5 states");
            dy.copy_from_slice(&model.rhs(t, y));
        })
        .init(
            move |_p: &[f64], _t: f64, y: &mut [f64]| y.copy_from_slice(&y_start),
            N,
        )
        .build()
        .map_err(|e| format!("{e:?}"))?;
    let solver = problem.tsit45().map_err(|e| format!("{e:?}"))?;
    let mut stepper = peers::ds::Ds::new(solver);
    // The evaluations of the solver's construction (f(y0) and its starting step) count too.
    let before = model.evals.get();
    let mut out = run_peer(sc, rtol, &model, &mut stepper, start)?;
    out.0.run.rhs += before;
    Ok(out)
}

/// Which samples of a communication-step loop fall on the error grid.
fn sampling(comm: f64) -> (usize, usize) {
    if comm >= GRID {
        (1, (comm / GRID).round() as usize) // every step, grid stride
    } else {
        ((GRID / comm).round() as usize, 1) // every k-th step, each grid point
    }
}

fn fmu_values(sc: &Scene) -> Values {
    let mut v = Values::start(gear_rattle::contract::VARIABLES);
    v.set_integer(vr::excitation, 1);
    v.set_real(vr::A_rms, sc.A_rms);
    v.set_real(vr::f_exc, sc.f_exc);
    v.set_real(vr::I_L, sc.I_L);
    v.set_real(vr::C_LM, sc.C_LM);
    v
}

/// The FMU's simulation without FMI: `Simulation::step_to` at each communication point, the
/// outputs read after each step as a master does. The FMI overhead is measured against this.
fn run_steps(sc: &Scene, rtol: f64, comm: f64) -> Outcome {
    let n = (sc.t_end / comm).round() as usize;
    let (every, stride) = sampling(comm);
    let start = cpu_now();
    let mut sim =
        Simulation::new(&fmu_values(sc), 0.0, 0.0, rtol, Carry::Asked).map_err(|e| e.message)?;
    let mut run = Run::with_capacity(n / every + 1);
    let record = |run: &mut Run, sim: &Simulation| {
        run.xi.push(sim.real_output(vr::xi).unwrap());
        run.xi_dot.push(sim.real_output(vr::xi_dot).unwrap());
        run.counts.push([
            sim.integer_output(vr::impacts_Fplus).unwrap() as u64,
            sim.integer_output(vr::impacts_Fminus).unwrap() as u64,
        ]);
    };
    record(&mut run, &sim);
    let mut sink = 0.0;
    for k in 1..=n {
        sim.step_to(k as f64 * comm).map_err(|e| e.to_string())?;
        sink += sim.real_output(vr::xi).unwrap() + sim.real_output(vr::xi_dot).unwrap();
        if k % every == 0 {
            record(&mut run, &sim);
        }
    }
    let cpu = cpu_now() - start;
    std::hint::black_box(sink);
    let stats = sim.stats();
    run.rhs = stats.rhs_evals;
    run.steps = stats.accepted + stats.rejected;
    run.edges = stats.edges;
    Ok((Sampled { run, stride }, cpu))
}

/// Initialises an instance of the FMU for scene `sc` at `rtol` (bench sine, the scene's
/// parameters set in initialisation mode), ready for fmi2DoStep from t = 0.
fn init_fmu(
    inst: &mut fmi::fmi2::instance::InstanceCS,
    sc: &Scene,
    rtol: f64,
) -> Result<(), fmi::fmi2::Fmi2Error> {
    inst.setup_experiment(Some(rtol), 0.0, None)?;
    inst.enter_initialization_mode()?;
    inst.set_integer(&[vr::excitation], &[1])?;
    inst.set_real(
        &[vr::A_rms, vr::f_exc, vr::I_L, vr::C_LM],
        &[sc.A_rms, sc.f_exc, sc.I_L, sc.C_LM],
    )?;
    inst.exit_initialization_mode()?;
    Ok(())
}

/// The packaged FMU through its C API (the `fmi` crate loads the shared library): parameters
/// set in initialisation mode, fmi2DoStep at each communication point, xi and xi_dot read
/// after every step. Timed from fmi2SetupExperiment to fmi2Terminate.
fn run_fmu(import: &Fmi2Import, sc: &Scene, rtol: f64, comm: f64) -> Outcome {
    let n = (sc.t_end / comm).round() as usize;
    let (every, stride) = sampling(comm);
    let fmi = |e: fmi::fmi2::Fmi2Error| format!("FMI: {e:?}");
    let mut inst = import
        .instantiate_cs("bench", false, false)
        .map_err(|e| format!("instantiate: {e:?}"))?;
    let start = cpu_now();
    init_fmu(&mut inst, sc, rtol).map_err(fmi)?;
    let mut run = Run::with_capacity(n / every + 1);
    let outs = [vr::xi, vr::xi_dot];
    let counters = [vr::impacts_Fplus, vr::impacts_Fminus];
    let mut x = [0.0; 2];
    let mut c = [0i32; 2];
    let record = |run: &mut Run, x: &[f64; 2], c: &[i32; 2]| {
        run.xi.push(x[0]);
        run.xi_dot.push(x[1]);
        run.counts.push([c[0] as u64, c[1] as u64]);
    };
    inst.get_real(&outs, &mut x).map_err(fmi)?;
    inst.get_integer(&counters, &mut c).map_err(fmi)?;
    record(&mut run, &x, &c);
    for k in 1..=n {
        inst.do_step((k - 1) as f64 * comm, comm, true)
            .map_err(fmi)?;
        inst.get_real(&outs, &mut x).map_err(fmi)?;
        if k % every == 0 {
            inst.get_integer(&counters, &mut c).map_err(fmi)?;
            record(&mut run, &x, &c);
        }
    }
    inst.terminate().map_err(fmi)?;
    let cpu = cpu_now() - start;
    Ok((Sampled { run, stride }, cpu))
}

// ---------------------------------------------------------------------------------------
// Measurement: configurations of one group run round-robin, so that the load of the machine
// (two cores, other builds) falls on all of them alike
// ---------------------------------------------------------------------------------------

struct Config<'a> {
    solver: &'static str,
    comm: Option<f64>,
    rtol: f64,
    runner: Box<dyn FnMut() -> Outcome + 'a>,
}

/// The integrators at `rtol`: GearRattle, then each crate with GearRattle's RHS and event
/// handling, then each crate as a user writes it from docs/MODEL.md.
fn integrators(sc: &Scene, rtol: f64) -> Vec<Config<'_>> {
    let mut configs = vec![Config {
        solver: "GearRattle (direct)",
        comm: None,
        rtol,
        runner: Box::new(move || run_gearrattle(sc, rtol)),
    }];
    for (user, names) in [(false, PEERS_SAME_RHS), (true, PEERS_USER_RHS)] {
        let [dopri5, dop853, tsit45] = names;
        configs.push(Config {
            solver: dopri5,
            comm: None,
            rtol,
            runner: Box::new(move || run_de(sc, rtol, DeMethod::Dopri5, user)),
        });
        configs.push(Config {
            solver: dop853,
            comm: None,
            rtol,
            runner: Box::new(move || run_de(sc, rtol, DeMethod::Dop853, user)),
        });
        configs.push(Config {
            solver: tsit45,
            comm: None,
            rtol,
            runner: Box::new(move || run_tsit45(sc, rtol, user)),
        });
    }
    configs
}

struct Measured {
    solver: &'static str,
    comm: Option<f64>,
    rtol: f64,
    first: Result<Sampled, String>,
    cpu: Vec<f64>,
}

fn measure(configs: Vec<Config>, budget: f64, max_reps: usize) -> Vec<Measured> {
    let mut configs = configs;
    let mut out: Vec<Measured> = configs
        .iter_mut()
        .map(|c| {
            let (first, cpu) = match (c.runner)() {
                Ok((s, cpu)) => (Ok(s), vec![cpu]),
                Err(e) => (Err(e), vec![]),
            };
            Measured {
                solver: c.solver,
                comm: c.comm,
                rtol: c.rtol,
                first,
                cpu,
            }
        })
        .collect();
    let round: f64 = out
        .iter()
        .map(|m| m.cpu.first().copied().unwrap_or(0.0))
        .sum();
    let reps = if max_reps <= 1 {
        1
    } else {
        ((budget / round.max(1e-9)).ceil() as usize).clamp(3, max_reps)
    };
    for _ in 1..reps {
        for (c, m) in configs.iter_mut().zip(out.iter_mut()) {
            if m.first.is_ok()
                && let Ok((_, cpu)) = (c.runner)()
            {
                m.cpu.push(cpu);
            }
        }
    }
    out
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.total_cmp(b));
    let n = s.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

// ---------------------------------------------------------------------------------------
// Errors and the CSV
// ---------------------------------------------------------------------------------------

struct Errors {
    max_xi: f64,
    rms_xi_dot: f64,
    points: usize,
}

fn errors(s: &Sampled, r: &Reference, window: f64) -> Errors {
    let (mut max_xi, mut sum, mut points) = (0.0f64, 0.0, 0);
    for j in 0..s.run.xi.len() {
        let g = j * s.stride;
        if g >= r.t.len() || r.t[g] > window + 1e-9 {
            break;
        }
        let dx = (s.run.xi[j] - r.xi[g]).abs();
        let dv = s.run.xi_dot[j] - r.xi_dot[g];
        max_xi = max_xi.max(if dx.is_nan() { f64::INFINITY } else { dx });
        sum += dv * dv;
        points += 1;
    }
    Errors {
        max_xi,
        rms_xi_dot: (sum / points.max(1) as f64).sqrt(),
        points,
    }
}

const HEADER: &str = "suite,solver,scene,t_end,window,rtol,comm_step,err_max_xi,err_rms_xi_dot,points,\
cpu_median,cpu_min,cpu_max,repeats,rhs_evals,steps,edges,impacts_plus,impacts_minus,\
rate_plus,rate_minus,status";

fn csv_row(suite: &str, sc: &Scene, r: &Reference, m: &Measured) -> String {
    let comm = m.comm.map_or(String::new(), |c| format!("{c:e}"));
    let mut line = format!(
        "{suite},{},{},{},{},{:e},{}",
        m.solver, sc.name, sc.t_end, sc.window, m.rtol, comm
    );
    match &m.first {
        Ok(s) => {
            let e = errors(s, r, sc.window);
            let last = *s.run.counts.last().unwrap_or(&[0, 0]);
            // Impact rates per flank over [0.2 s, t_end] (docs/MODEL.md §5), for runs past 0.5 s.
            let (rp, rm) = if sc.t_end >= 0.5 {
                let j = (0.2 / GRID).round() as usize / s.stride;
                let c = s.run.counts[j];
                let span = sc.t_end - 0.2;
                (
                    format!("{:.2}", (last[0] - c[0]) as f64 / span),
                    format!("{:.2}", (last[1] - c[1]) as f64 / span),
                )
            } else {
                (String::new(), String::new())
            };
            let cpu_min = m.cpu.iter().cloned().fold(f64::INFINITY, f64::min);
            let cpu_max = m.cpu.iter().cloned().fold(0.0, f64::max);
            // The FMU's work is not visible through FMI: blank (Simulation::step_to's rows
            // give it for the same steps).
            let work = if s.run.rhs == 0 {
                ",,".to_string()
            } else {
                format!("{},{},{}", s.run.rhs, s.run.steps, s.run.edges)
            };
            let _ = write!(
                line,
                ",{:.4e},{:.4e},{},{:.6e},{:.6e},{:.6e},{},{},{},{},{},{},ok",
                e.max_xi,
                e.rms_xi_dot,
                e.points,
                median(&m.cpu),
                cpu_min,
                cpu_max,
                m.cpu.len(),
                work,
                last[0],
                last[1],
                rp,
                rm
            );
        }
        Err(msg) => {
            let _ = write!(
                line,
                ",,,,,,,,,,,,,,,failed: {}",
                msg.replace([',', '\n'], ";")
            );
        }
    }
    line
}

// ---------------------------------------------------------------------------------------
// Equal-error comparison (the targets are set at 1e-9 m on S1)
// ---------------------------------------------------------------------------------------

/// The value (CPU time, or tolerance) at error `target`, interpolated log-log between the two
/// tolerances of the sweep (loosest first) that bracket it; None if the solver never reaches
/// it. The bool says "interpolated" (false: already below at the loosest tolerance, the
/// value there is a bound).
fn at_error(points: &[(f64, f64)], target: f64) -> Option<(f64, bool)> {
    let i = points.iter().position(|&(e, _)| e <= target)?;
    if i == 0 {
        return Some((points[0].1, false));
    }
    let (e0, c0) = points[i - 1];
    let (e1, c1) = points[i];
    let w = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
    Some(((c0.ln() + w * (c1.ln() - c0.ln())).exp(), true))
}

/// Each integrator at the loosest tolerance found where its error on `sc` is at most
/// [`TARGET_ERROR`] there and at the tolerances [`PROBES`] times tighter, for a group run side
/// by side. Errors are not monotone in the tolerance, and a tolerance that falls in a dip of
/// the error is one a user could not choose without the reference in hand (docs/DECISIONS.md,
/// D18). The loosest tolerance
/// of the sweep that passes this test, then bisection (in log rtol, 6 steps) towards the
/// sweep's next looser tolerance, so that every solver ends within 2 % in rtol of its own
/// threshold. Solvers that never reach it are left out; one within it at the loosest
/// tolerance runs there.
fn equal_error_configs<'a>(sc: &'a Scene, r: &Reference, sweep: &[Measured]) -> Vec<Config<'a>> {
    let solvers: Vec<&'static str> = integrators(sc, 1.0).iter().map(|c| c.solver).collect();
    let error_at = |solver: &str, rtol: f64| -> Option<f64> {
        let mut config = integrators(sc, rtol)
            .into_iter()
            .find(|c| c.solver == solver)?;
        let (s, _) = (config.runner)().ok()?;
        Some(errors(&s, r, sc.window).max_xi)
    };
    let within = |solver: &str, rtol: f64| {
        PROBES
            .iter()
            .all(|p| error_at(solver, rtol / p).is_some_and(|e| e <= TARGET_ERROR))
    };
    solvers
        .into_iter()
        .filter_map(|solver| {
            let rtols: Vec<f64> = sweep
                .iter()
                .filter(|m| m.solver == solver)
                .filter_map(|m| {
                    let s = m.first.as_ref().ok()?;
                    (errors(s, r, sc.window).max_xi <= TARGET_ERROR).then_some(m.rtol)
                })
                .collect();
            let i = rtols.iter().position(|&rtol| within(solver, rtol))?;
            let mut inside = rtols[i];
            let looser = TOLS.iter().rev().find(|&&rtol| rtol > inside);
            if let Some(&looser) = looser {
                let mut beyond = looser;
                for _ in 0..6 {
                    let mid = (inside * beyond).sqrt();
                    if within(solver, mid) {
                        inside = mid;
                    } else {
                        beyond = mid;
                    }
                }
            }
            integrators(sc, inside)
                .into_iter()
                .find(|c| c.solver == solver)
        })
        .collect()
}

/// Prints the side-by-side group's ratios: the fastest crate of each kind over GearRattle.
fn side_by_side(sc: &Scene, measured: &[Measured]) {
    let cpu = |name: &str| {
        measured
            .iter()
            .find(|m| m.solver == name && m.first.is_ok())
            .map(|m| median(&m.cpu))
    };
    let Some(gr) = cpu("GearRattle (direct)") else {
        return;
    };
    for (kind, names) in [
        ("GearRattle's RHS and edge handling", PEERS_SAME_RHS),
        ("user's RHS from docs/MODEL.md", PEERS_USER_RHS),
    ] {
        let best = names
            .iter()
            .filter_map(|n| cpu(n))
            .fold(f64::INFINITY, f64::min);
        println!(
            "{}: side by side at max |dxi| <= {TARGET_ERROR:e} m, fastest crate ({kind}) / GearRattle: {:.2}x (target >= 3)",
            sc.name,
            best / gr
        );
    }
}

fn main() {
    // The repository root: this crate lives in benches/.
    let root = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    let ref_dir = root.join("target/bench/reference");
    if let Ok(which) = std::env::var("BENCH_DEBUG") {
        let scenes = load_scenes(&ref_dir);
        let name = std::env::var("BENCH_DEBUG_SCENE").unwrap_or_else(|_| "S1-0.2s".into());
        let sc = scenes
            .iter()
            .find(|s| s.name == name)
            .expect("a scene of the reference");
        let r = load_reference(&ref_dir, &sc.base);
        let rtol: f64 = std::env::var("BENCH_DEBUG_RTOL").unwrap().parse().unwrap();
        let out = match which.as_str() {
            "dop853" => run_de(sc, rtol, DeMethod::Dop853, false),
            "dopri5" => run_de(sc, rtol, DeMethod::Dopri5, false),
            "tsit45" => run_tsit45(sc, rtol, false),
            _ => run_gearrattle(sc, rtol),
        }
        .unwrap();
        for (j, x) in out.0.run.xi.iter().enumerate() {
            println!(
                "{} {:e} {:e} {:?}",
                r.t[j],
                x,
                x - r.xi[j],
                out.0.run.counts[j]
            );
        }
        return;
    }
    if std::env::var("BENCH_PROFILE").is_ok_and(|v| v == "1") {
        profile::run(&load_scenes(&ref_dir));
        return;
    }
    let fmu_path = std::env::var("BENCH_FMU")
        .map(PathBuf::from)
        .unwrap_or_else(|_| root.join("target/fmu/GearRattle.fmu"));
    if std::env::var("BENCH_PROFILE").is_ok_and(|v| v == "calls") {
        let import: Fmi2Import = fmi::import::from_path(&fmu_path).expect("the FMU (make fmu)");
        profile::calls(&load_scenes(&ref_dir), &import);
        return;
    }
    let out_path = std::env::var("BENCH_OUT")
        .map(PathBuf::from)
        .unwrap_or_else(|_| root.join("target/bench/rust.csv"));
    let quick = std::env::var("BENCH_QUICK").is_ok_and(|v| v == "1");
    let budget: f64 = std::env::var("BENCH_BUDGET")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1.5);
    let max_reps = if quick { 1 } else { 9 };
    let wanted: Option<Vec<String>> = std::env::var("BENCH_SCENES")
        .ok()
        .map(|v| v.split(',').map(str::to_string).collect());

    let mut scenes = load_scenes(&ref_dir);
    if quick {
        scenes.retain(|s| s.name == "S1-0.2s");
    }
    if let Some(w) = &wanted {
        scenes.retain(|s| w.contains(&s.name));
    }
    let tols: Vec<f64> = if quick {
        vec![1e-4, 1e-6, 1e-8]
    } else {
        TOLS.to_vec()
    };
    let import: Fmi2Import = fmi::import::from_path(&fmu_path)
        .unwrap_or_else(|e| panic!("{}: {e:?}; build it with `make fmu`", fmu_path.display()));
    let import = &import;

    eprintln!(
        "work-precision: {} scene(s), tolerances {:?}, budget {budget} s CPU per group",
        scenes.len(),
        tols
    );
    let mut lines = vec![HEADER.to_string()];
    let mut s1: Vec<Measured> = Vec::new();
    let wall = std::time::Instant::now();
    for sc in &scenes {
        let reference = load_reference(&ref_dir, &sc.base);
        let mut sweep = Vec::new();
        for &rtol in &tols {
            // The integrators, side by side: GearRattle, then each crate with GearRattle's RHS
            // and event handling, then each crate as a user writes it from docs/MODEL.md.
            let configs = integrators(sc, rtol);
            let measured = measure(configs, budget, max_reps);
            report("rust", sc, &reference, &measured, &mut lines);
            sweep.extend(measured);
            if !fmu_tolerance(rtol) {
                continue;
            }
            // The FMU through its C API and the same simulation without FMI, per
            // communication step.
            let mut configs = Vec::new();
            for &comm in &COMM_STEPS {
                configs.push(Config {
                    solver: "GearRattle FMU (C API)",
                    comm: Some(comm),
                    rtol,
                    runner: Box::new(move || run_fmu(import, sc, rtol, comm)),
                });
                configs.push(Config {
                    solver: "GearRattle Simulation::step_to (no FMI)",
                    comm: Some(comm),
                    rtol,
                    runner: Box::new(move || run_steps(sc, rtol, comm)),
                });
            }
            let measured_fmu = measure(configs, budget, max_reps);
            report("rust", sc, &reference, &measured_fmu, &mut lines);
            if sc.name == "S1-1s" {
                s1.extend(measured_fmu);
            }
        }
        if !quick && EQUAL_ERROR_SCENES.contains(&sc.name.as_str()) {
            let configs = equal_error_configs(sc, &reference, &sweep);
            let measured = measure(configs, EQUAL_ERROR_BUDGET, EQUAL_ERROR_REPS);
            report("rust-equal-error", sc, &reference, &measured, &mut lines);
            side_by_side(sc, &measured);
        }
        if sc.name == "S1-1s" {
            s1.extend(sweep);
        }
    }
    if let Some(dir) = out_path.parent() {
        std::fs::create_dir_all(dir).expect("output directory");
    }
    std::fs::write(&out_path, lines.join("\n") + "\n").expect("write the CSV");
    eprintln!(
        "wrote {} ({} rows) in {:.0} s",
        out_path.display(),
        lines.len() - 1,
        wall.elapsed().as_secs_f64()
    );
    summary(&scenes, &ref_dir, &s1);
}

fn report(suite: &str, sc: &Scene, r: &Reference, measured: &[Measured], lines: &mut Vec<String>) {
    for m in measured {
        lines.push(csv_row(suite, sc, r, m));
        let comm = m.comm.map_or(String::new(), |c| format!(" @{c:e} s"));
        match &m.first {
            Ok(s) => {
                let e = errors(s, r, sc.window);
                eprintln!(
                    "{:8} rtol {:.0e} {:42} err {:9.3e} m  cpu {:9.3e} s (x{})  rhs {}",
                    sc.name,
                    m.rtol,
                    format!("{}{comm}", m.solver),
                    e.max_xi,
                    median(&m.cpu),
                    m.cpu.len(),
                    s.run.rhs
                );
            }
            Err(e) => eprintln!(
                "{:8} rtol {:.0e} {}{comm}: FAILED {e}",
                sc.name, m.rtol, m.solver
            ),
        }
    }
}

/// Prints the equal-error ratios on S1 (1 s) and the communication-step figures.
fn summary(scenes: &[Scene], ref_dir: &Path, s1: &[Measured]) {
    let Some(sc) = scenes.iter().find(|s| s.name == "S1-1s") else {
        return;
    };
    let r = load_reference(ref_dir, &sc.base);
    let curve = |solver: &str, comm: Option<f64>| -> Vec<(f64, f64)> {
        s1.iter()
            .filter(|m| m.solver == solver && m.comm == comm)
            .filter_map(|m| {
                m.first
                    .as_ref()
                    .ok()
                    .map(|s| (errors(s, &r, sc.window).max_xi, median(&m.cpu)))
            })
            .collect()
    };
    println!("\nS1 (1 s): CPU time at max |dxi| = {TARGET_ERROR:e} m (log-log interpolation):");
    let gr = at_error(&curve("GearRattle (direct)", None), TARGET_ERROR);
    let show = |n: &str, c: Option<(f64, bool)>| match c {
        Some((c, exact)) => println!(
            "  {n:44} {c:.3e} s{}",
            if exact { "" } else { " (upper bound)" }
        ),
        None => println!("  {n:44} does not reach it"),
    };
    show("GearRattle (direct)", gr);
    for (kind, names) in [
        ("GearRattle's RHS and edge handling", PEERS_SAME_RHS),
        (
            "user's RHS from docs/MODEL.md, no edge handling",
            PEERS_USER_RHS,
        ),
    ] {
        let costs: Vec<Option<(f64, bool)>> = names
            .iter()
            .map(|n| at_error(&curve(n, None), TARGET_ERROR))
            .collect();
        for (n, c) in names.iter().zip(&costs) {
            show(n, *c);
        }
        if let Some((gr, _)) = gr {
            let best = costs
                .iter()
                .flatten()
                .map(|c| c.0)
                .fold(f64::INFINITY, f64::min);
            println!(
                "  fastest Rust crate ({kind}) / GearRattle: {:.2}x (target >= 3)",
                best / gr
            );
        }
    }
    for &rtol in &[1e-6, 1e-8] {
        let at = |solver: &str, comm: f64| {
            s1.iter()
                .find(|m| m.solver == solver && m.comm == Some(comm) && m.rtol == rtol)
                .map(|m| median(&m.cpu))
                .unwrap_or(f64::NAN)
        };
        let fmu = |c| at("GearRattle FMU (C API)", c);
        let steps = |c| at("GearRattle Simulation::step_to (no FMI)", c);
        println!(
            "  rtol {rtol:e}: FMU cost 10 us / 10 ms = {:.2} (target <= 1.5); FMI overhead at 0.1 ms = {:+.0} % (target <= 20 %)",
            fmu(1e-5) / fmu(1e-2),
            100.0 * (fmu(1e-4) / steps(1e-4) - 1.0)
        );
    }
}
