//! The running gearbox of an initialised instance: its parameters from the contract's
//! values, what drives it (docs/GEARBOX.md §4 or the drivetrain's inputs), the solver and the
//! state, the clock, and the statistics window that opens on the way ([`crate::windowed`]).
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

use crate::contract::{self, vr};
use crate::independent::Independent;
use crate::outputs::mesh_force;
use crate::windowed::{self, Windowed};
use fmi2_shell::values::Values;
use fmi2_shell::{FmiError, FmiResult};
use gear_rattle::gearbox::{self, Drive, Gearbox, GearboxParams, LooseGear, PHI, State, xi};
use gear_rattle::instance::simulation::journal::{Change, Journal, Journaled};
use gear_rattle::instance::simulation::{Stepped, method};
use gear_rattle::integrator::solver::Point;
use gear_rattle::integrator::{Method, Solver, SolverError, Stats};
use gear_rattle::physics::{
    DamperParams, Engine, EngineOrder, EngineParams, GearParams, Oil, Polynomial, Shaft,
};
use gear_rattle::rattle::window::{self, Quadratures, Window};

/// Values of the `excitation` parameter.
pub const EXCITATION_FLYWHEEL: i64 = 0;
pub const EXCITATION_ENGINE: i64 = 1;
pub const EXCITATION_INPUT_SIDE: i64 = 2;

/// The gearbox before its statistics window opens, and with it; or on an imposed input side
/// in co-simulation, its gears stepped apart. Boxed: their solvers are some 60 and 145 KB,
/// which an instance, its FMU states and their decoding keep off the stack (an importer's
/// thread may have 1 MB).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Run {
    Lean(Box<Stepped<Gearbox, { gearbox::N }>>),
    Windowed(Box<Stepped<Windowed, { windowed::N }>>),
    Independent(Box<Independent>),
}

/// An initialised gearbox being stepped.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Simulation {
    pub run: Run,
    pub t: f64,
    /// Where the statistics window opens: max(stats_from, start time).
    pub window_from: f64,
    rtol: f64,
    method: Method,
    /// Communication points served from the dense output of natural steps (the built-in
    /// engine's drive does not change between steps; inputs do).
    interpolate_ends: bool,
    /// Model Exchange: the importer integrates, the outputs take the pieces the states are
    /// in.
    pub model_exchange: bool,
    /// What puts a failed step back: a copy of the run and the time, and the changes since.
    #[serde(skip)]
    journal: Journal<(Run, f64), Change<Input>, ENTRIES>,
}

/// How many changes the journal records before it takes a new copy of the run (145 KB with
/// the window open): a communication point served from the kept step is a change too, and
/// the sound's grid has some 13 of them per integrator step (docs/DECISIONS.md D60).
const ENTRIES: usize = 1024;

/// New inputs of the simulation in co-simulation, as the journal records them.
#[derive(Clone, Copy, Debug)]
pub enum Input {
    /// New flywheel inputs (excitation 0).
    Flywheel(Shaft),
    /// New input-side inputs (excitation 2).
    InputSide(Shaft),
    /// The output shaft's speed.
    OutputSpeed(f64),
}

/// The gearbox's parameters as set: gears 1..n_gears from the per-gear arrays (C and c_I at
/// 40 °C; the model scales them with the oil), the damper, the engine, the oil.
pub fn params(values: &Values) -> GearboxParams {
    let r = |vr: u32| values.real(vr);
    let n = values
        .integer(vr::n_gears)
        .clamp(0, gearbox::MAX_GEARS as i64) as usize;
    let g = |array: [u32; 8], i: usize| r(array[i]);
    let gears = (0..n)
        .map(|i| {
            use vr::gear;
            LooseGear {
                pair: GearParams {
                    I_L: g(gear::I_L, i),
                    r_L: g(gear::r_L, i),
                    r_M: g(gear::r_M, i),
                    K_star: g(gear::K_star, i),
                    alpha: g(gear::alpha, i),
                    epsilon: g(gear::epsilon, i),
                    G: g(gear::G, i),
                    C_LM: g(gear::C_LM, i),
                    C: g(gear::C, i),
                    B: g(gear::B, i),
                    omega_S: 0.0,
                },
                rho: g(gear::rho, i),
                sigma: g(gear::sigma, i),
            }
        })
        .collect();
    let order = |n, a, phase| EngineOrder {
        n: r(n),
        a: r(a),
        phase: r(phase),
    };
    GearboxParams {
        gears,
        I_I: r(vr::I_I),
        c_I: r(vr::c_I),
        damper: DamperParams {
            k_1: r(vr::k_1),
            k_2: r(vr::k_2),
            phi_1: r(vr::phi_1),
            H_1: r(vr::H_1),
            H_2: r(vr::H_2),
            c_cl: r(vr::c_cl),
            omega_h: r(vr::omega_h),
        },
        engine: EngineParams {
            rpm: r(vr::rpm),
            rpm_rate: r(vr::rpm_rate),
            orders: [
                order(vr::order_1, vr::a_1, vr::phase_1),
                order(vr::order_2, vr::a_2, vr::phase_2),
            ],
        },
        oil: Oil {
            nu_40: r(vr::nu_40),
            nu_100: r(vr::nu_100),
        },
        T_oil: r(vr::T_oil),
    }
}

