//! The slave for fmi2-shell: the flywheel's variables and stepping as methods that return
//! `Ok(())` or the reason of a refusal. The shell applies FMI's rules (state machine, time
//! checks, what may be set when) before calling in.
#![allow(non_snake_case)]

use crate::contract::{self, Causality, Kind, LOG_CATEGORIES, VARIABLES, vr};
use crate::model::{Params, State};
use fmi2_shell::values::Values;
use fmi2_shell::{FmiError, FmiResult, FmiState, Identity, Interface, Lifecycle, Log, Slave};
use serde::{Deserialize, Serialize};

/// The model's part of what determines the future of an instance (what fmi2GetFMUstate
/// saves), and its log.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Instance {
    pub y: State,
    /// Parameters and the input, by value reference.
    values: Values,
    /// d tau_M / dt from fmi2SetRealInputDerivatives (0 unless set; kept until set again).
    tau_dot: f64,
    /// The parameters, checked at fmi2ExitInitializationMode.
    params: Option<Params>,
    #[serde(skip)]
    log: Log,
}

fn error(message: String) -> FmiError {
    FmiError::error(message)
}

impl Instance {
    fn build(&self) -> FmiResult<Params> {
        Params::from(|vr| self.values.real(vr)).map_err(error)
    }

    /// Parameters and state used for outputs: during initialisation, the initial state from
    /// the parameters set so far.
    fn current(&self) -> FmiResult<(Params, State)> {
        match self.params {
            Some(p) => Ok((p, self.y)),
            None => {
                let p = self.build()?;
                Ok((p, p.initial_state()))
            }
        }
    }

    fn tau_M(&self) -> f64 {
        self.values.real(vr::tau_M)
    }
}

/// The flywheel's simulation is its parameters and state, without a solver or a tolerance:
/// it makes, initialises and steps itself.
impl Lifecycle for Instance {
    fn new(logging_on: bool, _interface: Interface) -> Self {
        Instance {
            y: [0.0; 4],
            values: Values::start(VARIABLES),
            tau_dot: 0.0,
            params: None,
            log: Log::new(LOG_CATEGORIES, logging_on),
        }
    }

    fn log(&mut self) -> &mut Log {
        &mut self.log
    }

    /// Checks the parameters and sets the initial state: both shafts at idle speed.
    fn exit_initialization_mode(&mut self) -> FmiResult {
        let p = self.build()?;
        self.y = p.initial_state();
        self.params = Some(p);
        Ok(())
    }

    /// One step of h from `current` (the shell has checked both).
    fn step(&mut self, current: f64, h: f64) -> FmiResult {
        let p = self.params.expect("initialised");
        let tau = self.tau_M();
        let y = p.advance(&self.y, tau, self.tau_dot, h);
        if y.iter().any(|x| !x.is_finite()) {
            return Err(error(format!(
                "the state is no longer finite at t = {}",
                current + h
            )));
        }
        self.y = y;
        // The input follows its ramp until the master sets it again.
        self.values.set_real(vr::tau_M, tau + self.tau_dot * h);
        Ok(())
    }
}

impl Slave for Instance {
    const IDENTITY: Identity = Identity {
        guid: contract::GUID,
        model_identifier: contract::MODEL_IDENTIFIER,
        log_categories: LOG_CATEGORIES,
        state_magic: *b"FLYS",
        state_version: 3,
        model_exchange: false,
        variable: contract::variable,
        variables: contract::VARIABLES,
        arrays: contract::FMI3_ARRAYS,
    };

    fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> FmiResult {
        for (vr, out) in vrs.iter().zip(out.iter_mut()) {
            *out = match contract::variable(Kind::Real, *vr)?.causality {
                Causality::Output => {
                    let (p, y) = self.current()?;
                    p.output(*vr, &y, self.tau_M())
                        .expect("every output is computed")
                }
                _ => self.values.real(*vr),
            };
        }
        Ok(())
    }

    /// Sets parameters (before fmi2ExitInitializationMode) and the input (the shell has
    /// checked the whole call).
    fn set_real(&mut self, _state: FmiState, vrs: &[u32], values: &[f64]) -> FmiResult {
        for (vr, value) in vrs.iter().zip(values) {
            self.values.set_real(*vr, *value);
        }
        Ok(())
    }

