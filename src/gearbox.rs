//! The gearbox in neutral (docs/GEARBOX.md): N ≤ 8 loose gears rattling against driving gears on
//! the input side, behind the two-stage clutch damper, driven by the flywheel. A
//! piecewise-smooth ODE for the integrator, built from the gear pair's physics (one
//! [`Dynamics`] and contact law per gear) with the damper's stages as one more guard.
//!
//! Relative coordinates (docs/GEARBOX.md §3): the damper's twist φ = θ_F − θ_I and its rate
//! φ' = ω_F − ω_I, and each gear's transmission error ξ_i = r_L,i θ_L,i − r_M,i ρ_i θ_I with
//! ξ_i'. The flywheel's motion is known (the engine's closed form, or the drivetrain's inputs
//! extrapolated over a step), so ω_I = ω_F − φ'. With ω_I' = α_I:
//!
//!   I_I α_I   = T_cl(φ, φ') + Σ_i ρ_i r_M,i F_i − c_I(T) ω_I
//!   φ''       = α_F − α_I
//!   ξ_i''     = r_L,i ω_L,i' − r_M,i ρ_i α_I,   ω_L,i = (ξ_i' + r_M,i ρ_i ω_I) / r_L,i
//!   I_L,i ω_L,i' = B_i − r_L,i F_i − C_i(T) (ω_L,i − ω_S,i)
//!
//! Guard 0 is φ among the damper's stage edges ±φ_1; guard 1 + i is ξ_i among gear i's band
//! edges. The error control covers φ, φ' and the n gears' ξ, ξ' only (and ω_F under a ramp):
//! the slots of the gears a box does not have stay in the state vector, idle, and cost
//! neither right-hand-side work nor error-norm terms.
#![allow(non_snake_case)]

mod jacobian;
pub mod params;
mod readout;

use serde::{Deserialize, Serialize};

use crate::integrator::{Crossing, Edge, Piecewise, System, Tolerance};
use crate::physics::{
    Damper, Dynamics, Engine, GearParams, Polynomial, Region, Shaft, Stage, contact::ContactForce,
};
use crate::rattle::{Impacts, LOCAL_SHARE, enter_region, scales};
pub use params::{GearboxParamError, GearboxParams, LooseGear, MAX_GEARS};
pub use readout::{BoxReadout, GearReadout, Readout};

/// The twist φ = θ_F − θ_I and its rate φ' = ω_F − ω_I.
pub const PHI: usize = 0;
pub const PHI_DOT: usize = 1;
/// ξ_i and ξ_i' of gear i (from 0).
pub const fn xi(i: usize) -> usize {
    2 + 2 * i
}
pub const fn xi_dot(i: usize) -> usize {
    3 + 2 * i
}
/// ω_F under an engine ramp, integrated from α_F: in the slot after the n gears', so that it
/// is formed and controlled with them; unused at a steady speed or when driven by inputs.
pub const fn omega_F(n: usize) -> usize {
    xi(n)
}
/// The quadratures, outside the error control, after the slots of [`MAX_GEARS`] gears and
/// one for ω_F: θ_F under a ramp; the energy the damper dissipates, the input side's drag
/// dissipates, the flywheel feeds in (∫ T_cl ω_F dt); then each gear's contact and
/// lubricant energies (docs/MODEL.md §3).
pub const THETA_F: usize = 3 + 2 * MAX_GEARS;
pub const E_DAMPER: usize = THETA_F + 1;
pub const E_INPUT_DRAG: usize = THETA_F + 2;
pub const W_FLYWHEEL: usize = THETA_F + 3;
pub const fn e_contact(i: usize) -> usize {
    W_FLYWHEEL + 1 + 2 * i
}
pub const fn e_lubricant(i: usize) -> usize {
    W_FLYWHEEL + 2 + 2 * i
}
pub const N: usize = e_contact(MAX_GEARS);

pub type State = [f64; N];

/// What drives the box.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Drive {
    /// The flywheel driven by the built-in engine (docs/GEARBOX.md §4).
    Engine(Engine),
    /// The flywheel's θ_F, ω_F, α_F from the drivetrain at a communication point,
    /// extrapolated over the step.
    Flywheel(Polynomial),
    /// The input side's θ_I, ω_I, α_I from the drivetrain, extrapolated alike: no damper, φ
    /// and φ' stay 0 (they still count in the error norm's mean, which reads the tolerance
    /// 2/(2 + 2n) looser).
    InputSide(Polynomial),
}

