//! The slave of fmi2-shell ([`fmi2_shell::Slave`]): the gearbox's variables, co-simulation
//! stepping and FMU state as typed methods. The shell applies FMI's rules (state machine,
//! time checks, what may be set when, the parameters' ranges at the set calls) before calling
//! in and turns the results into fmi2Status and log lines.

use serde::{Deserialize, Serialize};

use crate::contract::{self, Causality, Kind, LOG_CATEGORIES, VARIABLES, vr};
use crate::outputs::Now;
use crate::simulation::{self, Simulation};
use fmi2_shell::values::Values;
use fmi2_shell::{
    Continuous, EventInfo, FmiError, FmiResult, FmiState, Identity, Interface, Log, Slave, Status,
    Stepping,
};
use gear_rattle::integrator::SolverError;

/// The contract's log categories by role (errors and warnings first, as the shell wants).
const EVENTS: usize = contract::log::logEvents;
const STEPS: usize = contract::log::logStep;
const _: () = assert!(contract::log::logStatusError == fmi2_shell::log::ERRORS);
const _: () = assert!(contract::log::logStatusWarning == fmi2_shell::log::WARNINGS);

/// One FMU instance. Everything but the log is its FMU state: parameters, inputs, the
/// gearbox with its solver, state, windows and time.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Instance {
    interface: Interface,
    values: Values,
    start_time: f64,
    tolerance: Option<f64>,
    /// The running gearbox; built at fmi2ExitInitializationMode (and for reads during
    /// initialisation, from the values set so far).
    sim: Option<Simulation>,
    #[serde(skip)]
    log: Log,
}

impl Instance {
    /// The running gearbox, once initialised.
    pub fn simulation(&self) -> Option<&Simulation> {
        self.sim.as_ref()
    }

    fn build(&self) -> FmiResult<Simulation> {
        let rtol = self.tolerance.unwrap_or(contract::DEFAULT_TOLERANCE);
        let model_exchange = self.interface == Interface::ModelExchange;
        Simulation::new(&self.values, self.start_time, rtol, model_exchange)
    }

    /// The running simulation, or during initialisation one built from the values so far.
    fn current(&mut self) -> FmiResult<&Simulation> {
        if self.sim.is_none() {
            self.sim = Some(self.build()?);
        }
        Ok(self.sim.as_ref().expect("built above"))
    }

    /// Builds the simulation (as [`Self::current`]) when `vrs` asks for a computed variable, so
    /// that a getter computes its outputs from one readout ([`Now`]) for the whole call.
    fn build_if_computed(&mut self, kind: Kind, vrs: &[u32]) -> FmiResult {
        if fmi2_shell::contract::computed(contract::variable, kind, vrs) {
            self.current()?;
        }
        Ok(())
    }

    fn sim_mut(&mut self) -> &mut Simulation {
        self.sim.as_mut().expect("initialised")
    }

