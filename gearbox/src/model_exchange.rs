//! Model Exchange: the gearbox as continuous states, derivatives and event indicators for
//! the importer's solver, on the same [`Simulation`] (its gearbox, stage, regions, counters
//! and statistics windows) as co-simulation, whose own solver then stays idle.
//!
//! States (the contract's `STATES`): φ, the input side's speed ω_I (the model integrates
//! φ' = ω_F − ω_I: ω_I = ω_F(t) − φ'), the flywheel's θ_F and ω_F under an engine ramp (their
//! derivatives ω_F and α_F(t): docs/GEARBOX.md §4 has no closed form for them; at a steady
//! speed or driven by inputs the two are unused, 0), the box's energies E_damper,
//! E_input_drag and W_flywheel, then each gear slot's ξ, ξ', its energies E_contact and
//! E_lubricant and its statistics window's integrals ∫a² dt, ∫F dt, ∫F² dt (a slot beyond
//! n_gears is unused, 0). The window's integrals stay 0 until the window opens (a time event
//! at stats_from), as co-simulation starts them there; the window's figures are the
//! quadratures' increase since, so every statistic is the importer's integral. An unused
//! state's derivative is 0. Event indicators: per gear slot the contact law's edges ξ + ε, ξ,
//! ξ − G, ξ − G − ε and ξ' in the gap (its turning points), then the damper's stage edges
//! φ − φ_1 and φ + φ_1. The derivatives take the formulas of the pieces the states are in;
//! at an event the gearbox's stage and regions follow them across the edges (an onset counts
//! an impact and enters the statistics), as the co-simulation's solver does.
#![allow(non_snake_case)]

use crate::contract::{EVENT_INDICATORS, STATES};
use crate::simulation::{Run, Simulation};
use crate::windowed::{self, integrals, integrands};
use fmi2_shell::Continuous;
use gear_rattle::gearbox::{
    Drive, E_DAMPER, E_INPUT_DRAG, Gearbox, MAX_GEARS, PHI, PHI_DOT, State, THETA_F, W_FLYWHEEL,
    e_contact, e_lubricant, omega_F, xi, xi_dot,
};
use gear_rattle::integrator::Piecewise;
use gear_rattle::physics::{Polynomial, Region, Shaft};
use gear_rattle::rattle::window::quadrature;

/// Number of continuous states.
pub const NX: usize = X_GEARS + GEAR_STATES * MAX_GEARS;
const _: () = assert!(STATES.len() == NX);
/// Number of event indicators.
pub const NZ: usize = EVENT_INDICATORS;
const _: () = assert!(NZ == 5 * MAX_GEARS + 2);

/// State x's components: the box's, then each gear slot's block.
const X_PHI: usize = 0;
const X_OMEGA_I: usize = 1;
const X_THETA_F: usize = 2;
const X_OMEGA_F: usize = 3;
const X_ENERGIES: usize = 4;
const X_GEARS: usize = 7;
/// The gearbox's state components behind the box's energies.
const ENERGIES: [usize; 3] = [E_DAMPER, E_INPUT_DRAG, W_FLYWHEEL];
/// A gear's block: ξ, ξ', E_contact, E_lubricant, then its window's three integrals.
const GEAR_STATES: usize = 7;
const INTEGRALS: usize = 4;
const fn x_gear(i: usize) -> usize {
    X_GEARS + GEAR_STATES * i
}
/// The gearbox's state components of gear i's block before its window's integrals.
const fn gear_components(i: usize) -> [usize; INTEGRALS] {
    [xi(i), xi_dot(i), e_contact(i), e_lubricant(i)]
}
const _: () = assert!(INTEGRALS + 3 == GEAR_STATES && quadrature::COUNT - quadrature::A2 == 3);

impl Continuous for Simulation {
    type States = [f64; NX];
    type Indicators = [f64; NZ];