/// One loose gear as the box runs it: its pair's dynamics (drag at the oil's temperature),
/// the ratio ρ, its region and its impacts.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Gear {
    pub dynamics: Dynamics,
    pub rho: f64,
    /// ω_S = σ ω_out.
    pub sigma: f64,
    pub region: Region,
    pub impacts: Impacts,
}

/// The gearbox: n loose gears (slots up to [`MAX_GEARS`]), the input side, the damper in its
/// stage, the flywheel's drive. Plain data (copied for a rollback, serialized for a state).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Gearbox {
    n: usize,
    pub gears: [Gear; MAX_GEARS],
    pub damper: Damper,
    pub stage: Stage,
    /// I_I, and c_I at the oil's temperature.
    pub I_I: f64,
    pub c_I: f64,
    inv_I_I: f64,
    pub drive: Drive,
    /// The guard crossed last (for [`Piecewise::rough_start`]).
    last_crossed: usize,
}

/// The loads at one instant, shared by the right-hand side and the readouts.
pub struct Loads {
    pub flywheel: Shaft,
    /// θ_I, ω_I, α_I.
    pub input: Shaft,
    pub T_cl: f64,
    pub gears: [crate::physics::Loads; MAX_GEARS],
}

impl Gearbox {
    /// The box of valid `params` (see [`GearboxParams::validate`]) with the stage and
    /// regions of φ and the ξ_i in `state`, driven by `drive`.
    pub fn new(params: &GearboxParams, drive: Drive, state: &State) -> Self {
        let drag = params.oil.drag_factor(params.T_oil);
        let damper = Damper::new(params.damper);
        // The slots of gears the box does not have hold a gear that is never read.
        let mut gears = [Gear {
            dynamics: Dynamics::new(GearParams::paper()),
            rho: 1.0,
            sigma: 1.0,
            region: Region::Gap,
            impacts: Impacts::default(),
        }; MAX_GEARS];
        for (i, (slot, gear)) in gears.iter_mut().zip(&params.gears).enumerate() {
            let mut pair = gear.pair;
            pair.C *= drag;
            let dynamics = Dynamics::new(pair);
            *slot = Gear {
                region: dynamics.law.classify(state[xi(i)]),
                dynamics,
                rho: gear.rho,
                sigma: gear.sigma,
                impacts: Impacts::default(),
            };
        }
        Gearbox {
            n: params.gears.len(),
            gears,
            stage: damper.classify(state[PHI]),
            damper,
            I_I: params.I_I,
            c_I: params.c_I * drag,
            inv_I_I: 1.0 / params.I_I,
            drive,
            last_crossed: 0,
        }
    }

    /// docs/GEARBOX.md §6's start for `params`, once validated: φ = 0, the input side at the
    /// flywheel's speed, every loose gear at rigid meshing speed (ξ_i' = 0) mid-backlash;
    /// under an engine ramp ω_F(0) (and θ_F = 0) as states.
    pub fn start(params: &GearboxParams, drive: Drive) -> Result<(Self, State), GearboxParamError> {
        params.validate()?;
        let mut y = [0.0; N];
        for (i, gear) in params.gears.iter().enumerate() {
            y[xi(i)] = 0.5 * gear.pair.G;
        }
        let sys = Gearbox::new(params, drive, &y);
        if let Drive::Engine(e) = drive
            && !e.is_steady()
        {
            y[omega_F(sys.n)] = e.omega_start();
        }
        Ok((sys, y))
    }

    /// New flywheel motion from the drivetrain at t (θ_F, ω_F, α_F, extrapolated from there
    /// on). The input side does not move, so the twist follows the flywheel: φ and φ' change
    /// by the jumps of θ_F and ω_F (the ξ_i, relative to the input side, stay); the damper's
    /// stage settles where φ lands. Returns the edges crossed; the caller invalidates its
    /// solver.
    pub fn set_flywheel(&mut self, t: f64, y: &mut State, shaft: Shaft) -> usize {
        let old = self.flywheel_at(t, y);
        y[PHI] += shaft.theta - old.theta;
        y[PHI_DOT] += shaft.omega - old.omega;
        self.drive = Drive::Flywheel(Polynomial {
            t0: t,
            at_t0: shaft,
        });
        self.settle(t, y)
    }