/// The flywheel's inputs (excitation 0), or the input side's (excitation 2).
pub fn flywheel_inputs(values: &Values) -> Shaft {
    Shaft {
        theta: values.real(vr::theta_F),
        omega: values.real(vr::omega_F),
        alpha: values.real(vr::alpha_F),
    }
}

pub fn input_side_inputs(values: &Values) -> Shaft {
    Shaft {
        theta: values.real(vr::theta_I),
        omega: values.real(vr::omega_I),
        alpha: values.real(vr::alpha_I),
    }
}

/// The drive the `excitation` parameter asks for, from t0.
fn drive(values: &Values, params: &GearboxParams, t0: f64) -> Drive {
    let from = |at_t0| Polynomial { t0, at_t0 };
    match values.integer(vr::excitation) {
        EXCITATION_FLYWHEEL => Drive::Flywheel(from(flywheel_inputs(values))),
        EXCITATION_ENGINE => Drive::Engine(Engine::new(&params.engine)),
        EXCITATION_INPUT_SIDE => Drive::InputSide(from(input_side_inputs(values))),
        other => unreachable!("excitation = {other} is outside the contract's range"),
    }
}

/// The impacts of every gear so far, both flanks (the slots beyond n_gears have none).
fn impacts(g: &Gearbox) -> u64 {
    g.gears
        .iter()
        .map(|g| g.impacts.count.iter().sum::<u64>())
        .sum()
}

/// `$body` with `$k` the stepped system of `$run`, or `$independent` with `$p` its gears.
macro_rules! on_run {
    ($run:expr, $k:ident => $body:expr, $p:ident => $independent:expr) => {
        match $run {
            Run::Lean($k) => $body,
            Run::Windowed($k) => $body,
            Run::Independent($p) => $independent,
        }
    };
}

impl Simulation {
    /// Checks the parameters (the contract's ranges, then docs/GEARBOX.md's rules between them)
    /// and builds docs/GEARBOX.md §6's start at t0 with φ(0) = phi_start and each
    /// ξ_i(0) = gap_start_i G_i, the output shaft at omega_out.
    pub fn new(values: &Values, t0: f64, rtol: f64, model_exchange: bool) -> FmiResult<Self> {
        contract::check_parameters(values)?;
        let params = params(values);
        let drive = drive(values, &params, t0);
        let (_, mut y) = Gearbox::start(&params, drive)
            .map_err(|e| FmiError::error(format!("{e}: nothing runs on an invalid gearbox")))?;
        if !matches!(drive, Drive::InputSide(_)) {
            y[PHI] = values.real(vr::phi_start);
        }
        for (i, gear) in params.gears.iter().enumerate() {
            y[xi(i)] = values.real(vr::gear::gap_start[i]) * gear.pair.G;
        }
        let mut system = Gearbox::new(&params, drive, &y);
        system.set_output_speed(values.real(vr::omega_out));
        let method = method(values.integer(vr::solver));
        let window_from = values.real(vr::stats_from).max(t0);
        if matches!(drive, Drive::InputSide(_)) && !model_exchange {
            let run = Independent::new(system, &y, t0, window_from, rtol, method);
            return Ok(Simulation {
                run: Run::Independent(Box::new(run)),
                t: t0,
                window_from,
                rtol,
                method,
                interpolate_ends: false,
                model_exchange,
                journal: Journal::default(),
            });
        }
        let interpolate_ends = matches!(drive, Drive::Engine(_));
        let mut solver = Solver::with_method(system.tolerance(rtol), method);
        solver.interpolate_ends = interpolate_ends;
        let mut sim = Simulation {
            run: Run::Lean(Box::new(Stepped { system, solver, y })),
            t: t0,
            window_from,
            rtol,
            method,
            interpolate_ends,
            model_exchange,
            journal: Journal::default(),
        };
        if sim.window_from <= t0 {
            sim.open_window();
        }
        Ok(sim)
    }

