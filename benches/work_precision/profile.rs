//! `BENCH_PROFILE=1 cargo bench --bench work_precision`: GearRattle's integrator alone on
//! S1 (1 s) at one tolerance (BENCH_PROFILE_RTOL, default 1e-9), repeated for
//! BENCH_PROFILE_SECONDS (default 4) of CPU so that `perf record` can sample it, followed by a
//! breakdown of its work: right-hand sides per region (counted through a wrapper of `Rattle`,
//! the solver being generic over the system), the measured cost of one right-hand side in each
//! region, hence the share of the time spent in right-hand sides, and the evaluations spent on
//! edges and rejected steps: what bounds the gain of each lever (docs/BENCHMARKS.md).

use super::*;
use gear_rattle::integrator::taylor::Coefficients;
use gear_rattle::integrator::{ClosedForm, Crossing, Jacobian, Piecewise, System};
use gear_rattle::physics::Region;
use std::cell::Cell;

const REGIONS: [(Region, &str); 5] = [
    (Region::ContactPlus, "contact F+ (xi < -eps)"),
    (Region::BandPlus, "band F+ (-eps..0)"),
    (Region::Gap, "gap (0..G, free flight)"),
    (Region::BandMinus, "band F- (G..G+eps)"),
    (Region::ContactMinus, "contact F- (xi > G+eps)"),
];

fn index(r: Region) -> usize {
    REGIONS.iter().position(|(x, _)| *x == r).expect("a region")
}

/// `Rattle` with its right-hand sides counted per region, and the edges crossed out of a band
/// (reached by a DOPRI5 step, redone to end on the edge; those out of a contact or the gap are
/// reached at a Taylor step's polynomial or on the exact flight, with no redone step).
struct Counted {
    inner: Rattle,
    evals: Cell<[u64; 5]>,
    out_of_bands: u64,
}

impl Counted {
    fn new(inner: Rattle) -> Self {
        Counted {
            inner,
            evals: Cell::new([0; 5]),
            out_of_bands: 0,
        }
    }
}

impl System<N> for Counted {
    #[inline]
    fn rhs(&self, t: f64, y: &State) -> State {
        let mut e = self.evals.get();
        e[index(self.inner.region)] += 1;
        self.evals.set(e);
        self.inner.rhs(t, y)
    }
}

impl Jacobian<N> for Counted {
    fn jacobian(&self, t: f64, y: &State) -> [[f64; N]; N] {
        self.inner.jacobian(t, y)
    }
}

impl Piecewise<N> for Counted {
    fn guard(k: usize) -> (usize, usize) {
        Rattle::guard(k)
    }
    fn piece(&self, k: usize) -> (f64, f64) {
        self.inner.piece(k)
    }
    fn cross(&mut self, edge: Crossing, t: f64, y: &State) {
        if matches!(self.inner.region, Region::BandPlus | Region::BandMinus) {
            self.out_of_bands += 1;
        }
        self.inner.cross(edge, t, y)
    }
    fn exact(&mut self, t0: f64, y0: &State) -> Option<impl ClosedForm<N>> {
        self.inner.exact(t0, y0)
    }
    fn series(&self, t: f64, y: &State, c: &mut Coefficients<N>) -> bool {
        self.inner.series(t, y, c)
    }
}

/// CPU nanoseconds per call of `rhs` at ξ = xi, ξ' = 0.05 m/s (300 000 calls at moving times).
fn ns_per_rhs(rhs: impl Fn(f64, &State) -> State, xi: f64) -> f64 {
    let n = 300_000;
    let mut acc = 0.0;
    let t0 = cpu_now();
    for k in 0..n {
        let mut yy = [0.0; N];
        (yy[0], yy[1]) = (xi, 0.05);
        acc += std::hint::black_box(&rhs)(k as f64 * 1e-7, std::hint::black_box(&yy))[1];
    }
    std::hint::black_box(acc);
    (cpu_now() - t0) / n as f64 * 1e9
}

/// S1 (1 s), BENCH_PROFILE_RTOL (default `rtol`) and BENCH_PROFILE_SECONDS (default 4).
fn setup(scenes: &[Scene], rtol: f64) -> (&Scene, f64, f64) {
    let sc = scenes
        .iter()
        .find(|s| s.name == "S1-1s")
        .expect("scene S1-1s in the reference");
    let env = |k: &str, d: f64| {
        std::env::var(k)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(d)
    };
    (
        sc,
        env("BENCH_PROFILE_RTOL", rtol),
        env("BENCH_PROFILE_SECONDS", 4.0),
    )
}

