//! The running model of an initialised instance: the gear pair with its solver and state,
//! the clock, and what drives the main shaft. Two couplings: kinematic (the shaft's motion
//! imposed by the bench sine or the master's inputs; [`Rattle`], or [`LeanRattle`] without
//! the statistics window's quadratures when a run asks for no window) and torque (the shaft
//! an inertia driven by the master's torque; [`TorqueRattle`], two states more), each with a
//! solver of its own size: a state carries only what its run needs. Outputs are computed
//! here when they are read, by one code for every variant ([`Now`]).
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

use super::FmiResult;
use crate::contract::{self, vr};
use crate::integrator::{Jacobian, Method, Piecewise, Solver, SolverError, Stats};
use crate::physics::{
    Dynamics, Excitation, GearParams, Loads, MainShaft, Polynomial, Region, Shaft, Sine, TorqueRamp,
};
use crate::rattle::torque::{self, TorqueRattle};
use crate::rattle::window::{self, Metrics, Quadratures, Window};
use crate::rattle::{self, GearPair, Impacts, KinematicRattle, LeanRattle, Rattle};
use fmi2_shell::values::Values;
use journal::{Change, ENTRIES, Input, Journal};

pub mod journal;
mod readout;

pub use journal::Journaled;
pub use readout::Readout;

/// Values of the `excitation` parameter.
pub const EXCITATION_INPUTS: i64 = 0;
pub const EXCITATION_SINE: i64 = 1;
pub const EXCITATION_TORQUE: i64 = 2;

/// What moves the main shaft.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Drive {
    /// The paper's bench: exact sine motion, a function of time.
    Sine(Sine),
    /// The drivetrain's inputs: the shaft's motion at the current time, extrapolated over
    /// each step as a Taylor polynomial (docs/MODEL.md §5: never a zero-order hold).
    Inputs(Shaft),
    /// The drivetrain's torque on the shaft τ_in at the current time and its rate, ramped
    /// over each step; the shaft's motion follows from I_M ω_M' = τ_in + τ_M.
    Torque { tau: f64, rate: f64 },
}

/// A piecewise system with its solver and its state.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stepped<S, const N: usize> {
    pub system: S,
    pub solver: Solver<N>,
    #[serde(with = "crate::integrator::serde_array")]
    pub y: [f64; N],
}

impl<S: Piecewise<N> + Jacobian<N> + Copy, const N: usize> Stepped<S, N> {
    /// Advances to t_end, stopping on the first edge crossed that raises the system's count
    /// of `events` ([`Solver::advance_until`]): true if it stopped there. A failure leaves
    /// the system where it failed (its simulation's [`Journal`] puts it back).
    pub fn advance_until(
        &mut self,
        t: &mut f64,
        t_end: f64,
        events: impl Fn(&S) -> u64,
    ) -> Result<bool, SolverError> {
        self.solver
            .advance_until(&mut self.system, t, &mut self.y, t_end, events)
    }
}

impl<S: GearPair<N> + Jacobian<N> + Copy, const N: usize> Stepped<S, N> {
    /// Advances to t_end, through the opening of the statistics window on the way, where its
    /// quadratures are kept (on the call's start or end where it lies within the resolution
    /// of time of them: [`window::opening`]). With `at_impact`, stops at the first impact
    /// (contact onset) on the way, as located: true if it did. A failure leaves the pair
    /// where it failed (the simulation's [`Journal`] puts it back).
    pub fn advance(
        &mut self,
        t: &mut f64,
        t_end: f64,
        at_impact: bool,
    ) -> Result<bool, SolverError> {
        let impacts = move |s: &S| {
            let count = s.impacts().count;
            if at_impact { count[0] + count[1] } else { 0 }
        };
        let w = self.system.window();
        let opening = match w.is_opened() {
            true => None,
            false => window::opening(w.from, *t, t_end),
        };
        if let Some(from) = opening {
            // It opens there: what happens from then on is counted.
            self.system.window_mut().from = from;
            if self.advance_until(t, from, impacts)? {
                return Ok(true);
            }
            self.open_window();
        }
        self.advance_until(t, t_end, impacts)
    }