    /// The statistics window opens now: the windowed gearbox takes over from the lean one
    /// with a solver of its own size.
    pub(crate) fn open_window(&mut self) {
        let Run::Lean(k) = &self.run else {
            return;
        };
        let (system, y) = Windowed::open(k.system, self.t, &k.y);
        let mut solver = Solver::with_method(system.tolerance(self.rtol), self.method);
        solver.interpolate_ends = self.interpolate_ends;
        solver.stats = k.solver.stats;
        self.run = Run::Windowed(Box::new(Stepped { system, solver, y }));
    }

    /// The run's advance to t_end, stopping at an impact if `at_impact`: true if it did.
    fn advance_until(&mut self, t_end: f64, at_impact: bool) -> Result<bool, SolverError> {
        let on = u64::from(at_impact);
        match &mut self.run {
            Run::Lean(k) => k.advance_until(&mut self.t, t_end, |g| on * impacts(g)),
            Run::Windowed(k) => k.advance_until(&mut self.t, t_end, |w| on * impacts(&w.inner)),
            Run::Independent(p) => {
                let (reached, stopped) = p.advance(self.t, t_end, at_impact)?;
                self.t = reached;
                Ok(stopped)
            }
        }
    }

    /// The gearbox and its state now, as the outputs read them: in Model Exchange with the
    /// stage and regions the states are in.
    pub fn observed(&self) -> (Gearbox, State) {
        if self.model_exchange {
            return self.settled();
        }
        let (g, y) = self.gearbox();
        (*g, y)
    }

    /// The gearbox and its state now.
    pub fn gearbox(&self) -> (&Gearbox, State) {
        match &self.run {
            Run::Lean(k) => (&k.system, k.y),
            Run::Windowed(k) => (&k.system.inner, windowed::head(&k.y)),
            Run::Independent(p) => (&p.gearbox, p.state()),
        }
    }

    /// Gear i's statistics window and its quadratures, once it is open.
    pub fn window(&self, i: usize) -> Option<(&Window, Quadratures)> {
        match &self.run {
            Run::Lean(_) => None,
            Run::Windowed(k) => Some((&k.system.windows[i], windowed::quadratures(&k.y, i))),
            Run::Independent(p) => p.window(i),
        }
    }

    /// Changes the gearbox and its state from outside (new inputs): `change` gets the
    /// gearbox, the time and the gearbox's state; the solver starts afresh.
    pub(crate) fn change_state(&mut self, change: impl FnOnce(&mut Gearbox, f64, &mut State)) {
        let t = self.t;
        match &mut self.run {
            Run::Lean(k) => {
                change(&mut k.system, t, &mut k.y);
                k.solver.invalidate();
            }
            Run::Windowed(k) => {
                let mut y = windowed::head(&k.y);
                change(&mut k.system.inner, t, &mut y);
                k.y[..gearbox::N].copy_from_slice(&y);
                k.solver.invalidate();
            }
            Run::Independent(_) => {
                unreachable!("the gears stepped apart change through their own setters")
            }
        }
    }

    /// New flywheel inputs (excitation 0; ignored otherwise): φ and φ' follow at once.
    pub fn set_flywheel(&mut self, shaft: Shaft) {
        if matches!(self.gearbox().0.drive, Drive::Flywheel(_)) {
            self.change(Input::Flywheel(shaft));
        }
    }

    /// New input-side inputs (excitation 2; ignored otherwise): the ξ_i follow at once.
    pub fn set_input_side(&mut self, shaft: Shaft) {
        if matches!(self.gearbox().0.drive, Drive::InputSide(_)) {
            self.change(Input::InputSide(shaft));
        }
    }