    /// New input-side motion from the drivetrain at t ([`Drive::InputSide`]). The loose gears
    /// do not move, so each ξ_i = r_L,i θ_L,i − r_M,i ρ_i θ_I follows θ_I (and ξ_i' ω_I);
    /// their regions settle. Returns the edges crossed; the caller invalidates its solver.
    pub fn set_input_side(&mut self, t: f64, y: &mut State, shaft: Shaft) -> usize {
        let old = self.loads(t, y).input;
        for (i, gear) in self.gears[..self.n].iter().enumerate() {
            let lever = gear.dynamics.params.r_M * gear.rho;
            y[xi(i)] += lever * (old.theta - shaft.theta);
            y[xi_dot(i)] += lever * (old.omega - shaft.omega);
        }
        self.drive = Drive::InputSide(Polynomial {
            t0: t,
            at_t0: shaft,
        });
        self.settle(t, y)
    }

    /// The output shaft's speed ω_out: each loose gear's carrier turns at ω_S,i = σ_i ω_out.
    pub fn set_output_speed(&mut self, omega_out: f64) {
        for gear in &mut self.gears[..self.n] {
            gear.dynamics.params.omega_S = gear.sigma * omega_out;
        }
    }

    /// How many loose gears the box has.
    pub fn n_gears(&self) -> usize {
        self.n
    }

    /// Whether ω_F and θ_F are states (an engine ramp): ω_F in slot [`omega_F`] of the n
    /// gears, θ_F in [`THETA_F`].
    pub fn integrates_flywheel(&self) -> bool {
        matches!(self.drive, Drive::Engine(e) if !e.is_steady())
    }

    /// Error weights: φ on the scale of φ_1, φ' relative to itself with a floor of φ_1 per
    /// 10 ms; each gear's ξ, ξ' as GearRattle's ([`crate::rattle::Rattle::tolerance`]);
    /// ω_F under a ramp relative to itself. Each step gets [`LOCAL_SHARE`] of rtol.
    pub fn tolerance(&self, rtol: f64) -> Tolerance<N> {
        let rtol = rtol * LOCAL_SHARE;
        let mut atol = [0.0; N];
        let phi_1 = self.damper.params.phi_1;
        (atol[PHI], atol[PHI_DOT]) = (rtol * phi_1, rtol * phi_1 * 100.0);
        for (i, gear) in self.gears[..self.n].iter().enumerate() {
            let (xi_scale, xi_dot_scale) = scales(&gear.dynamics.params);
            (atol[xi(i)], atol[xi_dot(i)]) = (rtol * xi_scale, rtol * xi_dot_scale);
        }
        let mut controlled = xi(self.n);
        if self.integrates_flywheel() {
            atol[omega_F(self.n)] = rtol;
            controlled += 1;
        }
        Tolerance {
            rtol,
            atol,
            controlled,
        }
    }

    /// The flywheel's θ_F, ω_F, α_F at (t, y) (at rest when the input side is driven).
    #[inline]
    pub fn flywheel_at(&self, t: f64, y: &State) -> Shaft {
        match self.drive {
            Drive::Engine(e) => e.steady_at(t).unwrap_or(Shaft {
                theta: y[THETA_F],
                omega: y[omega_F(self.n)],
                alpha: e.alpha(t),
            }),
            Drive::Flywheel(p) => p.at(t),
            Drive::InputSide(_) => Shaft::default(),
        }
    }

    /// The input side's imposed motion ([`Drive::InputSide`]), if it is.
    fn imposed_input(&self) -> Option<&Polynomial> {
        match &self.drive {
            Drive::InputSide(p) => Some(p),
            _ => None,
        }
    }

