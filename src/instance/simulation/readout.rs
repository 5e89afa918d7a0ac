//! The Real outputs of a running simulation at its current time ([`Readout`]).

use std::cell::OnceCell;

use super::{Gear, Now, Simulation, on_gear, stat_real};
use crate::contract::vr;
use crate::physics::{Loads, Shaft};
use crate::rattle::window::{Metrics, quadrature};
use fmi2_shell::Interface;

/// The Real outputs of a simulation now, as an interface reads them: in Model Exchange the
/// loads in the region ξ is in, as the derivatives take them; in co-simulation those of the
/// region the integrator keeps. What several outputs share (the state's readout [`Now`], the
/// main shaft's motion, the loads, the statistics window's figures) is computed once, when an
/// output first needs it: one fmi2GetReal of many outputs pays for each once, one of ξ and ξ'
/// for none of them.
pub struct Readout<'a> {
    sim: &'a Simulation,
    interface: Interface,
    now: OnceCell<Now<'a>>,
    shaft: OnceCell<Shaft>,
    loads: OnceCell<Loads>,
    metrics: OnceCell<Metrics>,
}

impl<'a> Readout<'a> {
    pub fn new(sim: &'a Simulation, interface: Interface) -> Self {
        Readout {
            sim,
            interface,
            now: OnceCell::new(),
            shaft: OnceCell::new(),
            loads: OnceCell::new(),
            metrics: OnceCell::new(),
        }
    }

    /// A Real output; None if `vr` is none. ξ and ξ' straight from the state, inlined into
    /// the caller: a master reads them after every step.
    #[inline]
    pub fn real(&self, vr: u32) -> Option<f64> {
        match vr {
            vr::xi => Some(on_gear!(&self.sim.gear, k => k.xi()[0])),
            vr::xi_dot => Some(on_gear!(&self.sim.gear, k => k.xi()[1])),
            _ => self.computed(vr),
        }
    }

    /// The outputs computed from [`Now`].
    #[inline(never)]
    fn computed(&self, vr: u32) -> Option<f64> {
        let now = self.now();
        let dynamics = now.dynamics;
        Some(match vr {
            vr::theta_L => dynamics.theta_L(now.xi, self.shaft()),
            vr::omega_L => self.loads().omega_L,
            vr::alpha_L => self.loads().alpha_L,
            vr::a_pitch_L => dynamics.params.r_L * self.loads().alpha_L,
            vr::F_contact => self.loads().force.total(),
            vr::tau_M => dynamics.tau_M(self.loads()),
            vr::impact_speed => now.impacts.last_speed,
            vr::E_contact => now.quadratures[quadrature::E_CONTACT],
            vr::E_lubricant => now.quadratures[quadrature::E_LUBRICANT],
            vr::theta_M_out => self.shaft().theta,
            vr::omega_M_out => self.shaft().omega,
            vr::alpha_M_out => self.shaft().alpha,
            vr::solver_steps => now.stats.accepted as f64,
            vr::solver_rejected => now.stats.rejected as f64,
            vr::solver_rhs => now.stats.rhs_evals as f64,
            vr::solver_implicit_steps => now.stats.implicit_steps as f64,
            _ => {
                let metrics = self.metrics.get_or_init(|| now.metrics(self.sim.t));
                return stat_real(metrics, vr).or_else(|| self.sim.model_exchange_local(vr));
            }
        })
    }

    fn now(&self) -> &Now<'a> {
        self.now.get_or_init(|| self.sim.now())
    }

    /// The main shaft's motion (Model Exchange: with the loads, from one point).
    fn shaft(&self) -> &Shaft {
        self.shaft.get_or_init(|| match self.interface {
            Interface::CoSimulation => self.sim.shaft(),
            Interface::ModelExchange => {
                let (shaft, loads) = self.point();
                let _ = self.loads.set(loads);
                shaft
            }
        })
    }

    /// The loads on the gear pair (Model Exchange: with the shaft's motion, from one point).
    fn loads(&self) -> &Loads {
        self.loads.get_or_init(|| match self.interface {
            Interface::CoSimulation => self.now().loads(self.shaft()),
            Interface::ModelExchange => {
                let (shaft, loads) = self.point();
                let _ = self.shaft.set(shaft);
                loads
            }
        })
    }

    /// Model Exchange's point: the shaft's motion and the loads in the region ξ is in, both
    /// kept by whichever of [`shaft`](Self::shaft) and [`loads`](Self::loads) asks first.
    fn point(&self) -> (Shaft, Loads) {
        let point = self.sim.point();
        (point.shaft, point.loads)
    }
}