    /// The continuous states x.
    fn continuous_states(&self) -> [f64; NX] {
        let (g, y) = self.gearbox();
        let mut x = [0.0; NX];
        if !matches!(g.drive, Drive::InputSide(_)) {
            x[X_PHI] = y[PHI];
            x[X_OMEGA_I] = g.flywheel_at(self.t, &y).omega - y[PHI_DOT];
        }
        if g.integrates_flywheel() {
            (x[X_THETA_F], x[X_OMEGA_F]) = (y[THETA_F], y[omega_F(g.n_gears())]);
        }
        for (x, c) in x[X_ENERGIES..X_GEARS].iter_mut().zip(ENERGIES) {
            *x = y[c];
        }
        for i in 0..g.n_gears() {
            let block = &mut x[x_gear(i)..x_gear(i + 1)];
            for (x, c) in block.iter_mut().zip(gear_components(i)) {
                *x = y[c];
            }
            if let Some((_, q)) = self.window(i) {
                block[INTEGRALS..].copy_from_slice(&q[quadrature::A2..]);
            }
        }
        x
    }

    /// Takes the importer's states x (the unused ones ignored): φ' follows from ω_I and the
    /// flywheel's speed now, which under a ramp is the state ω_F.
    fn set_continuous_states(&mut self, x: &[f64; NX]) {
        self.change_state(|g, t, y| {
            if g.integrates_flywheel() {
                (y[THETA_F], y[omega_F(g.n_gears())]) = (x[X_THETA_F], x[X_OMEGA_F]);
            }
            if !matches!(g.drive, Drive::InputSide(_)) {
                y[PHI] = x[X_PHI];
                y[PHI_DOT] = g.flywheel_at(t, y).omega - x[X_OMEGA_I];
            }
            for (x, c) in x[X_ENERGIES..X_GEARS].iter().zip(ENERGIES) {
                y[c] = *x;
            }
            for i in 0..g.n_gears() {
                for (x, c) in x[x_gear(i)..].iter().zip(gear_components(i)) {
                    y[c] = *x;
                }
            }
        });
        if let Run::Windowed(k) = &mut self.run {
            for i in 0..k.system.inner.n_gears() {
                k.y[integrals(i)].copy_from_slice(&x[x_gear(i) + INTEGRALS..x_gear(i + 1)]);
            }
        }
    }

    /// dx/dt at the current time and states, with the formulas of the pieces they are in;
    /// the window's integrands once it is open.
    fn derivatives(&self) -> [f64; NX] {
        let (g, y) = self.settled();
        let l = g.loads(self.t, &y);
        let f = g.rhs_with(&l, &y);
        let mut dx = [0.0; NX];
        if !matches!(g.drive, Drive::InputSide(_)) {
            dx[X_PHI] = f[PHI];
            dx[X_OMEGA_I] = g.readout(self.t, &y).input.alpha_I;
        }
        if g.integrates_flywheel() {
            (dx[X_THETA_F], dx[X_OMEGA_F]) = (f[THETA_F], f[omega_F(g.n_gears())]);
        }
        for (dx, c) in dx[X_ENERGIES..X_GEARS].iter_mut().zip(ENERGIES) {
            *dx = f[c];
        }
        let open = matches!(self.run, Run::Windowed(_));
        for i in 0..g.n_gears() {
            let block = &mut dx[x_gear(i)..x_gear(i + 1)];
            for (dx, c) in block.iter_mut().zip(gear_components(i)) {
                *dx = f[c];
            }
            if open {
                block[INTEGRALS..].copy_from_slice(&integrands(&g.gears[i], &l.gears[i]));
            }
        }
        dx
    }

    /// Nominal magnitudes: φ on the scale of φ_1, ω_I and ω_F of 100 rad/s, θ_F of 100 rad
    /// (a second at idle), the box's energies of 1 J, each ξ of its backlash and ξ' of a
    /// backlash per millisecond, a gear's energies and integrals as GearRattle's.
    fn nominals(&self) -> [f64; NX] {
        let (g, _) = self.gearbox();
        let mut x = [1.0; NX];
        (x[X_PHI], x[X_OMEGA_I]) = (g.damper.params.phi_1, 100.0);
        (x[X_THETA_F], x[X_OMEGA_F]) = (100.0, 100.0);
        for (i, gear) in g.gears.iter().enumerate() {
            let G = gear.dynamics.params.G;
            x[x_gear(i)..x_gear(i + 1)].copy_from_slice(&[G, G * 1e3, 1e-3, 1e-2, 1e2, 1.0, 1e2]);
        }
        x
    }

