//! Model Exchange: the gear pair as continuous states, derivatives and event indicators for
//! the importer's solver, on the same [`Simulation`] (its systems, regions, counters and
//! statistics window) as co-simulation, whose own solver then stays idle.
//!
//! States (the contract's `STATES`, in this order): ξ (the transmission error itself, so that
//! nothing is lost at idle speed over an hour), ω_L, the main shaft's θ_M and ω_M (torque
//! mode; otherwise unused and constant), then the quadratures of
//! [`crate::rattle::window::quadrature`] (dissipated energies, the shaft's work, ∫a², ∫F,
//! ∫F²). With ω_L as a state, ξ' = r_L ω_L − r_M ω_M needs only the shaft's speed: in the
//! inputs mode the derivatives read θ_M and ω_M as set (α_M is not needed), in the sine mode
//! the time, in the torque mode the shaft's own states.
//!
//! Event indicators: ξ + ε, ξ, ξ − G, ξ − G − ε, the edges of the contact law (docs/MODEL.md §2),
//! and ξ' in the gap (its turning points, where a touch that stays in a band shows).
//! The derivatives take the formula of the region ξ is in; at an event the gear pair's
//! region follows ξ across the edges, and an onset counts an impact, exactly as in
//! co-simulation.
#![allow(non_snake_case)]

mod jacobian;

pub use jacobian::{Jacobian, column};

use super::simulation::{Drive, Gear, Simulation, by_coupling, on_gear};
use crate::physics::{Dynamics, Excitation, Loads, MainShaft, Polynomial, Region, Shaft};
use crate::rattle::window::quadrature;
use crate::rattle::{GearPair, XI, XI_DOT, quadrature_rates, torque};
use fmi2_shell::Continuous;

/// Number of continuous states.
pub const NX: usize = 4 + quadrature::COUNT;
/// Number of event indicators.
pub const NZ: usize = 5;

/// What the derivatives are computed from at the current time and states.
pub(super) struct Point<'a> {
    pub dynamics: &'a Dynamics,
    /// The region ξ is in, whose formula the derivatives take.
    pub region: Region,
    pub xi: f64,
    pub xi_dot: f64,
    pub loads: Loads,
    /// The main shaft's motion (torque mode: with the acceleration the contact gives it).
    pub shaft: Shaft,
    pub shaft_from: ShaftFrom,
}

/// Where the main shaft's angle and speed come from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum ShaftFrom {
    /// The sine mode: functions of time.
    Time,
    /// The inputs mode: the inputs theta_M and omega_M.
    Inputs,
    /// The torque mode: the states x_theta_M and x_omega_M of a shaft of this inertia.
    States(MainShaft),
}

/// Nominal magnitudes of the states, for the importer's error weights: ξ on the scale of
/// the backlash, speeds of 10 rad/s, a shaft angle of 1 rad, the energies and integrals on
/// the scale of a second of the paper's bench.
fn nominals(G: f64) -> [f64; NX] {
    [G, 10.0, 1.0, 10.0, 1e-3, 1e-2, 1e-2, 1e2, 1.0, 1e2]
}

impl Continuous for Simulation {
    type States = [f64; NX];
    type Indicators = [f64; NZ];

    /// The continuous states x.
    fn continuous_states(&self) -> [f64; NX] {
        let now = self.now();
        let mut x = [0.0; NX];
        (x[0], x[1]) = (now.xi, now.loads(&self.shaft()).omega_L);
        by_coupling!(&self.gear, kinematic _ => {},
            torque k => (x[2], x[3]) = (k.y[torque::THETA_M], k.y[torque::OMEGA_M]));
        x[4..].copy_from_slice(&now.quadratures);
        x
    }