    /// The calls of `advance` (not stopping at impacts) from each `from` to its `to` in
    /// `calls`, the first from `from`, as far as the solver serves them without stepping
    /// ([`Solver::serve_run`]), the contact force read `reads` times at each end into a row
    /// of `out`: how many were taken. A force that is not finite is left to the ordinary
    /// read, which refuses it. None across the statistics window's opening.
    fn serve_forces(
        &mut self,
        t: &mut f64,
        from: f64,
        calls: impl Iterator<Item = (f64, f64)>,
        reads: usize,
        out: &mut [f64],
    ) -> usize {
        let w = self.system.window();
        let (opened, opens) = (w.is_opened(), w.from);
        let shut = |&(_, to): &(f64, f64)| opened || window::opening(opens, from, to).is_none();
        let mut rows = out.chunks_exact_mut(reads.max(1));
        let calls = calls.take_while(shut);
        self.solver
            .serve_run(&self.system, t, &mut self.y, calls, |pair, at| {
                let (xi, xi_dot) = (at.component(S::XI), at.component(S::XI_DOT));
                let force = pair.dynamics().law.force(pair.region(), xi, xi_dot).total();
                match rows.next() {
                    Some(row) => {
                        row.fill(force);
                        force.is_finite()
                    }
                    None => reads == 0,
                }
            })
    }

    /// The pair at t0 with the state's first components `head` (the quadratures from 0) and
    /// its statistics window opening at `window`, if any: a window that opens at t0 keeps
    /// the initial quadratures.
    fn start(system: S, solver: Solver<N>, head: &[f64], t0: f64, window: Option<f64>) -> Self {
        let system = match window {
            Some(from) => system.with_window(t0, from),
            None => system,
        };
        let mut y = [0.0; N];
        y[..head.len()].copy_from_slice(head);
        let mut stepped = Stepped { system, solver, y };
        if stepped.system.window().from <= t0 {
            stepped.open_window();
        }
        stepped
    }

    /// The statistics window opens now: its quadratures are kept.
    pub(super) fn open_window(&mut self) {
        let q = S::quadratures(&self.y);
        self.system.window_mut().open(q);
    }

    /// ξ and ξ'.
    fn xi(&self) -> [f64; 2] {
        [self.y[S::XI], self.y[S::XI_DOT]]
    }

    fn now(&self) -> Now<'_> {
        let (sys, y) = (&self.system, &self.y);
        Now {
            dynamics: sys.dynamics(),
            region: sys.region(),
            impacts: sys.impacts(),
            xi: y[S::XI],
            xi_dot: y[S::XI_DOT],
            quadratures: S::quadratures(y),
            window: sys.window(),
            stats: &self.solver.stats,
            implicit: self.solver.is_implicit(),
        }
    }
}

impl<const N: usize> Stepped<KinematicRattle<N>, N> {
    /// New motion of the main shaft at t, from `old` to `shaft`, imposed from then on as
    /// `excitation`. The loose gear does not move, so ξ and ξ' follow the shaft
    /// (ξ = r_L θ_L − r_M θ_M) and the region settles where ξ lands; the solver starts afresh.
    pub fn move_shaft(&mut self, t: f64, old: Shaft, shaft: Shaft, excitation: Excitation) {
        let r_M = self.system.dynamics.params.r_M;
        self.y[rattle::XI] += r_M * (old.theta - shaft.theta);
        self.y[rattle::XI_DOT] += r_M * (old.omega - shaft.omega);
        self.system.excitation = excitation;
        self.system.settle(t, &self.y);
        self.solver.invalidate();
    }

    /// A kinematic pair at t0 (see [`Stepped::start`]) with its solver at `rtol`; `ends`:
    /// the end times of the calls are served from the dense output of natural steps.
    pub fn kinematic(
        system: KinematicRattle<N>,
        rtol: f64,
        method: Method,
        ends: bool,
        head: &[f64],
        t0: f64,
        window: Option<f64>,
    ) -> Self {
        let mut solver = Solver::with_method(system.tolerance(rtol), method);
        solver.interpolate_ends = ends;
        Self::start(system, solver, head, t0, window)
    }
}

/// The gear pair in one of the two couplings, with the statistics window's quadratures or
/// without. Plain data kept in place (copied whole by the journal that puts a failed step
/// back, and serialized for the FMU state), so the larger variants are not boxed.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Gear {
    /// The main shaft's motion imposed (sine or inputs): state ξ, ξ' and the quadratures.
    Kinematic(Stepped<Rattle, { rattle::N }>),
    /// The same without the window's quadratures.
    KinematicLean(Stepped<LeanRattle, { rattle::N_LEAN }>),
    /// The main shaft an inertia driven by τ_in: θ_M and ω_M join the state.
    Torque(Stepped<TorqueRattle, { torque::N }>),
}

