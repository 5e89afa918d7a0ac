//! What a user reads from the gearbox at (t, y) (docs/GEARBOX.md §7): per gear and for the box.

use serde::{Deserialize, Serialize};

use super::{
    E_DAMPER, E_INPUT_DRAG, Gearbox, MAX_GEARS, PHI, PHI_DOT, State, W_FLYWHEEL, e_contact,
    e_lubricant, xi, xi_dot,
};
use crate::physics::{Region, Stage};
use crate::rattle::Impacts;

/// One loose gear.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct GearReadout {
    /// ξ [m], ξ' [m/s].
    pub xi: f64,
    pub xi_dot: f64,
    /// ω_L [rad/s], ω_L' [rad/s²].
    pub omega_L: f64,
    pub alpha_L: f64,
    /// Contact force F [N].
    pub F: f64,
    /// Contact flag: 0 gap, 1 flank F+, 2 flank F− ([`Region::flank`]).
    pub flank: i32,
    pub impacts: Impacts,
    /// Energy dissipated in the contact and in the lubricant [J].
    pub e_contact: f64,
    pub e_lubricant: f64,
}

/// The damper, the input side and the flywheel.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BoxReadout {
    /// Twist φ [rad] and its rate [rad/s]; its stage −1, 0 (pre-damper), +1.
    pub phi: f64,
    pub phi_dot: f64,
    pub stage: i32,
    /// Torque through the damper T_cl [N m] (the flywheel feels −T_cl).
    pub T_cl: f64,
    pub theta_F: f64,
    pub omega_F: f64,
    pub alpha_F: f64,
    /// θ_I (θ_F − φ behind the damper), ω_I, α_I.
    pub theta_I: f64,
    pub omega_I: f64,
    pub alpha_I: f64,
    /// Energies dissipated in the damper and by the input side's drag, and the work the
    /// flywheel has fed in [J].
    pub e_damper: f64,
    pub e_input_drag: f64,
    pub w_flywheel: f64,
}

/// The whole box at one instant; gears beyond [`Gearbox::n_gears`] are zero.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Readout {
    pub input: BoxReadout,
    pub gears: [GearReadout; MAX_GEARS],
}

impl Gearbox {
    /// The readouts at (t, y) with the current stage and regions.
    pub fn readout(&self, t: f64, y: &State) -> Readout {
        let l = self.loads(t, y);
        let mut gears = [GearReadout::default(); MAX_GEARS];
        for (i, (out, gear)) in gears.iter_mut().zip(&self.gears[..self.n]).enumerate() {
            let g = &l.gears[i];
            *out = GearReadout {
                xi: y[xi(i)],
                xi_dot: y[xi_dot(i)],
                omega_L: g.omega_L,
                alpha_L: g.alpha_L,
                F: g.force.total(),
                flank: gear.region.flank(),
                impacts: gear.impacts,
                e_contact: y[e_contact(i)],
                e_lubricant: y[e_lubricant(i)],
            };
        }
        let f = &l.flywheel;
        Readout {
            input: BoxReadout {
                phi: y[PHI],
                phi_dot: y[PHI_DOT],
                stage: self.stage.sign(),
                T_cl: l.T_cl,
                theta_F: f.theta,
                omega_F: f.omega,
                alpha_F: f.alpha,
                theta_I: l.input.theta,
                omega_I: l.input.omega,
                alpha_I: l.input.alpha,
                e_damper: y[E_DAMPER],
                e_input_drag: y[E_INPUT_DRAG],
                w_flywheel: y[W_FLYWHEEL],
            },
            gears,
        }
    }

    /// Gear i's region and the damper's stage, for a caller that needs the enums.
    pub fn regions(&self) -> (Stage, [Region; MAX_GEARS]) {
        (self.stage, self.gears.map(|g| g.region))
    }
}
