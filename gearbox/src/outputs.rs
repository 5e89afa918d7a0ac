//! Every output (and local) of the contract, computed from the running gearbox when it is
//! read (docs/GEARBOX.md §7): the box's, then gear i's by its offset in the gear's block. The
//! slots of gears beyond n_gears read 0.
#![allow(non_snake_case, non_upper_case_globals)]

use crate::contract::vr::{self, gear::offset};
use crate::contract::{DERIVATIVES, STATES};
use crate::simulation::Simulation;
use fmi2_shell::Continuous;
use gear_rattle::gearbox::{Gearbox, Readout, xi, xi_dot};
use gear_rattle::rattle::window::Metrics;

/// What the outputs are computed from now: the gearbox's readout, once for every output read
/// at this instant.
pub struct Now<'a> {
    sim: &'a Simulation,
    gearbox: Gearbox,
    readout: Readout,
}

impl<'a> Now<'a> {
    pub fn new(sim: &'a Simulation) -> Self {
        let (gearbox, y) = sim.observed();
        Now {
            sim,
            readout: gearbox.readout(sim.t, &y),
            gearbox,
        }
    }

    fn gears(&self) -> std::ops::Range<usize> {
        0..self.gearbox.n_gears()
    }

    /// ρ_i r_M,i, the lever of gear i's force on the input shaft.
    fn lever(&self, i: usize) -> f64 {
        let g = &self.gearbox.gears[i];
        g.rho * g.dynamics.params.r_M
    }

    /// Σ ρ_i r_M,i F_i: the gears' torque on the input side.
    fn tau_I(&self) -> f64 {
        self.gears()
            .map(|i| self.lever(i) * self.readout.gears[i].F)
            .sum()
    }

    /// c_I(T) ω_I and each loose gear's drag C_i(T) (ω_L,i − ω_S,i) carried to the input
    /// shaft by ρ_i r_M,i / r_L,i.
    fn T_drag(&self) -> f64 {
        let omega_I = self.readout.input.omega_I;
        let gears: f64 = self
            .gears()
            .map(|i| {
                let p = &self.gearbox.gears[i].dynamics.params;
                self.lever(i) / p.r_L * p.C * (self.readout.gears[i].omega_L - p.omega_S)
            })
            .sum();
        self.gearbox.c_I * omega_I + gears
    }

    /// Gear i's window figures (zero before the window opens).
    fn metrics(&self, i: usize) -> Option<Metrics> {
        let (window, q) = self.sim.window(i).filter(|_| i < self.gearbox.n_gears())?;
        let p = &self.gearbox.gears[i].dynamics.params;
        Some(window.metrics(self.sim.t, &q, p.I_L / (p.r_L * p.r_L)))
    }

    /// Gear i's rattle power over the window: its impact energy per second.
    fn rattle_power(&self, i: usize) -> f64 {
        self.metrics(i).map_or(0.0, |m| {
            per_second(&m, m.impact_energy[0] + m.impact_energy[1])
        })
    }

    fn box_rattle_power(&self) -> f64 {
        self.gears().map(|i| self.rattle_power(i)).sum()
    }

    /// The gear (from 1) with the largest rattle power, 0 without impacts.
    fn loudest_gear(&self) -> i64 {
        self.gears()
            .map(|i| (i, self.rattle_power(i)))
            .filter(|&(_, p)| p > 0.0)
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(0, |(i, _)| i as i64 + 1)
    }
}

fn per_second(m: &Metrics, x: f64) -> f64 {
    if m.length > 0.0 { x / m.length } else { 0.0 }
}

impl Now<'_> {
    /// The value of a Real output or local; None if `vr` is none.
    pub fn real(&self, vr: u32) -> Option<f64> {
        let b = &self.readout.input;
        Some(match vr {
            vr::tau_F => -b.T_cl,
            vr::tau_I => self.tau_I(),
            vr::theta_I_out => b.theta_I,
            vr::omega_I_out => b.omega_I,
            vr::alpha_I_out => b.alpha_I,
            vr::phi => b.phi,
            vr::T_clutch => b.T_cl,
            vr::T_drag => self.T_drag(),
            vr::E_damper => b.e_damper,
            vr::stat_rattle_power => self.box_rattle_power(),
            _ => vr::gear::locate(vr)
                .and_then(|(i, offset)| gear_real(self, i, offset))
                .or_else(|| self.sim.model_exchange_local(vr))?,
        })
    }

    /// The value of an Integer output; None if `vr` is none.
    pub fn integer(&self, vr: u32) -> Option<i64> {
        Some(match vr {
            vr::damper_stage => 1 + i64::from(self.readout.input.stage.abs()),
            vr::stat_loudest_gear => self.loudest_gear(),
            _ => {
                let (i, offset) = vr::gear::locate(vr)?;
                gear_integer(self, i, offset)?
            }
        })
    }
}