    /// Takes the importer's states x: ξ' follows from ω_L and the shaft's speed now. (Model
    /// Exchange's simulation carries every quadrature, [`Carry::All`](super::Carry::All).)
    fn set_continuous_states(&mut self, x: &[f64; NX]) {
        let t = self.t;
        by_coupling!(&mut self.gear, kinematic k => {
            let p = &k.system.dynamics.params;
            let omega_M = k.system.excitation.at(t).omega;
            k.y[XI] = x[0];
            k.y[XI_DOT] = p.r_L * x[1] - p.r_M * omega_M;
            let q = k.y.len() - crate::rattle::E_CONTACT;
            k.y[crate::rattle::E_CONTACT..].copy_from_slice(&x[4..4 + q]);
        }, torque k => {
            let p = &k.system.dynamics.params;
            k.y[XI] = x[0];
            k.y[XI_DOT] = p.r_L * x[1] - p.r_M * x[3];
            (k.y[torque::THETA_M], k.y[torque::OMEGA_M]) = (x[2], x[3]);
            let q = k.y.len() - torque::E_CONTACT;
            k.y[torque::E_CONTACT..].copy_from_slice(&x[4..4 + q]);
        })
    }

    /// dx/dt at the current time and states, with the formula of the region ξ is in: the
    /// contact force is continuous with a continuous slope across the edges (docs/MODEL.md §2),
    /// so the importer's solver sees a smooth enough right-hand side wherever its trial
    /// points fall, also past an edge it has not located yet.
    fn derivatives(&self) -> [f64; NX] {
        let Point {
            dynamics,
            loads,
            shaft,
            shaft_from,
            ..
        } = self.point();
        let p = &dynamics.params;
        let mut dx = [0.0; NX];
        let xi_dot = p.r_L * loads.omega_L - p.r_M * shaft.omega;
        (dx[0], dx[1]) = (xi_dot, loads.alpha_L);
        if let ShaftFrom::States(_) = shaft_from {
            (dx[2], dx[3]) = (shaft.omega, shaft.alpha);
        }
        dx[4..].copy_from_slice(&quadrature_rates(p, &loads, xi_dot, shaft.omega));
        dx
    }

    /// The event indicators: ξ against the contact law's four edges, and in the gap ξ' (1
    /// elsewhere). A touch that enters a band and leaves it within one of the importer's
    /// steps changes no edge's sign at the step's ends, but has a turning point in the band:
    /// the event there finds ξ past the edge and counts the impact.
    fn event_indicators(&self) -> [f64; NZ] {
        let now = self.now();
        let (xi, p) = (now.xi, &now.dynamics.params);
        let turning = if now.region == Region::Gap {
            now.xi_dot
        } else {
            1.0
        };
        [xi + p.epsilon, xi, xi - p.G, xi - p.G - p.epsilon, turning]
    }

    fn nominals(&self) -> [f64; NX] {
        nominals(self.now().dynamics.params.G)
    }

    /// After an accepted step of the importer: |a| there for the statistics' peak.
    fn completed_integrator_step(&mut self) {
        let t = self.t;
        on_gear!(&mut self.gear, k => k.sample_acceleration(t))
    }
}

