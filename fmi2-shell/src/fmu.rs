//! An FMU instance as FMI 2.0 sees it: the model's [`Slave`] inside the rules every FMU
//! shares, written once. The C exports call these methods after the state table
//! ([`crate::state::allowed`]) has admitted the call; they make the state transitions, check
//! the time arguments ([`crate::time`]) and the values set against the contract, keep the
//! instance's time and last successful time, and call the slave where the model has a say.

use crate::log::Log;
use crate::slave::{Interface, Slave};
use crate::state::FmiState;
use crate::status::{FmiError, FmiResult};
use crate::time;
use crate::values::Starts;
use serde::{Deserialize, Serialize};

mod sampled;

/// The FMI state, the times and the slave. All of it is the FMU state (fmi2GetFMUstate)
/// except the slave's queued log lines.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Fmu<S> {
    pub state: FmiState,
    /// The instance's time: the start time, then the end of each step (Co-Simulation) or the
    /// time set (Model Exchange).
    time: f64,
    /// fmi2LastSuccessfulTime: the end of the last step that succeeded (Co-Simulation), the
    /// time of the last completed integrator step (Model Exchange).
    last_successful_time: f64,
    /// What the importer asked for at instantiation (FMI 3.0's Co-Simulation): kept by a
    /// restored FMU state and by a reset, as the logging settings are.
    #[serde(skip)]
    pub events: CoSimulationEvents,
    pub slave: S,
    /// Start values other than the contract's (a packed model description's), applied at
    /// instantiation and at each reset; the instance's, not part of its FMU state.
    #[serde(skip)]
    starts: Starts,
}

/// FMI 3.0's Co-Simulation with events ([`STEPS_TO_EVENTS`]): what the importer allows at
/// instantiation.
///
/// [`STEPS_TO_EVENTS`]: crate::slave::Lifecycle::STEPS_TO_EVENTS
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CoSimulationEvents {
    /// earlyReturnAllowed: a step may end at the model's first event inside it.
    pub early_return_allowed: bool,
    /// eventModeUsed: the importer enters event mode when a step ends at an event, and after
    /// initialisation.
    pub event_mode_used: bool,
    /// intermediateUpdate: the importer's callback, called at each of the model's events
    /// inside a step, with its instanceEnvironment.
    pub intermediate_update: Option<(IntermediateUpdate, *mut std::ffi::c_void)>,
}

/// FMI 3.0's fmi3IntermediateUpdateCallback: instanceEnvironment, intermediateUpdateTime,
/// intermediateVariableSetRequested, intermediateVariableGetAllowed, intermediateStepFinished,
/// canReturnEarly, earlyReturnRequested (out), earlyReturnTime (out).
pub type IntermediateUpdate =
    unsafe extern "C" fn(*mut std::ffi::c_void, f64, bool, bool, bool, bool, *mut bool, *mut f64);

impl<S: Slave> Fmu<S> {
    /// A fresh instance (state Instantiated, start time 0).
    pub fn new(logging_on: bool, interface: Interface) -> Self {
        Fmu {
            state: FmiState::Instantiated,
            time: 0.0,
            last_successful_time: 0.0,
            events: CoSimulationEvents::default(),
            slave: S::new(logging_on, interface),
            starts: Starts::default(),
        }
    }

    /// Takes `starts` as its start values: set as fmi2SetReal/SetInteger set them, and
    /// again at every reset.
    pub fn start_from(&mut self, starts: Starts) -> FmiResult {
        let (vrs, values): (Vec<u32>, Vec<f64>) = starts.real.iter().copied().unzip();
        self.set_real(&vrs, &values)?;
        let (vrs, values): (Vec<u32>, Vec<i32>) = starts.integer.iter().copied().unzip();
        self.set_integer(&vrs, &values)?;
        self.starts = starts;
        Ok(())
    }

    pub fn interface(&self) -> Interface {
        self.slave.interface()
    }

    pub fn log(&mut self) -> &mut Log {
        self.slave.log()
    }

