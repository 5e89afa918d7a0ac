//! The rattling gear as a piecewise-smooth ODE for the integrator: the state layout, the
//! right-hand side (MODEL.md §3 plus the dissipated energies and the shaft's work as
//! quadratures), the region as the current piece, and the impact counters (MODEL.md §1: an
//! impact is ξ leaving the gap, across 0 downwards on F+ or G upwards on F−).
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

use crate::integrator::{Edge, Jacobian, Piecewise, System, Tolerance};
use crate::physics::{Dynamics, Excitation, Region};

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
        const FLIGHT_RATE: f64 = 1e3;
        let p = &self.dynamics.params;
        let xi_scale = p.G;
        let xi_dot_scale = p.G * p.contact_frequency().min(FLIGHT_RATE);
        Tolerance {
            rtol,
            atol: [rtol * xi_scale, rtol * xi_dot_scale, 0.0, 0.0, 0.0],
            controlled: 2,
        }
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

impl Jacobian<N> for Rattle {
    /// ∂f/∂y of `rhs` for Radau IIA: the contact's slopes (MODEL.md §2) through the equation of
    /// motion (§3), ∂ξ''/∂ξ = −(r_L²/I_L) ∂F/∂ξ and ∂ξ''/∂ξ' = −(r_L²/I_L) ∂F/∂ξ' − C/I_L. The
    /// rows of the quadratures (energies, work) are left zero: they do not act back on ξ, ξ',
    /// so Radau's simplified Newton iteration gives them their exact stage values from those
    /// of ξ, ξ' in each iteration, and they are outside the error control.
    fn jacobian(&self, _t: f64, y: &State) -> [[f64; N]; N] {
        let p = &self.dynamics.params;
        let slopes = self.dynamics.law.slopes(self.region, y[XI], y[XI_DOT]);
        let lever = p.r_L * p.r_L / p.I_L;
        let mut j = [[0.0; N]; N];
        j[XI][XI_DOT] = 1.0;
        j[XI_DOT][XI] = -lever * slopes.d_xi;
        j[XI_DOT][XI_DOT] = -lever * slopes.d_xi_dot - p.C / p.I_L;
        j
    }
}

impl Piecewise<N> for Rattle {
    const GUARD: usize = XI;
    const RATE: usize = XI_DOT;

    fn piece(&self) -> (f64, f64) {
        self.dynamics.law.bounds(self.region)
    }

    fn rough_start(&self) -> bool {
        self.dynamics.law.rough_at_onset(self.region)
    }

    fn cross(&mut self, edge: Edge, _t: f64, y: &State) {
        let law = &self.dynamics.law;
        let next = match edge {
            Edge::Lower => law.below(self.region),
            Edge::Upper => law.above(self.region),
        };
        if self.region == Region::Gap {
            let flank = if edge == Edge::Lower { 0 } else { 1 };
            self.impacts.count[flank] += 1;
            self.impacts.last_speed = y[XI_DOT].abs();
        }
        self.region = next;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{GearParams, Sine};

    /// The Jacobian matches central differences of the right-hand side in every region, for
    /// the rows of ξ and ξ' (the quadratures' rows are zero on purpose, see `jacobian`).
    #[test]
    fn jacobian_matches_finite_differences_in_every_region() {
        let p = GearParams::paper();
        let excitation = Excitation::Sine(Sine::new(300.0, 30.0, 84.0));
        let xis = [-3e-6, -0.7e-6, -0.2e-6, 10e-6, p.G + 0.4e-6, p.G + 3e-6];
        for xi in xis {
            let rattle = Rattle::new(Dynamics::new(p), excitation, xi);
            let y = [xi, 0.03, 0.0, 0.0, 0.0];
            let j = rattle.jacobian(0.004, &y);
            for (col, step) in [(XI, 1e-12), (XI_DOT, 1e-7)] {
                let (mut up, mut down) = (y, y);
                up[col] += step;
                down[col] -= step;
                let (fu, fd) = (rattle.rhs(0.004, &up), rattle.rhs(0.004, &down));
                for row in [XI, XI_DOT] {
                    let fd_slope = (fu[row] - fd[row]) / (2.0 * step);
                    let err = (j[row][col] - fd_slope).abs();
                    assert!(
                        err <= 1e-5 * fd_slope.abs().max(1.0),
                        "region {:?}, ∂f{row}/∂y{col}: {} vs {fd_slope}",
                        rattle.region,
                        j[row][col]
                    );
                }
            }
        }
    }
}