    /// The output shaft's speed.
    pub fn set_output_speed(&mut self, omega_out: f64) {
        self.change(Input::OutputSpeed(omega_out));
    }

    /// The imposed motion's extrapolation now (excitation 0: the flywheel's, 2: the input
    /// side's), which the inputs follow until the master sets them again.
    pub fn extrapolated_inputs(&self) -> Option<(bool, Shaft)> {
        match self.gearbox().0.drive {
            Drive::Flywheel(p) => Some((true, p.at(self.t))),
            Drive::InputSide(p) => Some((false, p.at(self.t))),
            Drive::Engine(_) => None,
        }
    }

    /// The calls of `step_until` (not stopping at impacts) from each `from` to its `to` in
    /// `calls`, each continuing where the one before ends, as far as the solver serves them
    /// without stepping ([`Solver::serve_run`]), the contact force of each of `gears` (see
    /// [`mesh_force`]) read at each end into a row of `out`: how many were taken. A force
    /// that is not finite is left to the ordinary read, which refuses it. None on gears
    /// stepped apart, nor across the statistics window's opening.
    pub fn serve_forces(
        &mut self,
        calls: impl Iterator<Item = (f64, f64)>,
        gears: &[usize],
        out: &mut [f64],
    ) -> usize {
        let mut calls = calls.peekable();
        let Some(&(from, _)) = calls.peek() else {
            return 0;
        };
        let m = gears.len();
        let mut rows = out.chunks_exact_mut(m.max(1));
        let window_from = self.window_from;
        self.served(from, |sim| match &mut sim.run {
            Run::Lean(k) => {
                let shut = |&(_, to): &(f64, f64)| window::opening(window_from, from, to).is_none();
                let calls = calls.take_while(shut);
                k.solver
                    .serve_run(&k.system, &mut sim.t, &mut k.y, calls, |g, at| {
                        read_forces(g, &at, gears, rows.next())
                    })
            }
            Run::Windowed(k) => {
                k.solver
                    .serve_run(&k.system, &mut sim.t, &mut k.y, calls, |w, at| {
                        read_forces(&w.inner, &at, gears, rows.next())
                    })
            }
            Run::Independent(_) => 0,
        })
    }

    pub fn stats(&self) -> Stats {
        on_run!(&self.run, k => k.solver.stats, p => p.stats())
    }

    pub fn is_implicit(&self) -> bool {
        on_run!(&self.run, k => k.solver.is_implicit(), p => p.is_implicit())
    }

    pub fn proposed_step(&self) -> f64 {
        on_run!(&self.run, k => k.solver.proposed_step(), p => p.proposed_step())
    }
}

/// The contact force of each of `gears` at the point `at` into `row` (none to read: no row);
/// false where one is not finite.
fn read_forces<const N: usize>(
    gearbox: &Gearbox,
    at: &Point<N>,
    gears: &[usize],
    row: Option<&mut [f64]>,
) -> bool {
    let Some(row) = row else {
        return gears.is_empty();
    };
    for (value, &i) in row.iter_mut().zip(gears) {
        *value = mesh_force(gearbox, i, |k| at.component(k));
    }
    row.iter().all(|v| v.is_finite())
}

/// The gearbox's changes in co-simulation: steps and new inputs.
impl Journaled<ENTRIES> for Simulation {
    type Copy = (Run, f64);
    type Input = Input;

    fn journal(&mut self) -> &mut Journal<Self::Copy, Change<Input>, ENTRIES> {
        &mut self.journal
    }

    fn copy(&self) -> Self::Copy {
        (self.run.clone(), self.t)
    }

    fn restore(&mut self, (run, t): &Self::Copy) {
        (self.run, self.t) = (run.clone(), *t);
    }

    fn time(&mut self) -> &mut f64 {
        &mut self.t
    }

    /// Through the window's opening on the way (on the call's start or end where it lies
    /// within the resolution of time of them: [`window::opening`]); with `at_impact` the
    /// first impact is that of any gear.
    fn advance(&mut self, t_end: f64, at_impact: bool) -> Result<f64, SolverError> {
        let opening = match self.run {
            Run::Lean(_) => window::opening(self.window_from, self.t, t_end),
            _ => None,
        };
        let stopped = if let Some(from) = opening {
            if self.advance_until(from, at_impact)? {
                true
            } else {
                self.open_window();
                self.advance_until(t_end, at_impact)?
            }
        } else {
            self.advance_until(t_end, at_impact)?
        };
        if !stopped {
            self.t = t_end;
        }
        Ok(self.t)
    }