impl Simulation {
    /// The right-hand side's operating point at the current time and states, with the
    /// formula of the region ξ is in.
    pub(super) fn point(&self) -> Point<'_> {
        let now = self.now();
        let (dynamics, xi, xi_dot) = (now.dynamics, now.xi, now.xi_dot);
        let region = dynamics.law.classify(xi);
        let (loads, shaft, shaft_from) = by_coupling!(&self.gear, kinematic k => {
            let shaft = k.system.excitation.at(self.t);
            let shaft_from = match self.drive {
                Drive::Inputs(_) => ShaftFrom::Inputs,
                _ => ShaftFrom::Time,
            };
            (
                dynamics.loads(region, xi, xi_dot, &shaft),
                shaft,
                shaft_from,
            )
        }, torque k => {
            let mut system = k.system;
            system.region = region;
            let (loads, shaft) = system.loads(self.t, &k.y);
            (loads, shaft, ShaftFrom::States(k.system.main))
        });
        Point {
            dynamics,
            region,
            xi,
            xi_dot,
            loads,
            shaft,
            shaft_from,
        }
    }

    /// ∂ẋ/∂(x, u) and the outputs' partials at the current time and states
    /// (fmi2GetDirectionalDerivative; see [`Jacobian`]).
    pub fn jacobian(&self) -> Jacobian {
        let now = self.now();
        Jacobian::new(&self.point(), now.window.slopes(self.t, &now.quadratures))
    }

    /// The importer's time. In the inputs mode the shaft's inputs hold until set again. The
    /// states x stay as set: in the sine mode the shaft's speed moves with t, so ξ' is
    /// recomputed from ω_L. A time where the shaft's motion is not finite (where the sine's
    /// phase overflows) is refused with that motion, and nothing changes.
    pub fn set_time(&mut self, t: f64) -> Result<(), Shaft> {
        let (x, before) = (self.continuous_states(), self.t);
        self.t = t;
        self.hold_inputs();
        let shaft = self.shaft();
        if !(shaft.theta.is_finite() && shaft.omega.is_finite()) {
            self.t = before;
            self.hold_inputs();
            return Err(shaft);
        }
        self.set_continuous_states(&x);
        Ok(())
    }

    /// New shaft inputs (inputs mode) as the importer sets them: unlike co-simulation's
    /// [`Simulation::set_shaft`], the states x do not move (ξ and ω_L are the importer's), so
    /// ξ' follows the new ω_M.
    pub fn set_shaft_inputs(&mut self, shaft: Shaft) {
        if let Drive::Inputs(_) = self.drive {
            let x = self.continuous_states();
            self.drive = Drive::Inputs(shaft);
            self.hold_inputs();
            self.set_continuous_states(&x);
        }
    }

    fn hold_inputs(&mut self) {
        if let Drive::Inputs(shaft) = self.drive {
            let excitation = Excitation::Polynomial(Polynomial {
                t0: self.t,
                at_t0: Shaft {
                    alpha: 0.0,
                    ..shaft
                },
            });
            by_coupling!(&mut self.gear, kinematic k => k.system.excitation = excitation, torque _ => {});
        }
    }

    /// Event mode: the region follows ξ across the edges it passed (an onset counts an
    /// impact and enters the statistics) and the statistics window opens when its time has
    /// come. Returns the next time event: the window's opening, if still ahead.
    pub fn update_discrete_states(&mut self) -> Option<f64> {
        let t = self.t;
        on_gear!(&mut self.gear, k => k.update_discrete_states(t))
    }

    /// A Real output as Model Exchange reads it: the contact's loads, and the torque mode's
    /// shaft acceleration, in the region ξ is in, as the derivatives and the Jacobian take
    /// them (the region kept since the last event gives another force between an edge
    /// crossing and the importer's event there).
    pub fn model_exchange_output(&self, vr: u32) -> Option<f64> {
        super::simulation::Readout::new(self, fmi2_shell::Interface::ModelExchange).real(vr)
    }

    /// The Model Exchange variables that are not outputs: the states θ_M and ω_M of the
    /// torque mode, the quadratures W_shaft, ∫a², ∫F, ∫F², and the derivatives.
    pub fn model_exchange_local(&self, vr: u32) -> Option<f64> {
        use crate::contract::{DERIVATIVES, STATES};
        if let Some(i) = STATES.iter().position(|&s| s == vr) {
            return Some(self.continuous_states()[i]);
        }
        let i = DERIVATIVES.iter().position(|&d| d == vr)?;
        Some(self.derivatives()[i])
    }
}

impl<S: GearPair<N> + crate::integrator::Jacobian<N> + Copy, const N: usize>
    super::simulation::Stepped<S, N>
{
    fn update_discrete_states(&mut self, t: f64) -> Option<f64> {
        // The importer's root search may stop exactly on an edge: ξ is then taken a few
        // rounding errors further along ξ', so that an edge reached on the way out is crossed
        // now, and one just crossed is not crossed back.
        let mut probe = self.y;
        let (xi, xi_dot) = (probe[S::XI], probe[S::XI_DOT]);
        let (lo, hi) = self.system.piece(0);
        let scale = [xi, lo, hi]
            .iter()
            .filter(|v| v.is_finite())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        probe[S::XI] = xi + xi_dot.signum() * 8.0 * f64::EPSILON * scale;
        self.system.settle(t, &probe);
        let window = self.system.window();
        if !window.is_opened() && window.from <= t {
            self.open_window();
        }
        let window = self.system.window();
        (!window.is_opened() && window.from.is_finite()).then_some(window.from)
    }

    fn sample_acceleration(&mut self, t: f64) {
        let a = self.system.dynamics().params.r_L * self.system.loads_at(t, &self.y).alpha_L;
        self.system.window_mut().acceleration(t, a);
    }
}
