//! The slave of fmi2-shell ([`fmi2_shell::Slave`]): the gearbox's variables, co-simulation
//! stepping and FMU state as typed methods. The shell applies FMI's rules (state machine,
//! time checks, what may be set when, the parameters' ranges at the set calls) before calling
//! in and turns the results into fmi2Status and log lines.

use serde::{Deserialize, Serialize};

use crate::contract::{self, Causality, Kind, LOG_CATEGORIES, VARIABLES, vr};
use crate::outputs::Now;
use crate::simulation::{self, Simulation};
use fmi2_shell::{
    Continuous, Core, EventInfo, FmiError, FmiResult, FmiState, Grid, Identity, Interface, Model,
    Slave, Status, Stepping,
};
use gear_rattle::instance::Journaled;
use gear_rattle::integrator::SolverError;

/// One FMU instance. Everything but the log is its FMU state: parameters, inputs, the
/// gearbox with its solver, state, windows and time.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Instance {
    core: Core<Simulation>,
}

impl Instance {
    /// The running gearbox, once initialised.
    pub fn simulation(&self) -> Option<&Simulation> {
        self.core.sim.as_ref()
    }

    /// Builds the simulation (as [`Self::current`]) when `vrs` asks for a computed variable, so
    /// that a getter computes its outputs from one readout ([`Now`]) for the whole call.
    fn build_if_computed(&mut self, kind: Kind, vrs: &[u32]) -> FmiResult {
        if fmi2_shell::contract::computed(contract::variable, kind, vrs) {
            self.current()?;
        }
        Ok(())
    }

    /// New inputs in `state`: during initialisation the start is rebuilt; once running, the
    /// drive's inputs and the output shaft's speed take effect at once.
    fn inputs_changed(&mut self, state: FmiState, drive: bool, output_speed: bool) {
        if !state.is_initialised() {
            self.core.sim = None;
            return;
        }
        let values = &self.core.values;
        let (flywheel, input_side) = (
            simulation::flywheel_inputs(values),
            simulation::input_side_inputs(values),
        );
        let omega_out = values.real(vr::omega_out);
        let sim = self.core.running_mut();
        match state {
            FmiState::EventMode | FmiState::ContinuousTimeMode if drive => {
                sim.set_drive_inputs(flywheel, input_side);
            }
            _ if drive => {
                sim.set_flywheel(flywheel);
                sim.set_input_side(input_side);
            }
            _ => {}
        }
        if output_speed {
            sim.set_output_speed(omega_out);
        }
    }
}

/// The gearbox built from the parameters and the experiment; the lifecycle around it is
/// fmi2-shell's ([`Model`]).
impl Model for Instance {
    type Simulation = Simulation;
    const DEFAULT_TOLERANCE: f64 = contract::DEFAULT_TOLERANCE;

    fn with_core(core: Core<Simulation>) -> Self {
        Instance { core }
    }

    fn core(&self) -> &Core<Simulation> {
        &self.core
    }

    fn core_mut(&mut self) -> &mut Core<Simulation> {
        &mut self.core
    }

    /// Checks every parameter (the contract's ranges, then docs/GEARBOX.md's rules between
    /// them: k_2 ≥ k_1, ν_100 < ν_40, ...) and builds the start.
    fn build(&self, rtol: f64) -> FmiResult<Simulation> {
        let model_exchange = self.core.interface == Interface::ModelExchange;
        Simulation::new(
            &self.core.values,
            self.core.start_time,
            rtol,
            model_exchange,
        )
    }
}

/// The co-simulation step of fmi2-shell's [`Stepping`], on the running gearbox.
impl Stepping for Instance {
    /// The impacts per gear and the damper's stage.
    type Events = ([[u64; 2]; 8], i32);
    type StepError = SolverError;
    const EVENTS: usize = contract::log::logEvents;
    const STEPS: usize = contract::log::logStep;

    fn events(&self) -> Self::Events {
        let (gearbox, _) = self.core.running().gearbox();
        (
            gearbox.gears.map(|g| g.impacts.count),
            gearbox.regions().0.sign(),
        )
    }

    /// The gearbox from `current` towards `t_end`, with `at_event` ended at the first
    /// impact of any gear inside.
    fn advance(&mut self, current: f64, t_end: f64, at_event: bool) -> Result<f64, SolverError> {
        let sim = self.core.running_mut();
        sim.t = current;
        sim.step_until(t_end, at_event)
    }

