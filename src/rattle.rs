//! The rattling gear as a piecewise-smooth ODE for the integrator: the state layout, the
//! right-hand side (MODEL.md §3 plus the dissipated energies and the shaft's work as
//! quadratures), the region as the current piece, and the impact counters (MODEL.md §1: an
//! impact is ξ leaving the gap, across 0 downwards on F+ or G upwards on F−). [`torque`] is
//! the same gear pair with the main shaft an inertia driven by a torque (torque mode).
#![allow(non_snake_case)]

pub mod torque;

use serde::{Deserialize, Serialize};

use crate::integrator::{Edge, Piecewise, System, Tolerance};
use crate::physics::{Dynamics, Excitation, GearParams, Region, Shaft};

/// Components of the state vector.
pub const XI: usize = 0;
pub const XI_DOT: usize = 1;
/// ∫ F_c ξ' dt: energy dissipated in the contact damping [J].
pub const E_CONTACT: usize = 2;
/// ∫ C (ω_L − ω_S)² dt: energy dissipated by the lubricant [J].
pub const E_LUBRICANT: usize = 3;
/// ∫ −τ_M ω_M dt: work the main shaft feeds into the loose gear [J].
pub const W_SHAFT: usize = 4;
pub const N: usize = 5;

pub type State = [f64; N];

/// Impacts counted so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Impacts {
    /// Contact onsets on flank F+ and F−.
    pub count: [u64; 2],
    /// |ξ'| at the last onset [m/s].
    pub last_speed: f64,
}

/// The gear pair, the region it is in, and what drives the main shaft.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rattle {
    pub dynamics: Dynamics,
    pub region: Region,
    pub excitation: Excitation,
    pub impacts: Impacts,
}

impl Rattle {
    pub fn new(dynamics: Dynamics, excitation: Excitation, xi: f64) -> Self {
        Rattle {
            region: dynamics.law.classify(xi),
            dynamics,
            excitation,
            impacts: Impacts::default(),
        }
    }

    /// Error weights: ξ on the scale of G; ξ' relative to itself, with a floor of G per
    /// millisecond (or G times the contact frequency, if lower). An error δ in ξ' moves ξ by
    /// δ·G/|ξ'| over a flight across the gap, so ξ' must be held to rtol·|ξ'|, not to the
    /// contact's speed scale: with hard contacts (K* = 1e10) that looser floor let ξ drift by
    /// 100 rtol per flight. The energies are quadratures outside the error control.
    pub fn tolerance(&self, rtol: f64) -> Tolerance<N> {
        let (xi_scale, xi_dot_scale) = scales(&self.dynamics.params);
        Tolerance {
            rtol,
            atol: [rtol * xi_scale, rtol * xi_dot_scale, 0.0, 0.0, 0.0],
            controlled: 2,
        }
    }
}

/// What the co-simulation reads from the gear pair whatever drives its main shaft: ξ and ξ'
/// are the components `GUARD` and `RATE`; the dissipated energies sit at `E_CONTACT` and
/// `E_LUBRICANT`.
pub trait GearPair<const N: usize>: Piecewise<N> {
    const E_CONTACT: usize;
    const E_LUBRICANT: usize;
    fn dynamics(&self) -> &Dynamics;
    fn region(&self) -> Region;
    fn impacts(&self) -> &Impacts;
    /// θ_M, ω_M and a_M of the main shaft at (t, y).
    fn shaft(&self, t: f64, y: &[f64; N]) -> Shaft;
}

impl GearPair<N> for Rattle {
    const E_CONTACT: usize = E_CONTACT;
    const E_LUBRICANT: usize = E_LUBRICANT;
    fn dynamics(&self) -> &Dynamics {
        &self.dynamics
    }
    fn region(&self) -> Region {
        self.region
    }
    fn impacts(&self) -> &Impacts {
        &self.impacts
    }
    fn shaft(&self, t: f64, _y: &State) -> Shaft {
        self.excitation.at(t)
    }
}

/// Scales of ξ and ξ' for the error weights (see [`Rattle::tolerance`]).
pub(crate) fn scales(p: &GearParams) -> (f64, f64) {
    const FLIGHT_RATE: f64 = 1e3;
    (p.G, p.G * p.contact_frequency().min(FLIGHT_RATE))
}

/// The region entered through `edge`; an onset counted in `impacts` when it leaves the gap.
pub(crate) fn cross_edge(
    dynamics: &Dynamics,
    region: Region,
    impacts: &mut Impacts,
    edge: Edge,
    xi_dot: f64,
) -> Region {
    let law = &dynamics.law;
    if region == Region::Gap {
        let flank = if edge == Edge::Lower { 0 } else { 1 };
        impacts.count[flank] += 1;
        impacts.last_speed = xi_dot.abs();
    }
    match edge {
        Edge::Lower => law.below(region),
        Edge::Upper => law.above(region),
    }
}

impl System<N> for Rattle {
    #[inline]
    fn rhs(&self, t: f64, y: &State) -> State {
        let shaft = self.excitation.at(t);
        let loads = self.dynamics.loads(self.region, y[XI], y[XI_DOT], &shaft);
        let p = &self.dynamics.params;
        let slip = loads.omega_L - p.omega_S;
        [
            y[XI_DOT],
            loads.xi_ddot,
            loads.force.dissipative * y[XI_DOT],
            p.C * slip * slip,
            -p.r_M * loads.force.total() * shaft.omega,
        ]
    }
}

impl Piecewise<N> for Rattle {
    const GUARD: usize = XI;
    const RATE: usize = XI_DOT;

    fn piece(&self) -> (f64, f64) {
        self.dynamics.law.bounds(self.region)
    }

    fn cross(&mut self, edge: Edge, _t: f64, y: &State) {
        self.region = cross_edge(
            &self.dynamics,
            self.region,
            &mut self.impacts,
            edge,
            y[XI_DOT],
        );
    }
}
