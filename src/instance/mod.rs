//! The slave of the shell ([`fmi2_shell::Slave`]) for either interface: the gear pair's
//! variables, co-simulation stepping and Model Exchange equations as typed methods, free of C
//! types. Each method returns `Ok(())` or an [`FmiError`] with its reason; the shell applies
//! FMI's rules (state machine, time checks, what may be set when) before calling in and turns
//! the results into fmi2Status and log lines.

pub mod model_exchange;
pub mod simulation;

pub use fmi2_shell::{FmiError, FmiResult, FmiState, Status};
pub use simulation::{Carry, Journaled, Readout, Simulation};

use crate::contract::{self, Causality, Kind, LOG_CATEGORIES, vr};
use crate::integrator::SolverError;
use crate::physics::Shaft;
use crate::rattle::Impacts;
use fmi2_shell::values::Values;
use fmi2_shell::{Continuous, Core, EventInfo, Grid, Identity, Interface, Model, Slave, Stepping};

use serde::{Deserialize, Serialize};

/// The model of one FMU instance. Everything but the logging settings and the queued lines is
/// part of its FMU state (fmi2GetFMUstate / fmi2SerializeFMUstate): parameters, inputs, the
/// model's state and time, the integrator's step size and controller memory, counters,
/// energies.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Instance {
    /// The values, the experiment, the running gear pair (Model Exchange: see
    /// `model_exchange`) and the log.
    core: Core<Simulation>,
    /// dτ_in/dt from fmi2SetRealInputDerivatives [N m/s] (0 until set: a held torque); the
    /// derivatives of θ_M and ω_M are kept as the inputs omega_M and alpha_M.
    tau_in_rate: f64,
}

impl Instance {
    /// Queues a line for the logger if its category is on.
    fn log_line(&mut self, status: Status, category: usize, text: impl FnOnce() -> String) {
        self.core.log.log(status, category, text);
    }

    /// A value that overflowed is never handed out with fmi2OK.
    #[cold]
    fn not_finite(vr: u32, value: f64) -> FmiError {
        let name = contract::find(Kind::Real, vr).map_or("?", |v| v.name);
        FmiError::error(format!(
            "{name} = {value}: the state overflowed (inputs or times beyond what the model can represent); fmi2Reset to start over"
        ))
    }

    /// A Real variable's value by its contract entry (a parameter, an input, or an output of
    /// the simulation built from the values so far, as the interface reads it). Kept out of `get_real`'s loop: building a
    /// simulation needs a large stack frame, which the reading of outputs after each step
    /// would otherwise set up at every call.
    #[inline(never)]
    fn real_value(&mut self, vr: u32) -> FmiResult<f64> {
        Ok(match contract::variable(Kind::Real, vr)?.causality {
            Causality::Output | Causality::Local => {
                let interface = self.core.interface;
                Readout::new(self.current()?, interface)
                    .real(vr)
                    .expect("every computed Real variable of the contract is computed")
            }
            _ => self.core.values.real(vr),
        })
    }

    /// A Real parameter or input as set; refused if `vr` is no Real variable of the contract.
    /// The running simulation computes every other Real variable.
    #[inline(never)]
    fn stored_real(values: &Values, vr: u32) -> FmiResult<f64> {
        let var = contract::variable(Kind::Real, vr)?;
        assert!(
            !matches!(var.causality, Causality::Output | Causality::Local),
            "every computed Real variable of the contract is computed"
        );
        Ok(values.real(vr))
    }

    /// After new values in `state`: rebuild the initial state during initialisation, or hand
    /// the main shaft's new motion (inputs mode) or torque (torque mode) to the running
    /// simulation (inputs take effect at once).
    fn inputs_changed(&mut self, state: FmiState) {
        // Co-Simulation's event mode (FMI 3.0) sets inputs between steps, as step mode does.
        let stepping = self.core.interface == Interface::CoSimulation;
        match state {
            FmiState::EventMode | FmiState::ContinuousTimeMode if !stepping => {
                let (shaft, tau, rate) = self.shaft_inputs();
                let sim = self.core.running_mut();
                sim.set_shaft_inputs(shaft);
                sim.set_torque(tau, rate);
            }
            FmiState::StepComplete | FmiState::EventMode => {
                let (shaft, tau, rate) = self.shaft_inputs();
                let sim = self.core.running_mut();
                let before = sim.impacts();
                sim.set_shaft(shaft);
                sim.set_torque(tau, rate);
                if before != sim.impacts() {
                    self.log_line(Status::Ok, Self::EVENTS, || {
                        "new inputs moved the gear pair across a contact onset".to_string()
                    });
                }
            }
            FmiState::InitializationMode => self.core.sim = None,
            _ => {}
        }
    }