/// Gear i's contact force at its ξ_i and ξ_i', read from the gearbox's state through
/// `state` (a component by its index), in the region the gear is in; 0 beyond n_gears.
pub fn mesh_force(gearbox: &Gearbox, i: usize, state: impl Fn(usize) -> f64) -> f64 {
    match gearbox.gears[..gearbox.n_gears()].get(i) {
        Some(g) => g
            .dynamics
            .law
            .force(g.region, state(xi(i)), state(xi_dot(i)))
            .total(),
        None => 0.0,
    }
}

impl Simulation {
    /// The value of a Real output or local, computed now; None if `vr` is none.
    pub fn real_output(&self, vr: u32) -> Option<f64> {
        Now::new(self).real(vr)
    }

    /// Gear i's contact force F_contact from the gearbox's state alone, the value [`Now`]
    /// reads without the rest of the readout (the other loads, the flywheel's motion): what
    /// the sound reads at every sample (docs/SOUND.md, "The force"). None for any other
    /// variable, and in Model Exchange, where the outputs read the settled regions.
    pub fn contact_force(&self, vr: u32) -> Option<f64> {
        let i = self.contact_force_gear(vr)?;
        let (gearbox, y) = self.gearbox();
        Some(mesh_force(gearbox, i, |k| y[k]))
    }

    /// The gear whose F_contact `vr` is, as [`contact_force`](Self::contact_force) reads it;
    /// None for any other variable, and in Model Exchange.
    pub fn contact_force_gear(&self, vr: u32) -> Option<usize> {
        let (i, offset) = vr::gear::locate(vr)?;
        (offset == offset::F_contact && !self.model_exchange).then_some(i)
    }

    /// The Model Exchange variables that are not outputs: the state x_omega_I and the
    /// derivatives (see [`crate::model_exchange`]).
    fn model_exchange_local(&self, vr: u32) -> Option<f64> {
        if let Some(k) = STATES.iter().position(|&s| s == vr) {
            return Some(self.continuous_states()[k]);
        }
        let k = DERIVATIVES.iter().position(|&d| d == vr)?;
        Some(self.derivatives()[k])
    }

    /// The value of an Integer output, computed now; None if `vr` is none.
    pub fn integer_output(&self, vr: u32) -> Option<i64> {
        Now::new(self).integer(vr)
    }
}

/// Gear i's Real output of `offset` (0 for a gear the box does not have).
fn gear_real(now: &Now, i: usize, offset: u32) -> Option<f64> {
    use offset::*;
    let g = &now.readout.gears[i];
    let value = match offset {
        xi => g.xi,
        xi_dot => g.xi_dot,
        omega_L => g.omega_L,
        F_contact => g.F,
        impact_speed => g.impacts.last_speed,
        E_contact => g.e_contact,
        E_lubricant => g.e_lubricant,
        stat_rattle_share => {
            let total = now.box_rattle_power();
            if total > 0.0 {
                now.rattle_power(i) / total
            } else {
                0.0
            }
        }
        _ => {
            let m = now.metrics(i);
            return stat_real(m.as_ref(), offset);
        }
    };
    Some(if i < now.gearbox.n_gears() {
        value
    } else {
        0.0
    })
}

/// Gear i's Integer output of `offset`.
fn gear_integer(now: &Now, i: usize, offset: u32) -> Option<i64> {
    use offset::*;
    let g = &now.readout.gears[i];
    Some(match offset {
        contact => i64::from(g.flank),
        impacts_Fplus => g.impacts.count[0] as i64,
        impacts_Fminus => g.impacts.count[1] as i64,
        _ => return stat_integer(now.metrics(i).as_ref(), offset),
    })
}