pub fn run(scenes: &[Scene]) {
    let (sc, rtol, seconds) = setup(scenes, 1e-9);

    // 1. The plain run, repeated (what perf samples).
    let start = cpu_now();
    let mut runs = 0;
    let mut last = None;
    while cpu_now() - start < seconds || runs == 0 {
        last = Some(run_gearrattle(sc, rtol).expect("GearRattle run"));
        runs += 1;
    }
    let per_run = (cpu_now() - start) / runs as f64;
    let (sampled, _) = last.expect("one run");
    let run = &sampled.run;

    // 2. The same run with its right-hand sides counted per region.
    let p = sc.params();
    let mut sys = Counted::new(Rattle::new(Dynamics::new(p), excitation(sc), 0.5 * p.G));
    let mut solver = Solver::new(sys.inner.tolerance(rtol));
    let (mut t, mut y) = (0.0, y0(&p));
    for tg in grid(sc.t_end) {
        if tg > t {
            solver.advance(&mut sys, &mut t, &mut y, tg).expect("run");
        }
    }
    let evals = sys.evals.get();
    let counted: u64 = evals.iter().sum();

    // 3. The cost of one right-hand side in each region (states inside each region, the time
    //    varied so that nothing is hoisted).
    let eps = p.epsilon;
    let states = [-3e-6, -0.5 * eps, 0.5 * p.G, p.G + 0.5 * eps, p.G + 3e-6];
    let mut ns = [0.0; 5];
    for (i, (region, _)) in REGIONS.iter().enumerate() {
        let mut r = Rattle::new(Dynamics::new(p), excitation(sc), states[i]);
        r.region = *region;
        ns[i] = ns_per_rhs(|t, y| r.rhs(t, y), states[i]);
    }
    let rhs_time: f64 = (0..5).map(|i| evals[i] as f64 * ns[i] * 1e-9).sum();
    // The same right-hand side written literally from docs/MODEL.md, as a peer's user would write
    // it (powf for |δ/G|^(α−1), the band's sine as written, sin and cos of the excitation).
    let user = peers::UserRhs::new(p, sc.A_rms, sc.f_exc);
    let ns_literal: [f64; 5] =
        std::array::from_fn(|i| ns_per_rhs(|t, y| user.rhs(t, y), states[i]));
    let literal_time: f64 = (0..5).map(|i| evals[i] as f64 * ns_literal[i] * 1e-9).sum();

    println!(
        "GearRattle (direct), S1 1 s, rtol {rtol:e}: {:.3} ms CPU per run (mean of {runs}), \
         max |dxi| over the run's 1 ms grid vs the reference: see rust.csv",
        per_run * 1e3
    );
    println!(
        "work: {} RHS, {} accepted + {} rejected steps ({} of them Taylor steps), {} edges crossed",
        run.rhs, solver.stats.accepted, solver.stats.rejected, solver.stats.series_steps, run.edges
    );
    println!(
        "free flight in closed form: {} evaluations of the exact solution, {} RHS in the gap",
        solver.stats.exact_evals,
        evals[index(Region::Gap)]
    );
    println!(
        "RHS per accepted DOPRI5 step {:.2}; RHS on edges crossed out of a band ({} of the {} edges: \
         a DOPRI5 step redone to end on the edge + a new first stage, 7 each) {:.0} % ; RHS on \
         rejected steps (6 each) {:.0} %",
        run.rhs as f64 / (solver.stats.accepted - solver.stats.series_steps) as f64,
        sys.out_of_bands,
        run.edges,
        100.0 * 7.0 * sys.out_of_bands as f64 / run.rhs as f64,
        100.0 * 6.0 * solver.stats.rejected as f64 / run.rhs as f64
    );
    println!(
        "RHS by region (counted run: {counted} RHS, {} outside the regions' count: initial step):",
        run.rhs.saturating_sub(counted)
    );
    for (i, (_, name)) in REGIONS.iter().enumerate() {
        println!(
            "  {name:26} {:8} RHS ({:4.1} %)  {:5.1} ns each  {:5.1} % of the CPU time",
            evals[i],
            100.0 * evals[i] as f64 / counted as f64,
            ns[i],
            100.0 * evals[i] as f64 * ns[i] * 1e-9 / per_run
        );
    }
    println!(
        "literal docs/MODEL.md RHS (powf, the band's sine as written): {} ns per region; the run's RHS \
         would cost {:.0} % of GearRattle's RHS time",
        ns_literal
            .iter()
            .map(|x| format!("{x:.1}"))
            .collect::<Vec<_>>()
            .join(" / "),
        100.0 * literal_time / rhs_time
    );
    println!(
        "right-hand sides {:.0} % of the CPU time; the rest ({:.0} %, {:.1} ns per RHS) is the \
         integrator: stages, error norm, step control, edge search on the dense output, output stops",
        100.0 * rhs_time / per_run,
        100.0 * (1.0 - rhs_time / per_run),
        (per_run - rhs_time) / run.rhs as f64 * 1e9
    );
}