    /// The main shaft's inputs as set: its motion (inputs mode), its torque and rate (torque
    /// mode).
    fn shaft_inputs(&self) -> (Shaft, f64, f64) {
        let shaft = Shaft {
            theta: self.core.values.real(vr::theta_M),
            omega: self.core.values.real(vr::omega_M),
            alpha: self.core.values.real(vr::alpha_M),
        };
        (shaft, self.core.values.real(vr::tau_in), self.tau_in_rate)
    }

    fn method_name(sim: &Simulation) -> &'static str {
        if sim.is_implicit() {
            "Radau IIA"
        } else {
            "DOPRI5"
        }
    }
}

/// The gear pair built from the parameters and the experiment; the lifecycle around it is
/// fmi2-shell's ([`Model`]).
impl Model for Instance {
    type Simulation = Simulation;
    const DEFAULT_TOLERANCE: f64 = contract::DEFAULT_TOLERANCE;

    fn with_core(core: Core<Simulation>) -> Self {
        Instance {
            core,
            tau_in_rate: 0.0,
        }
    }

    fn core(&self) -> &Core<Simulation> {
        &self.core
    }

    fn core_mut(&mut self) -> &mut Core<Simulation> {
        &mut self.core
    }

    fn build(&self, rtol: f64) -> FmiResult<Simulation> {
        // Model Exchange's states are every quadrature of the contract.
        let carry = match self.core.interface {
            Interface::CoSimulation => Carry::Asked,
            Interface::ModelExchange => Carry::All,
        };
        let (values, t0) = (&self.core.values, self.core.start_time);
        Simulation::new(values, self.tau_in_rate, t0, rtol, carry)
    }
}

/// The co-simulation step of fmi2-shell's [`Stepping`], on the running gear pair.
impl Stepping for Instance {
    /// The impacts and the hand-overs of the method.
    type Events = (Impacts, u64);
    type StepError = SolverError;
    const EVENTS: usize = contract::log::logEvents;
    const STEPS: usize = contract::log::logStep;

    fn events(&self) -> Self::Events {
        let sim = self.core.running();
        (sim.impacts(), sim.stats().switches)
    }

    /// The gear pair from `current` towards `t_end`, with `at_event` ended at the first
    /// impact inside.
    fn advance(&mut self, current: f64, t_end: f64, at_event: bool) -> Result<f64, SolverError> {
        let sim = self.core.running_mut();
        sim.t = current;
        sim.step_until(t_end, at_event)
    }

    /// Served where every variable read is F_contact (the sound's read: docs/SOUND.md, "The
    /// force"); any other is read the ordinary way.
    fn serve(&mut self, grid: &Grid, vrs: &[u32], out: &mut [f64]) -> usize {
        match &mut self.core.sim {
            Some(sim) if vrs.iter().all(|vr| *vr == vr::F_contact) => {
                sim.serve_forces(grid.ends(), vrs.len(), out)
            }
            _ => 0,
        }
    }

    fn is_finite(&self) -> bool {
        let sim = self.core.running();
        let (xi, xi_dot) = (sim.real_output(vr::xi), sim.real_output(vr::xi_dot));
        xi.is_some_and(f64::is_finite) && xi_dot.is_some_and(f64::is_finite)
    }

    /// `theta_M` and `omega_M` (inputs mode) or `tau_in` (torque mode) follow the
    /// extrapolation (see `Simulation::step_to`).
    fn sync_inputs(&mut self) {
        match self.core.sim.as_ref().map(|sim| sim.drive) {
            Some(simulation::Drive::Inputs(shaft)) => {
                self.core.values.set_real(vr::theta_M, shaft.theta);
                self.core.values.set_real(vr::omega_M, shaft.omega);
            }
            Some(simulation::Drive::Torque { tau, .. }) => {
                self.core.values.set_real(vr::tau_in, tau)
            }
            _ => {}
        }
    }