/// A Real stat_* output of a gear from its window's figures (0 before the window opens);
/// None if `offset` is none of them. The formulas are GearRattle's (docs/METRICS.md).
fn stat_real(m: Option<&Metrics>, offset: u32) -> Option<f64> {
    use offset::*;
    let known = matches!(
        offset,
        stat_window
            | stat_impact_rate_Fplus
            | stat_impact_rate_Fminus
            | stat_run_mean_Fplus
            | stat_run_mean_Fminus
            | stat_v_mean_Fplus
            | stat_v_mean_Fminus
            | stat_v_rms_Fplus
            | stat_v_rms_Fminus
            | stat_v_max_Fplus
            | stat_v_max_Fminus
            | stat_E_impact_Fplus
            | stat_E_impact_Fminus
            | stat_rattle_power
            | stat_a_rms
            | stat_a_peak
            | stat_F_std
            | stat_contact_fraction
            | stat_P_contact
            | stat_P_lubricant
    );
    if !known {
        return None;
    }
    let Some(m) = m else { return Some(0.0) };
    let [plus, minus] = &m.flanks;
    Some(match offset {
        stat_window => m.length,
        stat_impact_rate_Fplus => per_second(m, plus.impacts as f64),
        stat_impact_rate_Fminus => per_second(m, minus.impacts as f64),
        stat_run_mean_Fplus => plus.run_mean(),
        stat_run_mean_Fminus => minus.run_mean(),
        stat_v_mean_Fplus => plus.v_mean(),
        stat_v_mean_Fminus => minus.v_mean(),
        stat_v_rms_Fplus => plus.v_rms(),
        stat_v_rms_Fminus => minus.v_rms(),
        stat_v_max_Fplus => plus.v_max,
        stat_v_max_Fminus => minus.v_max,
        stat_E_impact_Fplus => m.impact_energy[0],
        stat_E_impact_Fminus => m.impact_energy[1],
        stat_rattle_power => per_second(m, m.impact_energy[0] + m.impact_energy[1]),
        stat_a_rms => m.a_rms,
        stat_a_peak => m.a_peak,
        stat_F_std => m.F_std,
        stat_contact_fraction => m.contact_fraction,
        stat_P_contact => m.P_contact,
        _ => m.P_lubricant,
    })
}

/// An Integer stat_* output of a gear; None if `offset` is none of them.
fn stat_integer(m: Option<&Metrics>, offset: u32) -> Option<i64> {
    use offset::*;
    let known = (stat_impacts_Fplus..=stat_side).contains(&offset);
    if !known {
        return None;
    }
    let Some(m) = m else { return Some(0) };
    let [plus, minus] = &m.flanks;
    let (regime, side) = m.regime();
    Some(match offset {
        stat_impacts_Fplus => plus.impacts as i64,
        stat_impacts_Fminus => minus.impacts as i64,
        stat_runs_Fplus => plus.runs as i64,
        stat_runs_Fminus => minus.runs as i64,
        stat_run_max_Fplus => plus.run_max as i64,
        stat_run_max_Fminus => minus.run_max as i64,
        stat_regime => regime,
        _ => side,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use crate::contract::{Kind, vr};
    use crate::instance::Instance;
    use crate::outputs::Now;
    use fmi2_shell::{Fmu, Interface};

    /// A co-simulation instance on the built-in engine (excitation 1), initialised with the
    /// Real parameters `reals` set.
    pub(crate) fn on_engine(reals: &[(u32, f64)]) -> Fmu<Instance> {
        let mut fmu = Fmu::<Instance>::new(false, Interface::CoSimulation);
        fmu.set_integer(&[vr::excitation], &[1]).unwrap();
        for (vr, value) in reals {
            fmu.set_real(&[*vr], &[*value]).unwrap();
        }
        fmu.enter_initialization_mode().unwrap();
        fmu.exit_initialization_mode().unwrap();
        fmu
    }

    /// Every gear slot's F_contact.
    pub(crate) fn contact_forces() -> Vec<u32> {
        crate::contract::VARIABLES
            .iter()
            .filter(|v| v.kind == Kind::Real && v.name.ends_with(".F_contact"))
            .map(|v| v.vr)
            .collect()
    }

    /// The contact force read alone is the readout's, to the bit, for every gear slot at
    /// every point of a fine grid through the start-up's impacts (none in Model Exchange,
    /// whose outputs read the settled regions).
    #[test]
    fn contact_force_alone_is_the_readouts() {
        std::thread::Builder::new()
            .stack_size(8 << 20)
            .spawn(|| {
                let mut fmu = on_engine(&[]);
                let forces = contact_forces();
                assert_eq!(forces.len(), gear_rattle::gearbox::MAX_GEARS);
                let (h, mut in_contact) = (1.0 / 192_000.0, 0);
                for k in 0..3840 {
                    fmu.do_step(k as f64 * h, h).unwrap();
                    let sim = fmu.slave.simulation().unwrap();
                    for &vr in &forces {
                        let alone = sim.contact_force(vr).unwrap();
                        assert_eq!(alone.to_bits(), Now::new(sim).real(vr).unwrap().to_bits());
                        in_contact += usize::from(alone != 0.0);
                    }
                }
                assert!(in_contact > 100, "{in_contact} samples in contact");
                let mut me = Fmu::<Instance>::new(false, Interface::ModelExchange);
                me.enter_initialization_mode().unwrap();
                me.exit_initialization_mode().unwrap();
                let sim = me.slave.simulation().unwrap();
                assert!(sim.contact_force(forces[0]).is_none());
            })
            .unwrap()
            .join()
            .unwrap();
    }
}
