//! The gearbox on an imposed input side (excitation 2) in co-simulation: no gear acts on
//! another (docs/GEARBOX.md §3 with α_I imposed), so each loose gear is stepped as
//! GearRattle steps its one gear on an imposed main shaft ([`Stepped`] of a [`Rattle`], with
//! its own solver and step size: closed-form flight, Taylor steps in contact, DOPRI5 or
//! Radau IIA), its shaft the input side's motion times ρ_i. The [`Gearbox`] is kept beside
//! them, its gears' regions and impacts mirrored, for the readouts and the derivatives.
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

use gear_rattle::gearbox::{self, Drive, E_INPUT_DRAG, Gearbox, State, e_contact, e_lubricant};
use gear_rattle::gearbox::{xi, xi_dot};
use gear_rattle::instance::simulation::Stepped;
use gear_rattle::integrator::{Method, SolverError, Stats};
use gear_rattle::physics::{Excitation, Polynomial, Shaft};
use gear_rattle::rattle::window::{Quadratures, Window};
use gear_rattle::rattle::{self, GearPair, Rattle};

/// One loose gear as GearRattle's kinematic pair with its statistics window.
type Pair = Stepped<Rattle, { rattle::N }>;

/// The box's gears, each stepped on its own, and the box they belong to.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Independent {
    pub gearbox: Gearbox,
    pairs: Vec<Pair>,
    /// ∫ c_I ω_I² dt, the input side's drag energy (its ω_I is imposed: a quadrature of the
    /// extrapolation, exact for its linear ω_I).
    e_input_drag: f64,
}

fn imposed(g: &Gearbox) -> Polynomial {
    match g.drive {
        Drive::InputSide(p) => p,
        _ => unreachable!("the gears are stepped apart on an imposed input side"),
    }
}

/// Gear i's shaft: the input side's extrapolated motion times ρ_i (θ_M = ρ_i θ_I).
fn excitation(g: &Gearbox, i: usize) -> Excitation {
    let (p, rho) = (imposed(g), g.gears[i].rho);
    Excitation::Polynomial(Polynomial {
        t0: p.t0,
        at_t0: Shaft {
            theta: rho * p.at_t0.theta,
            omega: rho * p.at_t0.omega,
            alpha: rho * p.at_t0.alpha,
        },
    })
}

impl Independent {
    /// The gearbox at (t0, y) (its [`Drive::InputSide`]) with each gear's pair at ξ_i, ξ_i',
    /// its window opening at `window_from`.
    pub fn new(
        gearbox: Gearbox,
        y: &State,
        t0: f64,
        window_from: f64,
        rtol: f64,
        method: Method,
    ) -> Self {
        let pairs = (0..gearbox.n_gears())
            .map(|i| {
                let system =
                    Rattle::new(gearbox.gears[i].dynamics, excitation(&gearbox, i), y[xi(i)]);
                let head = [y[xi(i)], y[xi_dot(i)]];
                Stepped::kinematic(system, rtol, method, false, &head, t0, Some(window_from))
            })
            .collect();
        let mut run = Independent {
            gearbox,
            pairs,
            e_input_drag: 0.0,
        };
        run.mirror();
        run
    }

    /// The gearbox's state: each gear's ξ, ξ' and energies from its pair, the input side's
    /// drag energy (φ, φ' stay 0).
    pub fn state(&self) -> State {
        let mut y = [0.0; gearbox::N];
        for (i, k) in self.pairs.iter().enumerate() {
            (y[xi(i)], y[xi_dot(i)]) = (k.y[rattle::XI], k.y[rattle::XI_DOT]);
            (y[e_contact(i)], y[e_lubricant(i)]) =
                (k.y[rattle::E_CONTACT], k.y[rattle::E_LUBRICANT]);
        }
        y[E_INPUT_DRAG] = self.e_input_drag;
        y
    }

    /// Gear i's statistics window and its quadratures, once it is open (None for a gear the
    /// box does not have).
    pub fn window(&self, i: usize) -> Option<(&Window, Quadratures)> {
        let k = self.pairs.get(i).filter(|k| k.system.window.is_opened())?;
        Some((&k.system.window, Rattle::quadratures(&k.y)))
    }