    pub fn time(&self) -> f64 {
        self.time
    }

    pub fn last_successful_time(&self) -> f64 {
        self.last_successful_time
    }

    pub fn setup_experiment(&mut self, tolerance: Option<f64>, start_time: f64) -> FmiResult {
        time::check_experiment(tolerance, start_time)?;
        self.time = start_time;
        self.slave.setup_experiment(tolerance, start_time);
        Ok(())
    }

    pub fn enter_initialization_mode(&mut self) -> FmiResult {
        self.slave.enter_initialization_mode();
        self.state = FmiState::InitializationMode;
        Ok(())
    }

    /// Into the running state of the interface (Co-Simulation: step complete; Model
    /// Exchange: event mode) once the slave has accepted its parameters.
    pub fn exit_initialization_mode(&mut self) -> FmiResult {
        self.slave.exit_initialization_mode()?;
        self.last_successful_time = self.time;
        self.state = match self.interface() {
            Interface::CoSimulation if self.events.event_mode_used => FmiState::EventMode,
            Interface::CoSimulation => FmiState::StepComplete,
            Interface::ModelExchange => FmiState::EventMode,
        };
        Ok(())
    }

    pub fn terminate(&mut self) -> FmiResult {
        self.state = FmiState::Terminated;
        Ok(())
    }

    /// fmi2SetReal: the whole call is checked against the contract first (each variable
    /// known, settable in this state, to a finite value), so a refused call changes nothing.
    pub fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> FmiResult {
        for (vr, value) in vrs.iter().zip(values) {
            (S::IDENTITY.variable)(crate::contract::Kind::Real, *vr)?
                .settable_to(self.state, *value)?;
        }
        self.slave.set_real(self.state, vrs, values)
    }

    /// fmi2SetInteger, checked as [`set_real`](Self::set_real).
    pub fn set_integer(&mut self, vrs: &[u32], values: &[i32]) -> FmiResult {
        for vr in vrs {
            (S::IDENTITY.variable)(crate::contract::Kind::Integer, *vr)?.settable(self.state)?;
        }
        self.slave.set_integer(self.state, vrs, values)
    }

    pub fn set_input_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> FmiResult {
        self.slave
            .set_input_derivatives(self.state, vrs, orders, values)
    }

    /// fmi2DoStep: the step checked against the instance's time, then the slave's step; a
    /// failed step leaves the instance in the error state at its time.
    #[inline]
    pub fn do_step(&mut self, current: f64, h: f64) -> FmiResult {
        self.step_with(current, h, |s| s.step(current, h).map(|()| current + h))
            .map(|_| ())
    }

    /// fmi3DoStep: as [`do_step`](Self::do_step), ended at the model's first event inside the
    /// step where the importer allowed early return; returns the time reached (the instance's
    /// time and last successful time).
    pub fn do_step_to_event(&mut self, current: f64, h: f64) -> FmiResult<f64> {
        match self.events.early_return_allowed && S::STEPS_TO_EVENTS {
            true => self.step_with(current, h, |s| s.step_to_event(current, current + h)),
            false => self.step_with(current, h, |s| s.step(current, h).map(|()| current + h)),
        }
    }

    /// fmi3DoStep with an intermediate update: the step taken from event to event (a stop
    /// continued goes on as the step that never stopped, D41), `at_event` called with the
    /// time of each; ends there where it returns true. Returns the time reached.
    pub fn do_step_through_events(
        &mut self,
        current: f64,
        h: f64,
        mut at_event: impl FnMut(f64) -> bool,
    ) -> FmiResult<f64> {
        if !S::STEPS_TO_EVENTS {
            return self.do_step_to_event(current, h);
        }
        // Each part ends at the step's own end: the remainder t_end - t would round.
        let t_end = current + h;
        let (mut t, mut h) = (current, h);
        loop {
            t = self.step_with(t, h, |s| s.step_to_event(t, t_end))?;
            if t >= t_end || at_event(t) {
                return Ok(t);
            }
            h = t_end - t;
        }
    }