    /// logEvents after a step: the impacts it counted and a hand-over of the method.
    fn log_events(&mut self, t_end: f64, (impacts_before, switches_before): Self::Events) {
        let sim = self.core.running();
        let (impacts, switched) = (sim.impacts(), sim.stats().switches != switches_before);
        let method = Self::method_name(sim);
        let new = [
            impacts.count[0] - impacts_before.count[0],
            impacts.count[1] - impacts_before.count[1],
        ];
        if new != [0, 0] {
            self.log_line(Status::Ok, Self::EVENTS, || {
                format!(
                    "t = {t_end}: {} impact(s) on F+, {} on F-, last at |xi'| = {:e} m/s",
                    new[0], new[1], impacts.last_speed
                )
            });
        }
        if switched {
            self.log_line(Status::Ok, Self::EVENTS, || {
                format!("t = {t_end}: integration method handed over, now {method}")
            });
        }
    }

    /// logStep after a step: the solver's work so far.
    fn log_steps(&mut self, t_end: f64) {
        let sim = self.core.running();
        let (stats, h_next, method) = (sim.stats(), sim.proposed_step(), Self::method_name(sim));
        self.log_line(Status::Ok, Self::STEPS, || {
            format!(
                "t = {t_end}: {} accepted ({} by Radau IIA), {} rejected steps, {} edges, {} rhs evaluations, {} Jacobians, {} LU in total; next step {:e} s by {method}",
                stats.accepted,
                stats.implicit_steps,
                stats.rejected,
                stats.edges,
                stats.rhs_evals,
                stats.jacobians,
                stats.decompositions,
                h_next
            )
        });
    }
}

/// dv_unknown = J · dv_known, with the row of J of each unknown (its partials along the
/// knowns) from `row`, which refuses the unknowns it has none for; refused where a sum
/// overflows.
fn directional(
    unknowns: &[u32],
    dv_known: &[f64],
    dv_unknown: &mut [f64],
    mut row: impl FnMut(&contract::Variable) -> FmiResult<Vec<f64>>,
) -> FmiResult {
    for (u, out) in unknowns.iter().zip(dv_unknown) {
        let var = contract::variable(Kind::Real, *u)?;
        let sum: f64 = row(var)?.iter().zip(dv_known).map(|(p, dv)| p * dv).sum();
        if !sum.is_finite() {
            return Err(FmiError::error(format!(
                "the derivative of {} along dvKnown overflows ({sum}): scale the seed vector down",
                var.name
            )));
        }
        *out = sum;
    }
    Ok(())
}

/// The column of Model Exchange's Jacobian of a known: a continuous state or an input.
fn model_exchange_column(known: u32) -> FmiResult<usize> {
    let var = contract::variable(Kind::Real, known)?;
    model_exchange::column(known).ok_or_else(|| {
        let states = contract::STATES
            .iter()
            .filter_map(|s| contract::find(Kind::Real, *s).map(|v| v.name));
        FmiError::error(format!(
            "{} is neither a continuous state nor an input: Model Exchange's directional derivatives are taken with respect to the states {} and the inputs theta_M, omega_M, alpha_M, tau_in",
            var.name,
            states.collect::<Vec<_>>().join(", ")
        ))
    })
}

impl Slave for Instance {
    const IDENTITY: Identity = Identity {
        guid: contract::GUID,
        model_identifier: contract::MODEL_IDENTIFIER,
        log_categories: LOG_CATEGORIES,
        state_magic: *b"GRFS",
        state_version: 8,
        model_exchange: true,
        variable: contract::variable,
        variables: contract::VARIABLES,
        arrays: contract::FMI3_ARRAYS,
    };

    fn check_decoded(&self, state: FmiState) -> FmiResult {
        self.core.values.check(contract::VARIABLES)?;
        if !self.tau_in_rate.is_finite() {
            return Err(FmiError::error(format!(
                "dtau_in/dt is {}",
                self.tau_in_rate
            )));
        }
        // The running states step or integrate the simulation.
        let running = matches!(
            state,
            FmiState::StepComplete | FmiState::EventMode | FmiState::ContinuousTimeMode
        );
        if running && self.core.sim.is_none() {
            return Err(FmiError::error("initialised, but without a simulation"));
        }
        Ok(())
    }

    fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> FmiResult {
        let Some(sim) = &self.core.sim else {
            // No simulation yet (initialisation): the first computed value builds it.
            for (vr, out) in vrs.iter().zip(out) {
                *out = self.real_value(*vr)?;
                if !out.is_finite() {
                    return Err(Self::not_finite(*vr, *out));
                }
            }
            return Ok(());
        };
        // The outputs of the running simulation, what they share computed once for the call:
        // what a master reads after each step.
        let readout = Readout::new(sim, self.core.interface);
        for (vr, out) in vrs.iter().zip(out) {
            *out = match readout.real(*vr) {
                Some(value) => value,
                None => Self::stored_real(&self.core.values, *vr)?,
            };
            if !out.is_finite() {
                return Err(Self::not_finite(*vr, *out));
            }
        }
        Ok(())
    }

    fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> FmiResult {
        if fmi2_shell::contract::computed(contract::variable, Kind::Integer, vrs) {
            self.current()?;
        }
        let sim = self.core.sim.as_ref();
        let output = |vr| sim?.integer_output(vr);
        self.core
            .values
            .get_integer(contract::variable, vrs, out, output)
    }

    /// Sets Real parameters or inputs (the shell has checked the whole call).
    fn set_real(&mut self, state: FmiState, vrs: &[u32], values: &[f64]) -> FmiResult {
        let mut shaft_changed = false;
        for (vr, value) in vrs.iter().zip(values) {
            self.core.values.set_real(*vr, *value);
            shaft_changed |= matches!(*vr, vr::theta_M | vr::omega_M | vr::alpha_M | vr::tau_in);
        }
        if shaft_changed || !state.is_initialised() {
            self.inputs_changed(state);
        }
        Ok(())
    }

    fn set_integer(&mut self, state: FmiState, vrs: &[u32], values: &[i32]) -> FmiResult {
        self.core.set_integer(state, vrs, values)
    }