/// `$body` with `$k` the stepped pair of `$gear`, whichever the variant (compiled for each:
/// their types differ in the state's size).
macro_rules! on_gear {
    ($gear:expr, $k:ident => $body:expr) => {
        match $gear {
            Gear::Kinematic($k) => $body,
            Gear::KinematicLean($k) => $body,
            Gear::Torque($k) => $body,
        }
    };
}
pub(super) use on_gear;

/// `$kinematic` or `$torque` by the coupling of `$gear`, each with its pattern bound to the
/// stepped pair.
macro_rules! by_coupling {
    ($gear:expr, kinematic $kp:pat => $kinematic:expr, torque $tp:pat => $torque:expr) => {
        match $gear {
            Gear::Kinematic($kp) => $kinematic,
            Gear::KinematicLean($kp) => $kinematic,
            Gear::Torque($tp) => $torque,
        }
    };
}
pub(super) use by_coupling;

/// Which of the quadratures a simulation carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Carry {
    /// Those its run asks for: all of them with a statistics window, the energies and the
    /// work alone without in the kinematic modes (co-simulation).
    Asked,
    /// All of them: Model Exchange, whose importer integrates every state of the contract.
    All,
}

/// An initialised gear pair being stepped.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Simulation {
    pub gear: Gear,
    pub t: f64,
    pub drive: Drive,
    /// What puts a failed step back (see `journal`).
    #[serde(skip)]
    journal: Journal<(Gear, f64, Drive), Change<Input>, ENTRIES>,
}

/// What every output is computed from at the current time, whichever the coupling (the
/// shaft's motion apart: [`Simulation::shaft`], computed only for the outputs that need it).
pub(super) struct Now<'a> {
    pub(super) dynamics: &'a Dynamics,
    pub(super) region: Region,
    pub(super) impacts: &'a Impacts,
    pub(super) xi: f64,
    pub(super) xi_dot: f64,
    pub(super) quadratures: Quadratures,
    pub(super) window: &'a Window,
    pub(super) stats: &'a Stats,
    /// Radau IIA is stepping now.
    pub(super) implicit: bool,
}

impl Now<'_> {
    pub(super) fn loads(&self, shaft: &Shaft) -> Loads {
        self.dynamics
            .loads(self.region, self.xi, self.xi_dot, shaft)
    }

    /// The statistics window's figures at t.
    fn metrics(&self, t: f64) -> Metrics {
        let p = &self.dynamics.params;
        self.window
            .metrics(t, &self.quadratures, p.I_L / (p.r_L * p.r_L))
    }
}

fn param(values: &Values, vr: u32) -> f64 {
    values.real(vr)
}

/// The gear parameters as set.
pub fn gear_params(values: &Values) -> GearParams {
    GearParams {
        I_L: param(values, vr::I_L),
        r_L: param(values, vr::r_L),
        r_M: param(values, vr::r_M),
        K_star: param(values, vr::K_star),
        alpha: param(values, vr::alpha),
        epsilon: param(values, vr::epsilon),
        G: param(values, vr::G),
        C_LM: param(values, vr::C_LM),
        C: param(values, vr::C),
        B: param(values, vr::B),
        omega_S: param(values, vr::omega_S),
    }
}

/// The integration method the `solver` parameter asks for (checked against its range; the
/// gearbox's contract numbers them alike).
pub fn method(solver: i64) -> Method {
    match solver {
        0 => Method::Auto,
        1 => Method::Explicit,
        2 => Method::Implicit,
        other => unreachable!("solver = {other} is outside the contract's range"),
    }
}