    /// Served where every variable read is a gear's contact force (the sound's reads:
    /// docs/SOUND.md, "The force"); any other is read the ordinary way.
    fn serve(&mut self, grid: &Grid, vrs: &[u32], out: &mut [f64]) -> usize {
        let Some(sim) = self.core.sim.as_mut() else {
            return 0;
        };
        let gears: Option<Vec<usize>> = vrs.iter().map(|vr| sim.contact_force_gear(*vr)).collect();
        match gears {
            Some(gears) => sim.serve_forces(grid.ends(), &gears, out),
            None => 0,
        }
    }

    fn is_finite(&self) -> bool {
        let (_, y) = self.core.running().gearbox();
        y.iter().all(|v| v.is_finite())
    }

    fn sync_inputs(&mut self) {
        let Some((flywheel, shaft)) = self
            .core
            .sim
            .as_ref()
            .and_then(Simulation::extrapolated_inputs)
        else {
            return;
        };
        let [theta, omega] = if flywheel {
            [vr::theta_F, vr::omega_F]
        } else {
            [vr::theta_I, vr::omega_I]
        };
        self.core.values.set_real(theta, shaft.theta);
        self.core.values.set_real(omega, shaft.omega);
    }

    /// logEvents after a step: the impacts it counted per gear and the damper's stage.
    fn log_events(&mut self, t_end: f64, before: Self::Events) {
        let (gearbox, _) = self.core.running().gearbox();
        let (stage, _) = gearbox.regions();
        let lines: Vec<String> = (0..gearbox.n_gears())
            .filter_map(|i| {
                let count = gearbox.gears[i].impacts.count;
                let new = [count[0] - before.0[i][0], count[1] - before.0[i][1]];
                (new != [0, 0]).then(|| {
                    format!(
                        "t = {t_end}: gear {}: {} impact(s) on F+, {} on F-",
                        i + 1,
                        new[0],
                        new[1]
                    )
                })
            })
            .chain((stage.sign() != before.1).then(|| {
                format!(
                    "t = {t_end}: the clutch damper works in stage {}",
                    1 + stage.sign().abs()
                )
            }))
            .collect();
        for line in lines {
            self.core.log.log(Status::Ok, Self::EVENTS, || line);
        }
    }

    /// logStep after a step: the solver's work so far.
    fn log_steps(&mut self, t_end: f64) {
        let sim = self.core.running();
        let (stats, h, implicit) = (sim.stats(), sim.proposed_step(), sim.is_implicit());
        let method = if implicit { "Radau IIA" } else { "DOPRI5" };
        self.core.log.log(Status::Ok, Self::STEPS, || {
            format!(
                "t = {t_end}: {} accepted ({} by Radau IIA), {} rejected steps, {} edges, {} rhs evaluations in total; next step {h:e} s by {method}",
                stats.accepted, stats.implicit_steps, stats.rejected, stats.edges, stats.rhs_evals
            )
        });
    }
}

impl Slave for Instance {
    const IDENTITY: Identity = Identity {
        guid: contract::GUID,
        model_identifier: contract::MODEL_IDENTIFIER,
        log_categories: LOG_CATEGORIES,
        state_magic: *b"GBXS",
        state_version: 2,
        model_exchange: true,
        variable: contract::variable,
        variables: contract::VARIABLES,
        arrays: contract::FMI3_ARRAYS,
    };

    fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> FmiResult {
        self.build_if_computed(Kind::Real, vrs)?;
        // The readout once for the call, where a variable needs more than a contact force.
        let sim = self.core.sim.as_ref();
        let now = std::cell::OnceCell::new();
        for (vr, out) in vrs.iter().zip(out) {
            let var = contract::variable(Kind::Real, *vr)?;
            *out = match var.causality {
                Causality::Output | Causality::Local => sim
                    .and_then(|sim| {
                        sim.contact_force(*vr)
                            .or_else(|| now.get_or_init(|| Now::new(sim)).real(*vr))
                    })
                    .expect("every computed Real variable of the contract is computed"),
                _ => self.core.values.real(*vr),
            };
            if !out.is_finite() {
                return Err(FmiError::error(format!(
                    "{} = {out}: the state overflowed (inputs or times beyond what the model can represent); fmi2Reset to start over",
                    var.name
                )));
            }
        }
        Ok(())
    }

    fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> FmiResult {
        self.build_if_computed(Kind::Integer, vrs)?;
        let now = self.core.sim.as_ref().map(Now::new);
        let output = |vr| now.as_ref()?.integer(vr);
        self.core
            .values
            .get_integer(contract::variable, vrs, out, output)
    }

