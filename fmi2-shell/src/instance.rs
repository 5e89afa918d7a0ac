//! The instance of a model that runs a simulation built from its parameters, written once:
//! the values set, the experiment (interface, start time, tolerance), the simulation (built
//! at fmi2ExitInitializationMode, or earlier for a read during initialisation, and dropped
//! whenever what it was built from changes before then) and the log, with the lifecycle
//! around them ([`Lifecycle`] for every [`Model`]). The model supplies how its simulation is
//! built ([`Model::build`]), its variables (the rest of its [`Slave`]) and its step
//! ([`Stepping`]).

use crate::log::Log;
#[cfg(doc)]
use crate::slave::Slave;
use crate::slave::{Interface, Lifecycle};
use crate::state::FmiState;
use crate::status::FmiResult;
use crate::stepping::{Grid, Stepping};
use crate::values::Values;
use crate::vectors::Continuous;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// What every instance of a [`Model`] keeps. Everything but the log is part of its FMU state.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Core<S> {
    /// Co-Simulation, or Model Exchange (the importer integrates).
    pub interface: Interface,
    /// Parameters and inputs as last set.
    pub values: Values,
    /// From fmi2SetupExperiment: the simulation starts there, with that relative tolerance
    /// (the model's [`Model::DEFAULT_TOLERANCE`] where the importer gives none).
    pub start_time: f64,
    pub tolerance: Option<f64>,
    /// The running simulation; built at fmi2ExitInitializationMode (and for reads during
    /// initialisation, from the values set so far).
    pub sim: Option<S>,
    /// Log categories switched on and lines waiting for the importer's logger.
    #[serde(skip)]
    pub log: Log,
}

impl<S> Core<S> {
    /// The running simulation (the instance is initialised).
    pub fn running(&self) -> &S {
        self.sim.as_ref().expect("initialised")
    }

    pub fn running_mut(&mut self) -> &mut S {
        self.sim.as_mut().expect("initialised")
    }

    /// fmi2SetInteger in `state` (the shell has checked the whole call): the values are
    /// kept, and before initialisation ends the simulation is built again from them.
    pub fn set_integer(&mut self, state: FmiState, vrs: &[u32], values: &[i32]) -> FmiResult {
        for (vr, value) in vrs.iter().zip(values) {
            self.values.set_integer(*vr, i64::from(*value));
        }
        if !state.is_initialised() {
            self.sim = None;
        }
        Ok(())
    }
}

/// A model whose instance keeps a [`Core`]: the shell implements its [`Lifecycle`]
/// (instantiation, the experiment, initialisation, the steps through [`Stepping`]).
pub trait Model: Stepping {
    /// The running model: its state, its solver, its time.
    type Simulation: Clone + Serialize + DeserializeOwned + Continuous;

    /// The relative tolerance where fmi2SetupExperiment gives none (the contract's).
    const DEFAULT_TOLERANCE: f64;

    /// A fresh instance around `core` (the contract's start values, no simulation).
    fn with_core(core: Core<Self::Simulation>) -> Self;

    fn core(&self) -> &Core<Self::Simulation>;

    fn core_mut(&mut self) -> &mut Core<Self::Simulation>;

    /// The simulation at the start time from the values set, integrated with the relative
    /// tolerance `rtol`: every parameter validated (the contract's ranges, the model's rules
    /// between them), or the error of the first that is not.
    fn build(&self, rtol: f64) -> FmiResult<Self::Simulation>;

    /// The simulation built at the experiment's tolerance.
    fn start(&self) -> FmiResult<Self::Simulation> {
        self.build(self.core().tolerance.unwrap_or(Self::DEFAULT_TOLERANCE))
    }

    /// The running simulation, or during initialisation one built from the values so far.
    fn current(&mut self) -> FmiResult<&mut Self::Simulation> {
        if self.core().sim.is_none() {
            let sim = self.start()?;
            self.core_mut().sim = Some(sim);
        }
        Ok(self.core_mut().running_mut())
    }
}

impl<M: Model> Lifecycle for M {
    fn new(logging_on: bool, interface: Interface) -> Self {
        let identity = &M::IDENTITY;
        M::with_core(Core {
            interface,
            values: Values::start(identity.variables),
            start_time: 0.0,
            tolerance: None,
            sim: None,
            log: Log::new(identity.log_categories, logging_on),
        })
    }

    fn interface(&self) -> Interface {
        self.core().interface
    }

    fn log(&mut self) -> &mut Log {
        &mut self.core_mut().log
    }

    fn setup_experiment(&mut self, tolerance: Option<f64>, start_time: f64) {
        let core = self.core_mut();
        core.start_time = start_time;
        core.tolerance = tolerance;
        core.sim = None;
    }

    fn enter_initialization_mode(&mut self) {
        self.core_mut().sim = None;
    }

    /// Validates every parameter and builds the initial state; an invalid parameter is
    /// refused and the instance stays in initialisation mode, where it can be corrected.
    fn exit_initialization_mode(&mut self) -> FmiResult {
        let sim = self.start()?;
        self.core_mut().sim = Some(sim);
        Ok(())
    }

    /// One communication step from the master's point `current` (the shell has checked it
    /// against the time); a failure leaves the state at `current`.
    fn step(&mut self, current: f64, h: f64) -> FmiResult {
        self.step_until(current, current + h, false).map(|_| ())
    }

    /// Early return (FMI 3.0): the step ends at the model's first event inside it.
    const STEPS_TO_EVENTS: bool = true;

    fn step_to_event(&mut self, current: f64, t_end: f64) -> FmiResult<f64> {
        self.step_until(current, t_end, true)
    }

    fn sample(&mut self, grid: &Grid, vrs: &[u32], out: &mut [f64]) -> usize {
        self.serve_sampled(grid, vrs, out)
    }
}