impl Simulation {
    /// Checks the parameters against the contract's ranges and builds the initial state at t0 (docs/MODEL.md §1:
    /// ξ(0) = gap_start·G, ξ'(0) = xi_dot_start; in torque mode the shaft starts from the
    /// values of the inputs theta_M and omega_M, θ_M(0) = theta_M, ω_M(0) = omega_M, and
    /// τ_in ramps at `tau_in_rate`, the derivative fmi2SetRealInputDerivatives gave).
    /// The state carries the quadratures `carry` says.
    pub fn new(
        values: &Values,
        tau_in_rate: f64,
        t0: f64,
        rtol: f64,
        carry: Carry,
    ) -> FmiResult<Self> {
        contract::check_parameters(values)?;
        let params = gear_params(values);
        let f_exc = param(values, vr::f_exc);
        let a_rms = param(values, vr::A_rms);
        let omega_mean = param(values, vr::omega_mean);
        let gap_start = param(values, vr::gap_start);
        let xi_dot_start = param(values, vr::xi_dot_start);
        let I_M = param(values, vr::I_M);
        let stats_from = param(values, vr::stats_from);
        let shaft = Shaft {
            theta: param(values, vr::theta_M),
            omega: param(values, vr::omega_M),
            alpha: param(values, vr::alpha_M),
        };
        let drive = match values.integer(vr::excitation) {
            EXCITATION_INPUTS => Drive::Inputs(shaft),
            EXCITATION_SINE => Drive::Sine(Sine::new(a_rms, f_exc, omega_mean)),
            EXCITATION_TORQUE => Drive::Torque {
                tau: param(values, vr::tau_in),
                rate: tau_in_rate,
            },
            other => unreachable!("excitation = {other} is outside the contract's range"),
        };
        let method = method(values.integer(vr::solver));
        let dynamics = Dynamics::new(params);
        let xi = gap_start * params.G;
        // A negative stats_from opens no window: the kinematic state then carries none of its
        // quadratures, unless Model Exchange's contract has them as states. The torque mode
        // carries them always: its Jacobian's rows for them are not zero, so Radau IIA's
        // pivoting, and with it the trajectory's last bits, depends on them.
        let window = (stats_from >= 0.0).then_some(stats_from);
        let all = window.is_some() || carry == Carry::All;
        let gear = match drive {
            Drive::Torque { tau, rate } => {
                let ramp = TorqueRamp {
                    t0,
                    tau0: tau,
                    rate,
                };
                let head = [xi, xi_dot_start, shaft.theta, shaft.omega];
                let system = TorqueRattle::new(dynamics, MainShaft { I_M }, ramp, xi);
                let solver = Solver::with_method(system.tolerance(rtol), method);
                Gear::Torque(Stepped::start(system, solver, &head, t0, window))
            }
            _ => {
                let excitation = Self::excitation_from(drive, t0);
                let head = [xi, xi_dot_start];
                // The bench's sine does not change between steps: communication points are
                // served from the dense output of natural steps. Inputs change at every step:
                // steps end on the communication points, where the new inputs apply.
                let ends = matches!(drive, Drive::Sine(_));
                if all {
                    let system = Rattle::new(dynamics, excitation, xi);
                    Gear::Kinematic(Stepped::kinematic(
                        system, rtol, method, ends, &head, t0, window,
                    ))
                } else {
                    let system = LeanRattle::new(dynamics, excitation, xi);
                    Gear::KinematicLean(Stepped::kinematic(
                        system, rtol, method, ends, &head, t0, window,
                    ))
                }
            }
        };
        Ok(Simulation {
            gear,
            t: t0,
            drive,
            journal: Journal::default(),
        })
    }

    /// The imposed motion of the shaft for a kinematic drive.
    fn excitation_from(drive: Drive, t: f64) -> Excitation {
        match drive {
            Drive::Sine(s) => Excitation::Sine(s),
            Drive::Inputs(shaft) => Excitation::Polynomial(Polynomial {
                t0: t,
                at_t0: shaft,
            }),
            Drive::Torque { .. } => unreachable!("the torque mode has no imposed motion"),
        }
    }