    /// Sets parameters or inputs (the shell has checked the whole call).
    fn set_real(&mut self, state: FmiState, vrs: &[u32], values: &[f64]) -> FmiResult {
        let (mut drive, mut output_speed) = (false, false);
        for (vr, value) in vrs.iter().zip(values) {
            self.core.values.set_real(*vr, *value);
            drive |= (vr::theta_F..=vr::alpha_I).contains(vr);
            output_speed |= *vr == vr::omega_out;
        }
        self.inputs_changed(state, drive, output_speed);
        Ok(())
    }

    fn set_integer(&mut self, state: FmiState, vrs: &[u32], values: &[i32]) -> FmiResult {
        self.core.set_integer(state, vrs, values)
    }

    // Model Exchange (see `crate::model_exchange`).

    fn set_time(&mut self, t: f64) -> FmiResult {
        self.core.running_mut().set_time(t);
        Ok(())
    }

    fn continuous(&mut self) -> FmiResult<&mut impl Continuous> {
        self.current()
    }

    fn new_discrete_states(&mut self) -> FmiResult<EventInfo> {
        let t = self.core.running().t;
        let before = self.events();
        let next_event_time = self.core.running_mut().update_discrete_states();
        if self.core.log.is_on(Self::EVENTS) {
            self.log_events(t, before);
        }
        Ok(EventInfo {
            next_event_time,
            ..EventInfo::default()
        })
    }

    /// A decoded state must be one this build can run: an initialised instance has its
    /// simulation, of its interface, with 1 to 8 gears and a finite time and state; the
    /// values their full length and finite.
    fn check_decoded(&self, state: FmiState) -> FmiResult {
        self.core.values.check(VARIABLES)?;
        let refuse = |why: String| Err(FmiError::error(why));
        match &self.core.sim {
            None if state.is_initialised() => refuse(format!(
                "an initialised instance (state {state:?}) without a simulation"
            )),
            Some(sim) => {
                let (gearbox, y) = sim.gearbox();
                let n = gearbox.n_gears();
                if !(1..=gear_rattle::gearbox::MAX_GEARS).contains(&n) {
                    refuse(format!("a gearbox of {n} gears"))
                } else if sim.model_exchange != (self.core.interface == Interface::ModelExchange) {
                    refuse(format!(
                        "a {:?} instance with the other interface's simulation",
                        self.core.interface
                    ))
                } else if !(sim.t.is_finite() && y.iter().all(|v| v.is_finite())) {
                    refuse(format!("a time {} or a state that is not finite", sim.t))
                } else {
                    Ok(())
                }
            }
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::outputs::tests::{contact_forces, on_engine};

    /// The sound's grid through the sampling entry (steps served from the solver's kept steps
    /// where it can) against fmi2DoStep and fmi2GetReal at every point: the same forces and
    /// the same simulation, to the bit, through the start-up's impacts and the statistics
    /// window's opening, over more changes than the journal records. The journal replays the
    /// served runs to the same state (what a failed step puts back).
    #[test]
    fn sampled_steps_are_the_ordinary_ones() {
        std::thread::Builder::new()
            .stack_size(8 << 20)
            .spawn(|| {
                let start = || on_engine(&[(vr::stats_from, 0.013)]);
                let forces = contact_forces();
                let (h, n, m) = (1.0 / 192_000.0, 1920, forces.len());
                let (mut sampled, mut plain) = (start(), start());
                let (mut out, mut row) = (vec![0.0; n * m], vec![0.0; m]);
                let mut in_contact = 0;
                for call in 0..12 {
                    let t0 = (call * n) as f64 * h;
                    sampled
                        .do_step_sampled(t0, h, n, &forces, &mut out)
                        .unwrap();
                    for (k, want) in out.chunks(m).enumerate() {
                        plain.do_step(t0 + k as f64 * h, h).unwrap();
                        plain.slave.get_real(&forces, &mut row).unwrap();
                        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                        assert_eq!(bits(want), bits(&row), "call {call}, point {k}");
                        in_contact += row.iter().filter(|f| **f != 0.0).count();
                    }
                    assert!(sampled.slave.simulation() == plain.slave.simulation());
                }
                assert!(in_contact > 100, "{in_contact} samples in contact");
                let sim = sampled.slave.core.running_mut();
                assert!(matches!(sim.run, simulation::Run::Windowed(_)));
                // What a failed step does: back to the journal's copy, then its changes.
                let before = sim.clone();
                sim.replay();
                assert!(*sim == before);
                assert_eq!(sim.stats(), before.stats());
            })
            .unwrap()
            .join()
            .unwrap();
    }
}