    fn take(&mut self, input: Input) {
        match input {
            Input::Flywheel(shaft) => self.change_state(|g, t, y| {
                g.set_flywheel(t, y, shaft);
            }),
            Input::InputSide(shaft) => match &mut self.run {
                Run::Independent(p) => p.set_input_side(self.t, shaft),
                _ => self.change_state(|g, t, y| {
                    g.set_input_side(t, y, shaft);
                }),
            },
            Input::OutputSpeed(omega_out) => match &mut self.run {
                Run::Independent(p) => p.set_output_speed(omega_out),
                _ => self.change_state(|g, _, _| g.set_output_speed(omega_out)),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A step that fails leaves the simulation as it was, run and solver compared whole, in
    /// every kind of run: the coupled box (inputs, excitation 0) before its window opens, with
    /// the window opening among the journaled steps and open from the start, and the gears
    /// stepped apart (the input side, excitation 2);
    /// after more steps than a journal records, with new inputs among them: its journal
    /// replays them. The step fails on its first attempt, below the resolution of time, after
    /// new inputs have made the solver evaluate the derivative there. It then goes on as if the
    /// failed step had not been asked for.
    #[test]
    fn a_failed_step_leaves_the_simulation_as_it_was() {
        // The excitation, where the window opens and the kind of run it ends in.
        let cases = [
            (EXCITATION_FLYWHEEL, 10.0, "Lean"),
            (EXCITATION_FLYWHEEL, 5e-3, "Windowed"),
            (EXCITATION_FLYWHEEL, 0.0, "Windowed"),
            (EXCITATION_INPUT_SIDE, 2e-3, "Independent"),
        ];
        std::thread::Builder::new()
            .stack_size(8 << 20)
            .spawn(move || {
                for (excitation, stats_from, kind) in cases {
                    let case = format!("excitation {excitation}, window from {stats_from}");
                    let mut values = Values::start(contract::VARIABLES);
                    values.set_integer(vr::excitation, excitation);
                    values.set_integer(vr::n_gears, 3);
                    values.set_real(vr::omega_F, 84.0);
                    values.set_real(vr::omega_I, 84.0);
                    values.set_real(vr::stats_from, stats_from);
                    let mut sim = Simulation::new(&values, 0.0, 1e-6, false).unwrap();
                    let steps = ENTRIES + ENTRIES / 2;
                    let inputs = |k: usize| Shaft {
                        theta: 84.0 * k as f64 * 1e-4,
                        omega: 84.0 + (k as f64 * 0.7).sin(),
                        alpha: 0.0,
                    };
                    for k in 1..=steps {
                        sim.step_until(k as f64 * 1e-4, false).unwrap();
                        if k % 7 == 0 {
                            sim.set_flywheel(inputs(k));
                            sim.set_input_side(inputs(k));
                            sim.set_output_speed(20.0 + k as f64 * 1e-2);
                        }
                    }
                    let ran = match &sim.run {
                        Run::Lean(_) => "Lean",
                        Run::Windowed(_) => "Windowed",
                        Run::Independent(_) => "Independent",
                    };
                    assert_eq!(ran, kind, "{case}");
                    sim.set_output_speed(21.0);
                    // More changes than the journal records: it holds those since its last copy.
                    assert!(!sim.journal.is_empty() && sim.journal.len() < steps);
                    let before = sim.clone();
                    let t = sim.t;
                    assert!(
                        sim.step_until(t + 4.0 * f64::EPSILON * t, false).is_err(),
                        "{case}"
                    );
                    assert!(sim == before, "{case}");
                    assert_eq!(sim.stats(), before.stats(), "{case}");
                    let mut unfailed = before;
                    for k in steps + 1..=steps + 20 {
                        sim.step_until(k as f64 * 1e-4, false).unwrap();
                        unfailed.step_until(k as f64 * 1e-4, false).unwrap();
                    }
                    assert!(sim == unfailed, "{case}");
                }
            })
            .unwrap()
            .join()
            .unwrap();
    }
}