    /// The event indicators (see the module's documentation); constant 1 for the slots of
    /// gears the box does not have, and for the damper when the input side is driven.
    fn event_indicators(&self) -> [f64; NZ] {
        let (g, y) = self.gearbox();
        let mut z = [1.0; NZ];
        for (i, gear) in g.gears[..g.n_gears()].iter().enumerate() {
            let (p, xi) = (&gear.dynamics.params, y[xi(i)]);
            let turning = if gear.region == Region::Gap {
                y[xi_dot(i)]
            } else {
                1.0
            };
            z[5 * i..5 * i + 5].copy_from_slice(&[
                xi + p.epsilon,
                xi,
                xi - p.G,
                xi - p.G - p.epsilon,
                turning,
            ]);
        }
        if !matches!(g.drive, Drive::InputSide(_)) {
            let phi_1 = g.damper.params.phi_1;
            z[NZ - 2..].copy_from_slice(&[y[PHI] - phi_1, y[PHI] + phi_1]);
        }
        z
    }

    /// After an accepted step of the importer: each gear's |a| there for the window's peak.
    fn completed_integrator_step(&mut self) {
        let t = self.t;
        if let Run::Windowed(k) = &mut self.run {
            let y = windowed::head(&k.y);
            k.system.sample_accelerations(t, &y);
        }
    }
}

impl Simulation {
    /// The gearbox at the current states, with the stage and regions they are in (a copy:
    /// the kept ones change at events only).
    pub(crate) fn settled(&self) -> (Gearbox, State) {
        let (g, y) = self.gearbox();
        let mut g = *g;
        g.settle(self.t, &y);
        (g, y)
    }

    /// The importer's time: the states x stay as set (φ' follows the flywheel's speed).
    pub fn set_time(&mut self, t: f64) {
        let x = self.continuous_states();
        self.t = t;
        self.set_continuous_states(&x);
    }

    /// The drive's inputs as the importer sets them (excitation 0 or 2): unlike
    /// co-simulation's, the states x do not move.
    pub fn set_drive_inputs(&mut self, flywheel: Shaft, input_side: Shaft) {
        let x = self.continuous_states();
        self.change_state(|g, t, _| {
            g.drive = match g.drive {
                Drive::Flywheel(_) => Drive::Flywheel(Polynomial {
                    t0: t,
                    at_t0: flywheel,
                }),
                Drive::InputSide(_) => Drive::InputSide(Polynomial {
                    t0: t,
                    at_t0: input_side,
                }),
                engine => engine,
            };
        });
        self.set_continuous_states(&x);
    }

    /// Event mode: the stage and each gear's region follow the states across the edges they
    /// passed (an onset counts an impact, in the window too), and the statistics window
    /// opens when its time has come. Returns the next time event: the window's opening, if
    /// still ahead.
    pub fn update_discrete_states(&mut self) -> Option<f64> {
        let t = self.t;
        match &mut self.run {
            Run::Lean(k) => settle_past(&mut k.system, t, &k.y),
            Run::Windowed(k) => settle_past(&mut k.system, t, &k.y),
            Run::Independent(_) => unreachable!("Model Exchange steps the coupled box"),
        }
        if self.window_from <= self.t {
            self.open_window();
        }
        matches!(self.run, Run::Lean(_)).then_some(self.window_from)
    }
}

/// Moves every guard of `system` into the piece that holds it at (t, y). The importer's root
/// search may stop exactly on an edge: each guard is taken a few rounding errors further
/// along its rate, so that an edge reached on the way out is crossed now, and one just
/// crossed is not crossed back.
fn settle_past<S: Piecewise<N>, const N: usize>(system: &mut S, t: f64, y: &[f64; N]) {
    let mut probe = *y;
    for k in 0..system.guards() {
        let (c, rate) = S::guard(k);
        let (lo, hi) = system.piece(k);
        let scale = [probe[c], lo, hi]
            .iter()
            .filter(|v| v.is_finite())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        probe[c] += probe[rate].signum() * 8.0 * f64::EPSILON * scale;
    }
    system.settle(t, &probe);
}