    /// The state the outputs are computed from, now.
    pub(super) fn now(&self) -> Now<'_> {
        on_gear!(&self.gear, k => k.now())
    }

    /// The main shaft's motion now (in torque mode α_M follows from τ_in and the contact).
    pub fn shaft(&self) -> Shaft {
        on_gear!(&self.gear, k => k.system.shaft(self.t, &k.y))
    }

    /// Impacts counted so far.
    pub fn impacts(&self) -> Impacts {
        *self.now().impacts
    }

    /// The solver's work counters.
    pub fn stats(&self) -> Stats {
        *self.now().stats
    }

    /// True while Radau IIA steps.
    pub fn is_implicit(&self) -> bool {
        self.now().implicit
    }

    /// Step size the next internal step will try.
    pub fn proposed_step(&self) -> f64 {
        on_gear!(&self.gear, k => k.solver.proposed_step())
    }

    /// New input values for the main shaft (inputs mode). The loose gear does not move, so
    /// ξ and ξ' follow the shaft (ξ = r_L θ_L − r_M θ_M): reading them right after reflects
    /// the new inputs (direct feedthrough). In the other modes the inputs are not used.
    pub fn set_shaft(&mut self, shaft: Shaft) {
        if let Drive::Inputs(_) = self.drive {
            self.change(Input::Shaft(shaft));
        }
    }

    fn apply_shaft(&mut self, shaft: Shaft) {
        let Drive::Inputs(old) = self.drive else {
            unreachable!("inputs are applied in the inputs mode");
        };
        self.drive = Drive::Inputs(shaft);
        let (t, excitation) = (self.t, Self::excitation_from(self.drive, self.t));
        by_coupling!(&mut self.gear, kinematic k => k.move_shaft(t, old, shaft, excitation),
            torque _ => {})
    }

    /// New torque on the main shaft and its rate (torque mode; ignored otherwise). The state
    /// does not jump: only the shaft's acceleration, read at once as alpha_M_out, changes.
    pub fn set_torque(&mut self, tau: f64, rate: f64) {
        if let Drive::Torque { .. } = self.drive {
            self.change(Input::Torque { tau, rate });
        }
    }

    fn apply_torque(&mut self, tau: f64, rate: f64) {
        self.drive = Drive::Torque { tau, rate };
        let ramp = TorqueRamp {
            t0: self.t,
            tau0: tau,
            rate,
        };
        by_coupling!(&mut self.gear, kinematic _ => {}, torque k => {
            k.system.torque = ramp;
            k.solver.invalidate();
        })
    }

    /// Advances to t_end. On failure the simulation is left as it was.
    pub fn step_to(&mut self, t_end: f64) -> Result<(), SolverError> {
        self.step_until(t_end, false).map(|_| ())
    }

    /// The calls of `step_until` (not stopping at impacts) from each `from` to its `to` in
    /// `calls`, each continuing where the one before ends, as far as the solver serves them
    /// without stepping, F_contact read `reads` times at each end into a row of `out`: how
    /// many were taken. Only on the bench's sine: the other drives' inputs follow each step.
    pub fn serve_forces(
        &mut self,
        calls: impl Iterator<Item = (f64, f64)>,
        reads: usize,
        out: &mut [f64],
    ) -> usize {
        let mut calls = calls.peekable();
        let (Drive::Sine(_), Some(&(from, _))) = (self.drive, calls.peek()) else {
            return 0;
        };
        self.served(
            from,
            |sim| on_gear!(&mut sim.gear, k => k.serve_forces(&mut sim.t, from, calls, reads, out)),
        )
    }

    /// The value of a Real output read in co-simulation, computed now; None if `vr` is not a
    /// Real output (see [`Readout`]).
    #[inline]
    pub fn real_output(&self, vr: u32) -> Option<f64> {
        Readout::new(self, fmi2_shell::Interface::CoSimulation).real(vr)
    }

    /// First time derivative of a Real output (maxOutputDerivativeOrder = 1), from the
    /// equations of motion at the current state; None where the model has none to give.
    pub fn real_output_derivative(&self, vr: u32) -> Option<f64> {
        let now = self.now();
        let dynamics = now.dynamics;
        let p = &dynamics.params;
        let shaft = self.shaft();
        let (xi, xi_dot) = (now.xi, now.xi_dot);
        let loads = now.loads(&shaft);
        let force_rate = || {
            let slopes = dynamics.law.slopes(now.region, xi, xi_dot);
            slopes.d_xi * xi_dot + slopes.d_xi_dot * loads.xi_ddot
        };
        Some(match vr {
            vr::xi => xi_dot,
            vr::xi_dot => loads.xi_ddot,
            vr::theta_L => loads.omega_L,
            vr::omega_L => loads.alpha_L,
            vr::F_contact => force_rate(),
            vr::tau_M => p.r_M * force_rate(),
            vr::theta_M_out => shaft.omega,
            vr::omega_M_out => shaft.alpha,
            _ => return None,
        })
    }

    /// ∂output/∂input at the current state: how an output read right after new inputs moves
    /// with them (direct feedthrough). Zero for inputs the current excitation does not use.
    pub fn partial(&self, output: u32, input: u32) -> f64 {
        match self.drive {
            Drive::Inputs(_) => self.kinematic_partial(output, input),
            // Torque mode: τ_in moves only the shaft's acceleration at once,
            // α_M = (τ_in + τ_M) / I_M; the state (ξ, ξ', θ_M, ω_M) does not jump.
            Drive::Torque { .. } => match (output, input) {
                (vr::alpha_M_out, vr::tau_in) => {
                    by_coupling!(&self.gear, kinematic _ => 0.0, torque k => 1.0 / k.system.main.I_M)
                }
                _ => 0.0,
            },
            Drive::Sine(_) => 0.0,
        }
    }

    /// Inputs mode (docs/MODEL.md §3 with ξ = r_L θ_L − r_M θ_M at fixed θ_L). ∂τ_M/∂θ_M and
    /// ∂τ_M/∂ω_M are the coupling stiffness and damping a master sees.
    fn kinematic_partial(&self, output: u32, input: u32) -> f64 {
        let now = self.now();
        let p = &now.dynamics.params;
        let slopes = now.dynamics.law.slopes(now.region, now.xi, now.xi_dot);
        // ∂ξ/∂θ_M = −r_M and ∂ξ'/∂ω_M = −r_M; ∂F follows through the contact law.
        let d_force = match input {
            vr::theta_M => -p.r_M * slopes.d_xi,
            vr::omega_M => -p.r_M * slopes.d_xi_dot,
            _ => 0.0,
        };
        match (output, input) {
            (vr::xi, vr::theta_M) | (vr::xi_dot, vr::omega_M) => -p.r_M,
            (vr::theta_M_out, vr::theta_M)
            | (vr::omega_M_out, vr::omega_M)
            | (vr::alpha_M_out, vr::alpha_M) => 1.0,
            (vr::F_contact, _) => d_force,
            (vr::tau_M, _) => p.r_M * d_force,
            (vr::alpha_L, _) => -p.r_L / p.I_L * d_force,
            (vr::a_pitch_L, _) => -p.r_L * p.r_L / p.I_L * d_force,
            _ => 0.0,
        }
    }

    /// The value of an Integer output; None if `vr` is not an Integer output.
    pub fn integer_output(&self, vr: u32) -> Option<i64> {
        let now = self.now();
        let count = &now.impacts.count;
        Some(match vr {
            vr::contact => now.region.flank() as i64,
            vr::impacts_Fplus => count[0] as i64,
            vr::impacts_Fminus => count[1] as i64,
            vr::solver_method => {
                if now.implicit {
                    2
                } else {
                    1
                }
            }
            _ => return stat_integer(&now.metrics(self.t), vr),
        })
    }
}