    /// The step checked against the instance's time, then `step`, which gives the time it
    /// reached; a failed step leaves the instance in the error state at its time.
    #[inline]
    fn step_with(
        &mut self,
        current: f64,
        h: f64,
        step: impl FnOnce(&mut S) -> FmiResult<f64>,
    ) -> FmiResult<f64> {
        time::check_step(current, h, self.time)?;
        match step(&mut self.slave) {
            Ok(reached) => {
                self.time = reached;
                self.last_successful_time = self.time;
                Ok(reached)
            }
            Err(e) => {
                self.state = FmiState::Error;
                Err(e)
            }
        }
    }

    // Model Exchange.

    pub fn set_time(&mut self, t: f64) -> FmiResult {
        time::check_time(t)?;
        self.slave.set_time(t)?;
        self.time = t;
        Ok(())
    }

    pub fn enter_event_mode(&mut self) -> FmiResult {
        self.state = FmiState::EventMode;
        Ok(())
    }

    pub fn enter_continuous_time_mode(&mut self) -> FmiResult {
        self.state = FmiState::ContinuousTimeMode;
        Ok(())
    }

    pub fn completed_integrator_step(&mut self) -> FmiResult<bool> {
        let event = self.slave.completed_integrator_step()?;
        self.last_successful_time = self.time;
        Ok(event)
    }

    // FMU states.

    /// A copy of the FMU state: the instance without its queued log lines.
    pub fn snapshot(&self) -> Self {
        let mut copy = self.clone();
        copy.log().messages.clear();
        copy
    }

    /// fmi2SetFMUstate: takes over a saved FMU state of an instance of the same interface,
    /// keeping the logging settings and lines.
    pub fn restore(&mut self, saved: &Self) -> FmiResult {
        // A state holds its instance's interface, which the importer's calls must keep.
        if saved.interface() != self.interface() {
            return Err(FmiError::error(format!(
                "the FMU state is of a {:?} instance, this one is {:?}",
                saved.interface(),
                self.interface()
            )));
        }
        self.take_over(saved);
        Ok(())
    }

    fn take_over(&mut self, saved: &Self) {
        let (log, events) = (std::mem::take(self.log()), self.events);
        let starts = std::mem::take(&mut self.starts);
        *self = saved.clone();
        *self.log() = log;
        self.events = events;
        self.starts = starts;
    }

    /// fmi2Reset: back to the state after instantiation, the logging settings kept.
    pub fn reset(&mut self) -> FmiResult {
        let mut fresh = Self::new(false, self.interface());
        fresh.start_from(self.starts.clone())?;
        self.take_over(&fresh);
        Ok(())
    }

    /// Whether an instance decoded by fmi2DeSerializeFMUstate can run: finite times, a
    /// running state of its own interface, and what the slave checks of itself.
    pub fn check_decoded(&self) -> FmiResult {
        if !(self.time.is_finite() && self.last_successful_time.is_finite()) {
            return Err(FmiError::error(format!(
                "time {} or last successful time {} not finite",
                self.time, self.last_successful_time
            )));
        }
        // Event mode is both interfaces' (Co-Simulation's with eventModeUsed).
        let running = match self.state {
            FmiState::StepComplete => Some(Interface::CoSimulation),
            FmiState::ContinuousTimeMode => Some(Interface::ModelExchange),
            _ => None,
        };
        if let Some(interface) = running
            && interface != self.interface()
        {
            return Err(FmiError::error(format!(
                "a {:?} instance in state {:?}",
                self.interface(),
                self.state
            )));
        }
        self.slave.check_decoded(self.state)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contract::{Causality, Kind, Range, Start, Variable, unknown};
    use crate::slave::{Identity, Lifecycle};

    const fn var(name: &'static str, vr: u32, causality: Causality) -> Variable {
        Variable {
            name,
            vr,
            kind: Kind::Real,
            causality,
            start: Start::Real(1.0),
            unit: "",
            depends_on: &[],
            derivative: false,
            range: Range::ANY,
            description: "",
        }
    }

    static VARIABLES: [Variable; 3] = [
        var("k", 0, Causality::Parameter),
        var("u", 1, Causality::Input),
        var("y", 2, Causality::Output),
    ];

    fn variable(kind: Kind, vr: u32) -> FmiResult<&'static Variable> {
        VARIABLES
            .get(vr as usize)
            .filter(|_| kind == Kind::Real)
            .ok_or_else(|| unknown(kind, vr))
    }