    /// The gearbox's regions and impacts from the pairs'.
    fn mirror(&mut self) {
        for (gear, k) in self.gearbox.gears.iter_mut().zip(&self.pairs) {
            (gear.region, gear.impacts) = (k.system.region, k.system.impacts);
        }
    }

    /// Advances every gear from t0 to t_end; with `at_impact` all stop at the first impact of
    /// any gear, where its pair locates it. Returns the time they reached and whether it is an
    /// impact's. A failure leaves the gears where it failed (the simulation's journal puts
    /// them back).
    pub fn advance(
        &mut self,
        t0: f64,
        t_end: f64,
        at_impact: bool,
    ) -> Result<(f64, bool), SolverError> {
        let (reached, stopped) = self.advance_all(t0, t_end, at_impact)?;
        self.add_input_drag(t0, reached);
        self.mirror();
        Ok((reached, stopped))
    }

    /// Each pair in turn from t0 to the earliest stop so far; with `at_impact`, a pair that
    /// stops earlier takes the pairs before it back to their starts and on to its stop (none
    /// of them had an impact before it). Returns the time all reached and whether it is an
    /// impact's.
    fn advance_all(
        &mut self,
        t0: f64,
        t_end: f64,
        at_impact: bool,
    ) -> Result<(f64, bool), SolverError> {
        let starts = if at_impact {
            self.pairs.clone()
        } else {
            Vec::new()
        };
        let (mut stop, mut stopped) = (t_end, false);
        for i in 0..self.pairs.len() {
            let mut t = t0;
            if !self.pairs[i].advance(&mut t, stop, at_impact)? {
                continue;
            }
            if t < stop {
                for (k, start) in self.pairs[..i].iter_mut().zip(&starts) {
                    let mut back = t0;
                    *k = *start;
                    k.advance(&mut back, t, false)?;
                }
                stop = t;
            }
            stopped = true;
        }
        Ok((stop, stopped))
    }

    /// ∫ c_I ω_I² dt from t0 to t1 along the imposed ω_I, linear in t: Simpson's rule, exact.
    fn add_input_drag(&mut self, t0: f64, t1: f64) {
        let p = imposed(&self.gearbox);
        let (a, b) = (p.at(t0).omega, p.at(t1).omega);
        self.e_input_drag += self.gearbox.c_I * (t1 - t0) * (a * a + a * b + b * b) / 3.0;
    }

    /// New input-side motion at t: each gear's shaft moves to ρ_i times it as GearRattle's
    /// does ([`Stepped::move_shaft`]: ξ_i, ξ_i' follow, the loose gears do not move).
    pub fn set_input_side(&mut self, t: f64, shaft: Shaft) {
        self.gearbox.drive = Drive::InputSide(Polynomial {
            t0: t,
            at_t0: shaft,
        });
        for (i, k) in self.pairs.iter_mut().enumerate() {
            let excitation = excitation(&self.gearbox, i);
            let old = k.system.excitation.at(t);
            k.move_shaft(t, old, excitation.at(t), excitation);
        }
        self.mirror();
    }

    /// The output shaft's speed: each gear's carrier speed ω_S,i.
    pub fn set_output_speed(&mut self, omega_out: f64) {
        self.gearbox.set_output_speed(omega_out);
        for (gear, k) in self.gearbox.gears.iter().zip(&mut self.pairs) {
            k.system.dynamics.params.omega_S = gear.dynamics.params.omega_S;
            k.solver.invalidate();
        }
    }

    /// The pairs' work counters, summed.
    pub fn stats(&self) -> Stats {
        self.pairs.iter().fold(Stats::default(), |mut s, k| {
            s += k.solver.stats;
            s
        })
    }

    /// True while any pair steps with Radau IIA.
    pub fn is_implicit(&self) -> bool {
        self.pairs.iter().any(|k| k.solver.is_implicit())
    }

    /// The smallest step a pair proposes.
    pub fn proposed_step(&self) -> f64 {
        self.pairs
            .iter()
            .map(|k| k.solver.proposed_step())
            .fold(f64::INFINITY, f64::min)
    }
}