    /// fmi2SetRealInputDerivatives: the derivatives of θ_M (orders 1, 2) and ω_M (order 1) at
    /// the start of the next step set the speed and acceleration of the main shaft's Taylor
    /// polynomial over the step (a later call for the same quantity wins); the derivative of
    /// τ_in (order 1) ramps the torque over the step (torque mode). Like the inputs, a
    /// derivative holds until it is set again.
    fn set_input_derivatives(
        &mut self,
        state: FmiState,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> FmiResult {
        let mut targets = Vec::with_capacity(vrs.len());
        for ((vr, order), value) in vrs.iter().zip(orders).zip(values) {
            // Where the derivative is kept: an input variable, or τ_in's rate (None).
            let target = match (*vr, *order) {
                (vr::theta_M, 1) => Some(vr::omega_M),
                (vr::theta_M, 2) | (vr::omega_M, 1) => Some(vr::alpha_M),
                (vr::tau_in, 1) => None,
                _ => {
                    let name = contract::find(Kind::Real, *vr).map_or("?", |v| v.name);
                    return Err(FmiError::error(format!(
                        "derivative of order {order} of value reference {vr} ({name}) is not an input derivative of this model: theta_M takes orders 1 and 2, omega_M and tau_in order 1"
                    )));
                }
            };
            if !value.is_finite() {
                return Err(FmiError::error(format!(
                    "derivative {value} of order {order} refused: values must be finite"
                )));
            }
            targets.push((target, *value));
        }
        for (target, value) in targets {
            match target {
                Some(vr) => self.core.values.set_real(vr, value),
                None => self.tau_in_rate = value,
            }
        }
        self.inputs_changed(state);
        Ok(())
    }

    /// fmi2GetRealOutputDerivatives (order 1).
    fn output_derivative(&mut self, vr: u32) -> FmiResult<f64> {
        let var = contract::variable(Kind::Real, vr)?;
        match self.current()?.real_output_derivative(vr) {
            Some(d) if d.is_finite() => Ok(d),
            Some(d) => Err(Self::not_finite(vr, d)),
            None => Err(FmiError::error(format!(
                "no derivative for {}: order 1 is given for {}",
                var.name,
                contract::with_derivative().collect::<Vec<_>>().join(", ")
            ))),
        }
    }

    /// fmi2GetDirectionalDerivative: dv_unknown = J · dv_known. Co-simulation: J =
    /// ∂outputs/∂inputs ([`Simulation::partial`]); Model Exchange: J = ∂(derivatives,
    /// outputs)/∂(states, inputs) ([`model_exchange::Jacobian`]).
    fn directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> FmiResult {
        if let Some(dv) = dv_known.iter().find(|dv| !dv.is_finite()) {
            return Err(FmiError::error(format!(
                "dvKnown = {dv} refused: the seed vector must be finite"
            )));
        }
        match self.core.interface {
            Interface::CoSimulation => {
                for k in knowns {
                    let var = contract::variable(Kind::Real, *k)?;
                    if var.causality != Causality::Input {
                        return Err(FmiError::error(format!(
                            "{} is not an input: directional derivatives are taken with respect to theta_M, omega_M, alpha_M, tau_in",
                            var.name
                        )));
                    }
                }
                let sim = self.current()?;
                directional(unknowns, dv_known, dv_unknown, |var| {
                    if var.causality != Causality::Output {
                        return Err(FmiError::error(format!(
                            "{} is not an output: directional derivatives are of outputs",
                            var.name
                        )));
                    }
                    Ok(knowns.iter().map(|k| sim.partial(var.vr, *k)).collect())
                })
            }
            Interface::ModelExchange => {
                let columns = knowns
                    .iter()
                    .map(|k| model_exchange_column(*k))
                    .collect::<FmiResult<Vec<usize>>>()?;
                let jacobian = self.current()?.jacobian();
                directional(unknowns, dv_known, dv_unknown, |var| {
                    let gradient = jacobian.gradient(var.vr).ok_or_else(|| {
                        FmiError::error(format!(
                            "{} is not an unknown of Model Exchange's directional derivatives: they are given for the state derivatives der(...) and the Real outputs",
                            var.name
                        ))
                    })?;
                    Ok(columns.iter().map(|&c| gradient.0[c]).collect())
                })
            }
        }
    }

    // Model Exchange (see `model_exchange`).

    fn set_time(&mut self, t: f64) -> FmiResult {
        self.core.running_mut().set_time(t).map_err(|shaft| {
            FmiError::error(format!(
                "time = {t:e} refused: the main shaft's motion there is not finite ({shaft:?}), beyond what the model can represent"
            ))
        })
    }

    fn continuous(&mut self) -> FmiResult<&mut impl Continuous> {
        self.current()
    }

    fn new_discrete_states(&mut self) -> FmiResult<EventInfo> {
        let sim = self.core.running_mut();
        let before = sim.impacts();
        let next_event_time = sim.update_discrete_states();
        let after = sim.impacts();
        if before != after {
            let t = sim.t;
            self.log_line(Status::Ok, Self::EVENTS, || {
                format!(
                    "t = {t}: impact at |xi'| = {:e} m/s ({} on F+, {} on F- so far)",
                    after.last_speed, after.count[0], after.count[1]
                )
            });
        }
        Ok(EventInfo {
            next_event_time,
            ..EventInfo::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fmi2_shell::Fmu;
    use fmi2_shell::fmu_state::{deserialize, serialize};
    use fmi2_shell::values::Values;

    fn stepped() -> Fmu<Instance> {
        let mut i = Fmu::<Instance>::new(false, Interface::CoSimulation);
        i.set_integer(&[vr::excitation], &[1]).unwrap();
        i.enter_initialization_mode().unwrap();
        i.exit_initialization_mode().unwrap();
        i.do_step(0.0, 0.01).unwrap();
        i
    }

    /// The sound's grid through the sampling entry (points served from the kept step where it
    /// can) against fmi2DoStep and fmi2GetReal at every point on S1: the same F_contact and
    /// the same simulation, to the bit, through free flights, contacts and the statistics
    /// window's opening, over more changes than the journal records. The journal replays the
    /// served runs to the same state (what a failed step puts back).
    #[test]
    fn sampled_steps_are_the_ordinary_ones() {
        let start = || {
            let mut i = Fmu::<Instance>::new(false, Interface::CoSimulation);
            i.set_integer(&[vr::excitation], &[1]).unwrap();
            i.set_real(&[vr::stats_from], &[0.013]).unwrap();
            i.enter_initialization_mode().unwrap();
            i.exit_initialization_mode().unwrap();
            i
        };
        let (h, n) = (1.0 / 192_000.0, 1920);
        let (mut sampled, mut plain) = (start(), start());
        let (mut out, mut row, mut in_contact) = (vec![0.0; n], [0.0], 0);
        for call in 0..6 {
            let t0 = (call * n) as f64 * h;
            sampled
                .do_step_sampled(t0, h, n, &[vr::F_contact], &mut out)
                .unwrap();
            for (k, want) in out.iter().enumerate() {
                plain.do_step(t0 + k as f64 * h, h).unwrap();
                plain.slave.get_real(&[vr::F_contact], &mut row).unwrap();
                assert_eq!(want.to_bits(), row[0].to_bits(), "call {call}, point {k}");
                in_contact += usize::from(row[0] != 0.0);
            }
            assert!(
                sampled.slave.core.sim == plain.slave.core.sim,
                "call {call}"
            );
        }
        assert!(in_contact > 100, "{in_contact} samples in contact");
        let sim = sampled.slave.core.running_mut();
        assert!(sim.now().window.is_opened());
        let before = *sim;
        sim.replay();
        assert!(*sim == before);
        assert_eq!(sim.stats(), before.stats());
    }

    /// A serialized state decodes to an instance that serializes to the same bytes.
    #[test]
    fn serialized_state_round_trip_is_exact() {
        let i = stepped();
        let back: Fmu<Instance> = deserialize(&serialize(&i)).unwrap();
        assert_eq!(serialize(&back), serialize(&i));
    }

    /// Bytes with a valid checksum but made by hand are refused when the instance they
    /// decode to could not run: an initialised one without its simulation (in Co-Simulation
    /// or Model Exchange), in a state of the other interface, values missing or not finite
    /// (the fuzzer's mended states made fmi2ExitInitializationMode panic).
    #[test]
    fn hand_made_states_are_refused() {
        let refused =
            |i: &Fmu<Instance>| deserialize::<Instance>(&serialize(i)).unwrap_err().message;
        let mut no_sim = stepped();
        no_sim.slave.core.sim = None;
        assert!(refused(&no_sim).contains("without a simulation"));
        let mut in_event_mode = Fmu::<Instance>::new(false, Interface::ModelExchange);
        in_event_mode.state = FmiState::EventMode;
        assert!(refused(&in_event_mode).contains("without a simulation"));
        let mut stepping = stepped();
        stepping.slave.core.interface = Interface::ModelExchange;
        assert!(refused(&stepping).contains("ModelExchange instance in state StepComplete"));
        let mut integrating = stepped();
        integrating.state = FmiState::ContinuousTimeMode;
        assert!(refused(&integrating).contains("CoSimulation instance in state Continuous"));
        let mut nan = stepped();
        nan.slave.core.values.set_real(vr::omega_M, f64::NAN);
        assert!(refused(&nan).contains("NaN"));
        let mut short = stepped();
        short.slave.core.values = values_without_integers();
        assert!(refused(&short).contains("Integer values"));
    }

    /// Values with no Integer entry, as a mended state decoded to.
    fn values_without_integers() -> Values {
        let bytes = postcard::to_allocvec(&(vec![0.0f64; 70], Vec::<i64>::new())).unwrap();
        postcard::from_bytes(&bytes).unwrap()
    }

    /// Corrupt, cut, foreign and other-version bytes are refused with the reason.
    #[test]
    fn corrupt_or_foreign_states_are_refused() {
        let bytes = serialize(&stepped());
        let refused = |b: &[u8]| deserialize::<Instance>(b).unwrap_err().message;
        let mut flipped = bytes.clone();
        flipped[13] ^= 1;
        assert!(refused(&flipped).contains("checksum"));
        assert!(refused(&bytes[..bytes.len() - 1]).contains("length"));
        assert!(refused(b"hello world, not a state").contains("GRFS"));
        let mut version = bytes.clone();
        version[4] = 9;
        assert!(refused(&version).contains("version"));
    }
}