    /// y' = k u: refuses k <= 0 at initialisation, fails a step with u < 0.
    #[derive(Clone, Debug, Serialize, Deserialize)]
    struct Integrator {
        interface: Interface,
        values: [f64; 3],
        #[serde(skip)]
        log: Log,
    }

    impl Lifecycle for Integrator {
        fn new(_logging_on: bool, interface: Interface) -> Self {
            Integrator {
                interface,
                values: [1.0; 3],
                log: Log::default(),
            }
        }

        fn interface(&self) -> Interface {
            self.interface
        }

        fn log(&mut self) -> &mut Log {
            &mut self.log
        }

        fn exit_initialization_mode(&mut self) -> FmiResult {
            if self.values[0] > 0.0 {
                Ok(())
            } else {
                Err(FmiError::error("k must be > 0"))
            }
        }

        fn step(&mut self, _t: f64, h: f64) -> FmiResult {
            if self.values[1] < 0.0 {
                return Err(FmiError::error("u < 0"));
            }
            self.values[2] += self.values[0] * self.values[1] * h;
            Ok(())
        }
    }

    impl Slave for Integrator {
        const IDENTITY: Identity = Identity {
            guid: "{test}",
            model_identifier: "Integrator",
            log_categories: &[("logStatusError", ""), ("logStatusWarning", "")],
            state_magic: *b"TEST",
            state_version: 1,
            model_exchange: true,
            variable,
            variables: &VARIABLES,
            arrays: &[],
        };

        fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> FmiResult {
            for (vr, out) in vrs.iter().zip(out) {
                *out = self.values[variable(Kind::Real, *vr)?.vr as usize];
            }
            Ok(())
        }

        fn set_real(&mut self, _state: FmiState, vrs: &[u32], values: &[f64]) -> FmiResult {
            for (vr, value) in vrs.iter().zip(values) {
                self.values[*vr as usize] = *value;
            }
            Ok(())
        }

        fn set_time(&mut self, _t: f64) -> FmiResult {
            Ok(())
        }

        fn completed_integrator_step(&mut self) -> FmiResult<bool> {
            Ok(false)
        }
    }

    fn running(interface: Interface, start_time: f64) -> Fmu<Integrator> {
        let mut fmu = Fmu::<Integrator>::new(false, interface);
        fmu.setup_experiment(None, start_time).unwrap();
        fmu.enter_initialization_mode().unwrap();
        fmu.exit_initialization_mode().unwrap();
        fmu
    }

    /// Co-Simulation: the start time, then each step's end, is the instance's time; a refused
    /// step changes nothing, a failed one leaves the error state at the last good time.
    #[test]
    fn steps_keep_the_time_and_a_failed_one_is_an_error() {
        let mut fmu = running(Interface::CoSimulation, 1.0);
        assert_eq!(fmu.state, FmiState::StepComplete);
        assert_eq!(fmu.last_successful_time(), 1.0);
        fmu.do_step(1.0, 0.5).unwrap();
        assert_eq!((fmu.time(), fmu.slave.values[2]), (1.5, 1.5));
        assert!(fmu.do_step(1.0, 0.5).is_err());
        assert!(fmu.do_step(1.5, -0.5).is_err());
        assert_eq!(fmu.state, FmiState::StepComplete);
        assert_eq!((fmu.time(), fmu.slave.values[2]), (1.5, 1.5));
        fmu.set_real(&[1], &[-1.0]).unwrap();
        assert_eq!(fmu.do_step(1.5, 0.5).unwrap_err().message, "u < 0");
        assert_eq!(fmu.state, FmiState::Error);
        assert_eq!(fmu.last_successful_time(), 1.5);
    }