/// GearRattle's changes in co-simulation: steps and new inputs.
impl Journaled<ENTRIES> for Simulation {
    type Copy = (Gear, f64, Drive);
    type Input = Input;

    fn journal(&mut self) -> &mut Journal<Self::Copy, Change<Input>, ENTRIES> {
        &mut self.journal
    }

    fn copy(&self) -> Self::Copy {
        (self.gear, self.t, self.drive)
    }

    fn restore(&mut self, copy: &Self::Copy) {
        (self.gear, self.t, self.drive) = *copy;
    }

    fn time(&mut self) -> &mut f64 {
        &mut self.t
    }

    fn advance(&mut self, t_end: f64, at_impact: bool) -> Result<f64, SolverError> {
        let stopped = on_gear!(&mut self.gear, k => k.advance(&mut self.t, t_end, at_impact)?);
        if !stopped {
            self.t = t_end;
        }
        let t = self.t;
        // The inputs continue along their extrapolation unless the master sets new ones.
        match &mut self.drive {
            Drive::Inputs(shaft) => by_coupling!(&self.gear,
                kinematic k => *shaft = k.system.excitation.at(t), torque _ => {}),
            Drive::Torque { tau, .. } => by_coupling!(&self.gear,
                kinematic _ => {}, torque k => *tau = k.system.torque.at(t)),
            Drive::Sine(_) => {}
        }
        Ok(t)
    }

    fn take(&mut self, input: Input) {
        match input {
            Input::Shaft(shaft) => self.apply_shaft(shaft),
            Input::Torque { tau, rate } => self.apply_torque(tau, rate),
        }
    }
}

/// A Real stat_* output from the window's figures; None if `vr` is none of them.
fn stat_real(m: &Metrics, vr: u32) -> Option<f64> {
    let [plus, minus] = &m.flanks;
    let per_second = |x: f64| if m.length > 0.0 { x / m.length } else { 0.0 };
    Some(match vr {
        vr::stat_window => m.length,
        vr::stat_impact_rate_Fplus => per_second(plus.impacts as f64),
        vr::stat_impact_rate_Fminus => per_second(minus.impacts as f64),
        vr::stat_run_mean_Fplus => plus.run_mean(),
        vr::stat_run_mean_Fminus => minus.run_mean(),
        vr::stat_v_mean_Fplus => plus.v_mean(),
        vr::stat_v_mean_Fminus => minus.v_mean(),
        vr::stat_v_rms_Fplus => plus.v_rms(),
        vr::stat_v_rms_Fminus => minus.v_rms(),
        vr::stat_v_max_Fplus => plus.v_max,
        vr::stat_v_max_Fminus => minus.v_max,
        vr::stat_E_impact_Fplus => m.impact_energy[0],
        vr::stat_E_impact_Fminus => m.impact_energy[1],
        vr::stat_rattle_power => per_second(m.impact_energy[0] + m.impact_energy[1]),
        vr::stat_a_rms => m.a_rms,
        vr::stat_a_peak => m.a_peak,
        vr::stat_F_std => m.F_std,
        vr::stat_contact_fraction => m.contact_fraction,
        vr::stat_P_contact => m.P_contact,
        vr::stat_P_lubricant => m.P_lubricant,
        _ => return None,
    })
}