    /// The loads at (t, y) with the current stage and regions (docs/GEARBOX.md §2, §3): the
    /// contact forces first, which with the damper give α_I, which drives every ξ_i''.
    #[inline]
    pub fn loads(&self, t: f64, y: &State) -> Loads {
        let flywheel = self.flywheel_at(t, y);
        let imposed = self.imposed_input().map(|p| p.at(t));
        let phi_dot = y[PHI_DOT];
        let omega_I = imposed.map_or(flywheel.omega - phi_dot, |s| s.omega);
        let T_cl = match imposed {
            Some(_) => 0.0,
            None => self.damper.torque(self.stage, y[PHI], phi_dot),
        };
        let gears = &self.gears[..self.n];
        let mut forces = [ContactForce::NONE; MAX_GEARS];
        let mut reaction = 0.0;
        for (i, gear) in gears.iter().enumerate() {
            forces[i] = gear.dynamics.law.force(gear.region, y[xi(i)], y[xi_dot(i)]);
            reaction += gear.rho * gear.dynamics.params.r_M * forces[i].total();
        }
        let alpha_I = imposed.map_or((T_cl + reaction - self.c_I * omega_I) * self.inv_I_I, |s| {
            s.alpha
        });
        let mut loads = [crate::physics::Loads {
            force: ContactForce::NONE,
            omega_L: 0.0,
            alpha_L: 0.0,
            xi_ddot: 0.0,
        }; MAX_GEARS];
        for (i, gear) in gears.iter().enumerate() {
            let driving = Shaft {
                theta: 0.0,
                omega: gear.rho * omega_I,
                alpha: gear.rho * alpha_I,
            };
            loads[i] = gear.dynamics.respond(forces[i], y[xi_dot(i)], &driving);
        }
        let input = Shaft {
            theta: imposed.map_or(flywheel.theta - y[PHI], |s| s.theta),
            omega: omega_I,
            alpha: alpha_I,
        };
        Loads {
            flywheel,
            input,
            T_cl,
            gears: loads,
        }
    }
}

impl System<N> for Gearbox {
    /// docs/GEARBOX.md §3 in relative coordinates, with the quadratures of the energy balance.
    #[inline]
    fn rhs(&self, t: f64, y: &State) -> State {
        self.rhs_with(&self.loads(t, y), y)
    }
}

impl Gearbox {
    /// The right-hand side at y from the loads `l` there (a caller that reads the loads too
    /// forms them once).
    #[inline]
    pub fn rhs_with(&self, l: &Loads, y: &State) -> State {
        let phi_dot = y[PHI_DOT];
        let mut f = [0.0; N];
        if self.imposed_input().is_none() {
            (f[PHI], f[PHI_DOT]) = (phi_dot, l.flywheel.alpha - l.input.alpha);
        }
        for (i, gear) in self.gears[..self.n].iter().enumerate() {
            let (g, v) = (&l.gears[i], y[xi_dot(i)]);
            let p = &gear.dynamics.params;
            let slip = g.omega_L - p.omega_S;
            (f[xi(i)], f[xi_dot(i)]) = (v, g.xi_ddot);
            f[e_contact(i)] = g.force.dissipative * v;
            f[e_lubricant(i)] = p.C * slip * slip;
        }
        if self.integrates_flywheel() {
            (f[omega_F(self.n)], f[THETA_F]) = (l.flywheel.alpha, l.flywheel.omega);
        }
        f[E_DAMPER] = self.damper.dissipative(self.stage, phi_dot) * phi_dot;
        f[E_INPUT_DRAG] = self.c_I * l.input.omega * l.input.omega;
        f[W_FLYWHEEL] = l.T_cl * l.flywheel.omega;
        f
    }
}

impl Piecewise<N> for Gearbox {
    #[inline]
    fn guards(&self) -> usize {
        1 + self.n
    }

    /// Guard 0: φ with φ'; guard 1 + i: ξ_i with ξ_i'.
    #[inline]
    fn guard(k: usize) -> (usize, usize) {
        (2 * k, 2 * k + 1)
    }

    #[inline]
    fn piece(&self, k: usize) -> (f64, f64) {
        match k {
            0 => self.damper.bounds(self.stage),
            _ => {
                let gear = &self.gears[k - 1];
                gear.dynamics.law.bounds(gear.region)
            }
        }
    }

    /// The damper's next stage, or gear i's next region with its impact counted.
    fn cross(&mut self, at: Crossing, _t: f64, y: &State) {
        self.last_crossed = at.guard;
        if at.guard == 0 {
            self.stage = match at.edge {
                Edge::Lower => self.damper.below(self.stage),
                Edge::Upper => self.damper.above(self.stage),
            };
            return;
        }
        let i = at.guard - 1;
        let gear = &mut self.gears[i];
        gear.region = enter_region(
            &gear.dynamics.law,
            gear.region,
            &mut gear.impacts,
            at.edge,
            y[xi_dot(i)],
        )
        .0;
    }

    fn rough_start(&self) -> bool {
        self.last_crossed > 0 && {
            let gear = &self.gears[self.last_crossed - 1];
            gear.dynamics.law.rough_at_onset(gear.region)
        }
    }
}