    /// A refused initialisation stays in initialisation mode; a parameter is fixed after it,
    /// a value must be finite, an output is never set: the slave sees none of these calls.
    #[test]
    fn initialisation_and_sets_follow_the_state() {
        let mut fmu = Fmu::<Integrator>::new(false, Interface::CoSimulation);
        fmu.enter_initialization_mode().unwrap();
        fmu.set_real(&[0], &[0.0]).unwrap();
        assert!(fmu.exit_initialization_mode().is_err());
        assert_eq!(fmu.state, FmiState::InitializationMode);
        fmu.set_real(&[0], &[2.0]).unwrap();
        fmu.exit_initialization_mode().unwrap();
        assert!(fmu.set_real(&[1, 0], &[3.0, 1.0]).is_err());
        assert!(fmu.set_real(&[1], &[f64::NAN]).is_err());
        assert!(fmu.set_real(&[2], &[1.0]).is_err());
        assert!(fmu.set_real(&[7], &[1.0]).is_err());
        assert_eq!(fmu.slave.values, [2.0, 1.0, 1.0]);
        fmu.reset().unwrap();
        assert_eq!(fmu.state, FmiState::Instantiated);
    }

    /// Start values other than the contract's are set at the start and again at each reset,
    /// and survive taking over an FMU state.
    #[test]
    fn packed_start_values_outlive_resets() {
        let mut fmu = Fmu::<Integrator>::new(false, Interface::CoSimulation);
        let saved = fmu.snapshot();
        let starts = Starts {
            real: vec![(0, 4.0)],
            integer: vec![],
        };
        fmu.start_from(starts).unwrap();
        fmu.set_real(&[0], &[2.0]).unwrap();
        fmu.restore(&saved).unwrap();
        fmu.reset().unwrap();
        assert_eq!(fmu.slave.values, [4.0, 1.0, 1.0]);
        let bad = Starts {
            real: vec![(2, 4.0)],
            integer: vec![],
        };
        assert!(fmu.start_from(bad).is_err());
    }

    /// Model Exchange: event mode after initialisation, a finite time set is the instance's
    /// time and the last successful one once an integrator step completes.
    #[test]
    fn model_exchange_keeps_the_time_set() {
        let mut fmu = running(Interface::ModelExchange, 0.0);
        assert_eq!(fmu.state, FmiState::EventMode);
        fmu.enter_continuous_time_mode().unwrap();
        assert!(fmu.set_time(f64::NAN).is_err());
        fmu.set_time(2.0).unwrap();
        assert_eq!(fmu.last_successful_time(), 0.0);
        assert!(!fmu.completed_integrator_step().unwrap());
        assert_eq!(fmu.last_successful_time(), 2.0);
        fmu.enter_event_mode().unwrap();
        assert_eq!(fmu.state, FmiState::EventMode);
    }

    /// A decoded instance in a running state of the other interface, or with a time that is
    /// not finite, is refused; an FMU state of the other interface is not taken over.
    #[test]
    fn inconsistent_instances_are_refused() {
        let mut stepping = running(Interface::CoSimulation, 0.0);
        stepping.slave.interface = Interface::ModelExchange;
        let refused = stepping.check_decoded().unwrap_err().message;
        assert!(refused.contains("ModelExchange instance in state StepComplete"));
        let mut lost = running(Interface::CoSimulation, 0.0);
        lost.time = f64::NAN;
        assert!(lost.check_decoded().is_err());
        let mut fmu = running(Interface::CoSimulation, 0.0);
        assert!(
            fmu.restore(&running(Interface::ModelExchange, 0.0))
                .is_err()
        );
        fmu.restore(&running(Interface::CoSimulation, 3.0)).unwrap();
        assert_eq!(fmu.time(), 3.0);
    }
}