/// `BENCH_PROFILE=calls`: the cost of each communication step on S1 (1 s) at
/// BENCH_PROFILE_RTOL (default 1e-7): GearRattle alone (1 ms grid), `Simulation::step_to`
/// and the C API at 10 ms and 10 µs, interleaved for BENCH_PROFILE_SECONDS (default 4) of
/// CPU, then the split of one 10 µs call ([`call_split`]); BENCH_PROFILE_ONLY=fmu|steps runs
/// only that one at 10 µs (for `perf record`).
pub fn calls(scenes: &[Scene], import: &Fmi2Import) {
    let (sc, rtol, seconds) = setup(scenes, 1e-7);
    let only = std::env::var("BENCH_PROFILE_ONLY").ok();
    type Runner<'a> = Box<dyn Fn() -> Outcome + 'a>;
    let mut runs: Vec<(&str, Runner)> = vec![
        ("direct, 1 ms grid", Box::new(|| run_gearrattle(sc, rtol))),
        ("step_to 10 ms", Box::new(|| run_steps(sc, rtol, 1e-2))),
        ("step_to 10 us", Box::new(|| run_steps(sc, rtol, 1e-5))),
        ("C API 10 ms", Box::new(|| run_fmu(import, sc, rtol, 1e-2))),
        ("C API 10 us", Box::new(|| run_fmu(import, sc, rtol, 1e-5))),
    ];
    match only.as_deref() {
        Some("fmu") => runs.retain(|(name, _)| *name == "C API 10 us"),
        Some("steps") => runs.retain(|(name, _)| *name == "step_to 10 us"),
        _ => {}
    }
    let mut cpu: Vec<Vec<f64>> = vec![Vec::new(); runs.len()];
    let start = cpu_now();
    while cpu_now() - start < seconds || cpu[0].is_empty() {
        for (i, (_, run)) in runs.iter().enumerate() {
            cpu[i].push(run().expect("run").1);
        }
    }
    let med: Vec<f64> = cpu.iter().map(|c| median(c)).collect();
    println!(
        "S1 1 s at rtol {rtol:e}, median CPU of {} interleaved runs:",
        cpu[0].len()
    );
    for (i, (name, _)) in runs.iter().enumerate() {
        println!(
            "  {name:20} {:8.3} ms  ({:.2}x the first)",
            med[i] * 1e3,
            med[i] / med[0]
        );
    }
    if only.is_none() {
        // step_to at 10 ms: the integration of the second alone.
        call_split(import, sc, rtol, med[1]);
    }
}

/// Where a 10 µs call's time goes, each part timed over 100 000 calls of its own (median of
/// 5 rounds): fmi2GetReal of ξ, ξ' alone (no step between: the C boundary, the guard and two
/// outputs), `Simulation::real_output` of ξ alone, and 1 s of fmi2DoStep against
/// `Simulation::step_to` (both with the integration, whose share per call is the second's
/// `integration` CPU over the 100 000 calls).
fn call_split(import: &Fmi2Import, sc: &Scene, rtol: f64, integration: f64) {
    const CALLS: usize = 100_000;
    let per_call = |start: f64| (cpu_now() - start) / CALLS as f64 * 1e9;
    let outs = [vr::xi, vr::xi_dot];
    let mut rounds: [Vec<f64>; 4] = Default::default();
    for _ in 0..5 {
        let mut inst = import
            .instantiate_cs("split", false, false)
            .expect("instantiate");
        init_fmu(&mut inst, sc, rtol).expect("initialisation");
        let mut x = [0.0; 2];
        let start = cpu_now();
        for _ in 0..CALLS {
            inst.get_real(&outs, &mut x).expect("get");
        }
        rounds[0].push(per_call(start));
        let start = cpu_now();
        for k in 1..=CALLS {
            inst.do_step((k - 1) as f64 * 1e-5, 1e-5, true)
                .expect("step");
        }
        rounds[1].push(per_call(start));
        let mut sim =
            Simulation::new(&fmu_values(sc), 0.0, 0.0, rtol, Carry::Asked).expect("simulation");
        let start = cpu_now();
        for k in 1..=CALLS {
            sim.step_to(k as f64 * 1e-5).expect("step");
        }
        rounds[2].push(per_call(start));
        let start = cpu_now();
        let mut sink = 0.0;
        for _ in 0..CALLS {
            sink += sim.real_output(std::hint::black_box(vr::xi)).expect("xi");
        }
        std::hint::black_box(sink);
        rounds[3].push(per_call(start));
    }
    let [get, step, step_to, output] = rounds.map(|r| median(&r));
    println!(
        "One 10 us call, median of 5 rounds of {CALLS}: fmi2GetReal (xi, xi') {get:.0} ns; \
         fmi2DoStep {step:.0} ns against Simulation::step_to {step_to:.0} ns (both with the \
         integration: {:.0} ns of it); Simulation::real_output (xi) {output:.0} ns",
        integration / CALLS as f64 * 1e9
    );
}