/// An Integer stat_* output from the window's figures; None if `vr` is none of them.
fn stat_integer(m: &Metrics, vr: u32) -> Option<i64> {
    let [plus, minus] = &m.flanks;
    let (regime, side) = m.regime();
    Some(match vr {
        vr::stat_impacts_Fplus => plus.impacts as i64,
        vr::stat_impacts_Fminus => minus.impacts as i64,
        vr::stat_runs_Fplus => plus.runs as i64,
        vr::stat_runs_Fminus => minus.runs as i64,
        vr::stat_run_max_Fplus => plus.run_max as i64,
        vr::stat_run_max_Fminus => minus.run_max as i64,
        vr::stat_regime => regime,
        vr::stat_side => side,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// S1 over 0.2 s in steps of 1 ms, in the sine and the inputs modes (held inputs), with
    /// the automatic choice and with Radau IIA throughout: a run without a window (the state
    /// without the window's quadratures) and one whose window opens after its end (every
    /// quadrature carried) give the same ξ, ξ', impacts, solver counters and energies, to the
    /// last bit.
    #[test]
    fn a_run_without_window_steps_the_same_trajectory() {
        let run = |(excitation, solver): (i64, i64), stats_from: f64| {
            let mut values = Values::start(crate::contract::VARIABLES);
            values.set_integer(vr::excitation, excitation);
            values.set_integer(vr::solver, solver);
            values.set_real(vr::omega_M, 30.0);
            values.set_real(vr::stats_from, stats_from);
            let mut sim = Simulation::new(&values, 0.0, 0.0, 1e-6, Carry::Asked).unwrap();
            for k in 1..=200 {
                sim.step_to(k as f64 * 1e-3).unwrap();
            }
            let outputs = [
                vr::xi,
                vr::xi_dot,
                vr::E_contact,
                vr::E_lubricant,
                vr::solver_steps,
                vr::solver_rhs,
            ]
            .map(|v| sim.real_output(v).unwrap().to_bits());
            let lean = matches!(sim.gear, Gear::KinematicLean(_));
            (lean, outputs, sim.impacts().count)
        };
        for case in [
            (EXCITATION_SINE, 0),
            (EXCITATION_INPUTS, 0),
            (EXCITATION_SINE, 2),
        ] {
            let (lean, outputs, impacts) = run(case, -1.0);
            let (all, outputs_all, impacts_all) = run(case, 1.0);
            assert!(lean && !all, "{case:?}");
            assert!(impacts[0] + impacts[1] > 0, "{case:?}: {impacts:?}");
            assert_eq!((outputs, impacts), (outputs_all, impacts_all), "{case:?}");
        }
    }

    /// The window at 0.03 s and a master stepping 0.029 + 1e-3 (one ulp past it), or at two
    /// ulps past that end: it opens within the resolution of time of the step's end, so it
    /// opens there. In each mode the steps succeed, ended at each impact too (FMI 3.0's early
    /// return), and every stat_* output equals that of the run whose window opens on the
    /// communication point, to the last bit, with impacts counted in the window.
    #[test]
    fn a_window_within_rounding_of_a_step_end_opens_there() {
        use fmi2_shell::contract::Kind;
        let ulps = |x: f64, n: i64| f64::from_bits((x.to_bits() as i64 + n) as u64);
        let t_end = 0.029 + 1e-3;
        let run = |(excitation, solver): (i64, i64), stats_from: f64, at_impact: bool| {
            let mut values = Values::start(crate::contract::VARIABLES);
            // The bench's sine motion as inputs, or as the torque that gives it a shaft too
            // heavy for the contact to move.
            let sine = Sine::new(
                values.real(vr::A_rms),
                values.real(vr::f_exc),
                values.real(vr::omega_mean),
            );
            let I_M = 10.0;
            let start = sine.at(0.0);
            values.set_integer(vr::excitation, excitation);
            values.set_integer(vr::solver, solver);
            values.set_real(vr::I_M, I_M);
            values.set_real(vr::theta_M, start.theta);
            values.set_real(vr::omega_M, start.omega);
            values.set_real(vr::stats_from, stats_from);
            let mut sim = Simulation::new(&values, 0.0, 0.0, 1e-6, Carry::Asked).unwrap();
            let points = (0..20).map(|k| k as f64 * 1e-3);
            for t in points.chain((0..40).map(|k| 0.02 + k as f64 * 1e-3)) {
                let h = 1e-3;
                // From the master's communication point, as the instance steps.
                sim.t = t;
                let (now, then) = (sine.at(t).alpha, sine.at(t + h).alpha);
                sim.set_shaft(sine.at(t));
                sim.set_torque(I_M * now, I_M * (then - now) / h);
                while sim.step_until(t + h, at_impact).unwrap() < t + h {}
            }
            let now = sim.now();
            let m = now.metrics(sim.t);
            let stats = crate::contract::VARIABLES
                .iter()
                .filter(|v| v.name.starts_with("stat_"))
                .map(|v| match v.kind {
                    Kind::Real => stat_real(&m, v.vr).unwrap().to_bits(),
                    _ => stat_integer(&m, v.vr).unwrap() as u64,
                })
                .collect::<Vec<_>>();
            (stats, m.flanks[0].impacts + m.flanks[1].impacts, m.length)
        };
        for case in [
            (EXCITATION_INPUTS, 0),
            (EXCITATION_INPUTS, 2),
            (EXCITATION_SINE, 0),
            (EXCITATION_SINE, 2),
            (EXCITATION_TORQUE, 0),
        ] {
            for at_impact in [false, true] {
                let on_the_point = run(case, t_end, at_impact);
                let (_, impacts, length) = on_the_point;
                assert!(impacts > 0, "{case:?}: {impacts}");
                assert_eq!(length, 0.06 - t_end, "{case:?}");
                for from in [0.03, ulps(t_end, 2)] {
                    assert_eq!(run(case, from, at_impact), on_the_point, "{case:?} {from}");
                }
            }
        }
    }

    /// A step that fails leaves the simulation as it was, solver and all (compared whole),
    /// after more steps than a journal records, with new inputs among them and the
    /// statistics window opening: its journal replays them. The step fails on its first attempt, below the
    /// resolution of time, after the solver has evaluated the derivative there.
    #[test]
    fn a_failed_step_leaves_the_simulation_as_it_was() {
        for (excitation, solver) in [
            (EXCITATION_INPUTS, 0),
            (EXCITATION_INPUTS, 2),
            (EXCITATION_TORQUE, 0),
        ] {
            let mut values = Values::start(crate::contract::VARIABLES);
            values.set_integer(vr::excitation, excitation);
            values.set_integer(vr::solver, solver);
            values.set_real(vr::omega_M, 30.0);
            values.set_real(vr::tau_in, 0.5);
            values.set_real(vr::stats_from, 2e-3);
            let mut sim = Simulation::new(&values, 0.0, 0.0, 1e-6, Carry::Asked).unwrap();
            let steps = ENTRIES + ENTRIES / 2;
            for k in 1..=steps {
                sim.step_to(k as f64 * 1e-4).unwrap();
                // New inputs now and then (each mode takes its own).
                if k % 7 == 0 {
                    let shaft = sim.shaft();
                    sim.set_shaft(Shaft {
                        omega: shaft.omega + 0.1,
                        ..shaft
                    });
                    sim.set_torque(0.5 + k as f64 * 1e-3, 2.0);
                }
            }
            assert!(!sim.journal.is_empty() && sim.journal.len() < steps / 2);
            let before = sim;
            let t = sim.t;
            assert!(sim.step_to(t + 4.0 * f64::EPSILON * t).is_err());
            assert_eq!(sim, before, "{excitation}, {solver}");
            assert_eq!(sim.stats(), before.stats());
            // And it goes on as if the failed step had not been asked for.
            let mut unfailed = before;
            for k in steps + 1..=steps + 20 {
                sim.step_to(k as f64 * 1e-4).unwrap();
                unfailed.step_to(k as f64 * 1e-4).unwrap();
            }
            assert_eq!(sim, unfailed, "{excitation}, {solver}");
        }
    }
}