    /// New inputs in `state`: during initialisation the start is rebuilt; once running, the
    /// drive's inputs and the output shaft's speed take effect at once.
    fn inputs_changed(&mut self, state: FmiState, drive: bool, output_speed: bool) {
        if !state.is_initialised() {
            self.sim = None;
            return;
        }
        let values = &self.values;
        let (flywheel, input_side) = (
            simulation::flywheel_inputs(values),
            simulation::input_side_inputs(values),
        );
        let omega_out = values.real(vr::omega_out);
        let sim = self.sim_mut();
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

/// The co-simulation step of fmi2-shell's [`Stepping`], on the running gearbox.
impl Stepping for Instance {
    /// The impacts per gear and the damper's stage.
    type Events = ([[u64; 2]; 8], i32);
    type StepError = SolverError;
    const EVENTS: usize = EVENTS;
    const STEPS: usize = STEPS;

    fn events(&self) -> Self::Events {
        let (gearbox, _) = self.sim.as_ref().expect("initialised").gearbox();
        (
            gearbox.gears.map(|g| g.impacts.count),
            gearbox.regions().0.sign(),
        )
    }

    /// The gearbox from `current` towards `t_end`, with `at_event` ended at the first
    /// impact of any gear inside.
    fn advance(&mut self, current: f64, t_end: f64, at_event: bool) -> Result<f64, SolverError> {
        let sim = self.sim_mut();
        sim.t = current;
        sim.step_until(t_end, at_event)
    }

    fn is_finite(&self) -> bool {
        let (_, y) = self.sim.as_ref().expect("initialised").gearbox();
        y.iter().all(|v| v.is_finite())
    }

    fn sync_inputs(&mut self) {
        let Some((flywheel, shaft)) = self.sim.as_ref().and_then(Simulation::extrapolated_inputs)
        else {
            return;
        };
        let [theta, omega] = if flywheel {
            [vr::theta_F, vr::omega_F]
        } else {
            [vr::theta_I, vr::omega_I]
        };
        self.values.set_real(theta, shaft.theta);
        self.values.set_real(omega, shaft.omega);
    }

    /// logEvents after a step: the impacts it counted per gear and the damper's stage.
    fn log_events(&mut self, t_end: f64, before: Self::Events) {
        let (gearbox, _) = self.sim.as_ref().expect("initialised").gearbox();
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
            self.log.log(Status::Ok, EVENTS, || line);
        }
    }

    /// logStep after a step: the solver's work so far.
    fn log_steps(&mut self, t_end: f64) {
        let sim = self.sim.as_ref().expect("initialised");
        let (stats, h, implicit) = (sim.stats(), sim.proposed_step(), sim.is_implicit());
        let method = if implicit { "Radau IIA" } else { "DOPRI5" };
        self.log.log(Status::Ok, STEPS, || {
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
        state_version: 1,
        model_exchange: true,
        variable: contract::variable,
        variables: contract::VARIABLES,
        arrays: contract::FMI3_ARRAYS,
    };

    fn new(logging_on: bool, interface: Interface) -> Self {
        Instance {
            interface,
            values: Values::start(VARIABLES),
            start_time: 0.0,
            tolerance: None,
            sim: None,
            log: Log::new(LOG_CATEGORIES, logging_on),
        }
    }

    fn interface(&self) -> Interface {
        self.interface
    }

    fn log(&mut self) -> &mut Log {
        &mut self.log
    }

    fn setup_experiment(&mut self, tolerance: Option<f64>, start_time: f64) {
        self.start_time = start_time;
        self.tolerance = tolerance;
        self.sim = None;
    }

    fn enter_initialization_mode(&mut self) {
        self.sim = None;
    }

    /// Checks every parameter (the contract's ranges, then docs/GEARBOX.md's rules between them:
    /// k_2 ≥ k_1, ν_100 < ν_40, ...) and builds the start; an invalid parameter is refused
    /// and the instance stays in initialisation mode, where it can be corrected.
    fn exit_initialization_mode(&mut self) -> FmiResult {
        self.sim = Some(self.build()?);
        Ok(())
    }

    fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> FmiResult {
        self.build_if_computed(Kind::Real, vrs)?;
        let now = self.sim.as_ref().map(Now::new);
        for (vr, out) in vrs.iter().zip(out) {
            let var = contract::variable(Kind::Real, *vr)?;
            *out = match var.causality {
                Causality::Output | Causality::Local => now
                    .as_ref()
                    .and_then(|now| now.real(*vr))
                    .expect("every computed Real variable of the contract is computed"),
                _ => self.values.real(*vr),
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
        let now = self.sim.as_ref().map(Now::new);
        let output = |vr| now.as_ref()?.integer(vr);
        self.values
            .get_integer(contract::variable, vrs, out, output)
    }

    /// Sets parameters or inputs (the shell has checked the whole call).
    fn set_real(&mut self, state: FmiState, vrs: &[u32], values: &[f64]) -> FmiResult {
        let (mut drive, mut output_speed) = (false, false);
        for (vr, value) in vrs.iter().zip(values) {
            self.values.set_real(*vr, *value);
            drive |= (vr::theta_F..=vr::alpha_I).contains(vr);
            output_speed |= *vr == vr::omega_out;
        }
        self.inputs_changed(state, drive, output_speed);
        Ok(())
    }

    fn set_integer(&mut self, state: FmiState, vrs: &[u32], values: &[i32]) -> FmiResult {
        for (vr, value) in vrs.iter().zip(values) {
            self.values.set_integer(*vr, i64::from(*value));
        }
        if !state.is_initialised() {
            self.sim = None;
        }
        Ok(())
    }

    /// One communication step from the master's point `current`; a failure leaves the
    /// state at `current`.
    fn step(&mut self, current: f64, h: f64) -> FmiResult {
        self.step_until(current, current + h, false).map(|_| ())
    }

    /// Early return (FMI 3.0): the step ends at the first impact of any gear inside it.
    const STEPS_TO_EVENTS: bool = true;

    fn step_to_event(&mut self, current: f64, t_end: f64) -> FmiResult<f64> {
        self.step_until(current, t_end, true)
    }

    // Model Exchange (see `crate::model_exchange`).

    fn set_time(&mut self, t: f64) -> FmiResult {
        self.sim_mut().set_time(t);
        Ok(())
    }

    fn continuous(&mut self) -> FmiResult<&mut impl Continuous> {
        self.current()?;
        Ok(self.sim_mut())
    }

    fn new_discrete_states(&mut self) -> FmiResult<EventInfo> {
        let t = self.sim.as_ref().expect("initialised").t;
        let before = self.events();
        let next_event_time = self.sim_mut().update_discrete_states();
        if self.log.is_on(EVENTS) {
            self.log_events(t, before);
        }
        Ok(EventInfo {
            next_event_time,
            ..EventInfo::default()
        })
    }

    fn completed_integrator_step(&mut self) -> FmiResult<bool> {
        self.sim_mut().completed_integrator_step();
        Ok(false)
    }

    /// A decoded state must be one this build can run: an initialised instance has its
    /// simulation, of its interface, with 1 to 8 gears and a finite time and state; the
    /// values their full length and finite.
    fn check_decoded(&self, state: FmiState) -> FmiResult {
        self.values.check(VARIABLES)?;
        let refuse = |why: String| Err(FmiError::error(why));
        match &self.sim {
            None if state.is_initialised() => refuse(format!(
                "an initialised instance (state {state:?}) without a simulation"
            )),
            Some(sim) => {
                let (gearbox, y) = sim.gearbox();
                let n = gearbox.n_gears();
                if !(1..=gear_rattle::gearbox::MAX_GEARS).contains(&n) {
                    refuse(format!("a gearbox of {n} gears"))
                } else if sim.model_exchange != (self.interface == Interface::ModelExchange) {
                    refuse(format!(
                        "a {:?} instance with the other interface's simulation",
                        self.interface
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