    /// fmi2SetRealInputDerivatives: order 1 of tau_M, a ramp over the following steps.
    fn set_input_derivatives(
        &mut self,
        _state: FmiState,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> FmiResult {
        for ((vr, order), value) in vrs.iter().zip(orders).zip(values) {
            if *vr != vr::tau_M || *order != 1 || !value.is_finite() {
                return Err(error(format!(
                    "input derivative of order {order} = {value} for value reference {vr} refused: only the first derivative of tau_M ({}), finite",
                    vr::tau_M
                )));
            }
        }
        if let Some(value) = values.last() {
            self.tau_dot = *value;
        }
        Ok(())
    }

    /// fmi2GetRealOutputDerivatives (order 1).
    fn output_derivative(&mut self, vr: u32) -> FmiResult<f64> {
        let (p, y) = self.current()?;
        p.output_derivative(vr, &y, self.tau_M(), self.tau_dot)
            .ok_or_else(|| error(format!("value reference {vr} is not a Real output")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fmi2_shell::Fmu;
    use fmi2_shell::fmu_state::{deserialize, serialize};

    fn running() -> Fmu<Instance> {
        let mut i = Fmu::<Instance>::new(false, Interface::CoSimulation);
        i.setup_experiment(None, 0.0).unwrap();
        i.enter_initialization_mode().unwrap();
        i.exit_initialization_mode().unwrap();
        i
    }

    #[test]
    fn rollback_is_bit_identical() {
        let mut i = running();
        i.set_real(&[vr::tau_M], &[-1.5]).unwrap();
        i.set_input_derivatives(&[vr::tau_M], &[1], &[30.0])
            .unwrap();
        i.do_step(0.0, 1e-3).unwrap();
        let saved: Fmu<Instance> = deserialize(&serialize(&i)).unwrap();
        i.do_step(1e-3, 2.5e-3).unwrap();
        let first = serialize(&i);
        let mut j = Fmu::<Instance>::new(false, Interface::CoSimulation);
        j.restore(&saved).unwrap();
        j.do_step(1e-3, 2.5e-3).unwrap();
        assert_eq!(serialize(&j), first);
        assert_eq!(serialize(&j.snapshot()), first);
    }

    #[test]
    fn corrupt_state_is_refused() {
        let mut b = serialize(&running());
        b[20] ^= 1;
        let refused = |b: &[u8]| deserialize::<Instance>(b).unwrap_err().message;
        assert!(refused(&b).contains("checksum"));
        assert!(refused(&b[..10]).contains("FLYS") || refused(&b[..10]).contains("length"));
    }

    #[test]
    fn parameters_are_fixed_after_initialisation() {
        let mut i = running();
        assert!(i.set_real(&[vr::k_d], &[1.0]).is_err());
        assert!(i.set_real(&[vr::theta_M], &[1.0]).is_err());
        assert!(i.set_real(&[vr::tau_M], &[f64::NAN]).is_err());
    }

    #[test]
    fn invalid_parameter_keeps_initialisation_mode() {
        let mut i = Fmu::<Instance>::new(false, Interface::CoSimulation);
        i.enter_initialization_mode().unwrap();
        i.set_real(&[vr::I_M], &[0.0]).unwrap();
        assert!(
            i.exit_initialization_mode()
                .unwrap_err()
                .message
                .contains("I_M")
        );
        assert_eq!(i.state, FmiState::InitializationMode);
        i.set_real(&[vr::I_M], &[0.01]).unwrap();
        i.exit_initialization_mode().unwrap();
    }

    #[test]
    fn long_step_equals_sub_steps() {
        // A 1 ms step is cut into 10 sub-steps of 0.1 ms: the same as ten 0.1 ms steps.
        let mut a = running();
        let mut b = running();
        a.do_step(0.0, 1e-3).unwrap();
        for k in 0..10 {
            b.do_step(f64::from(k) * 1e-4, 1e-4).unwrap();
        }
        for (x, y) in a.slave.y.iter().zip(&b.slave.y) {
            assert!((x - y).abs() <= 1e-12 * x.abs().max(1.0));
        }
    }
}
