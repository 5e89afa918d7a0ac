//! The running model of an initialised instance: the rattle, its solver, the clock, the
//! state, and what drives the main shaft. Outputs are computed here when they are read.
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

use super::error::{FmiError, FmiResult};
use super::values::Values;
use crate::contract::vr;
use crate::integrator::{Method, Piecewise, Solver, SolverError};
use crate::physics::{Dynamics, Excitation, GearParams, Polynomial, Shaft, Sine};
use crate::rattle::{self, E_CONTACT, E_LUBRICANT, Rattle, State, XI, XI_DOT};

/// Values of the `excitation` parameter.
pub const EXCITATION_INPUTS: i64 = 0;
pub const EXCITATION_SINE: i64 = 1;

/// Values of the `solver` parameter.
fn method(values: &Values) -> FmiResult<Method> {
    match values.integer(vr::solver) {
        0 => Ok(Method::Auto),
        1 => Ok(Method::Explicit),
        2 => Ok(Method::Implicit),
        other => Err(FmiError::error(format!(
            "parameter solver = {other} is invalid: allowed 0 (auto), 1 (DOPRI5) or 2 (Radau IIA)"
        ))),
    }
}

/// What moves the main shaft.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Drive {
    /// The paper's bench: exact sine motion, a function of time.
    Sine(Sine),
    /// The drivetrain's inputs: the shaft's motion at the current time, extrapolated over
    /// each step as a Taylor polynomial (MODEL.md §5: never a zero-order hold).
    Inputs(Shaft),
}

/// An initialised gear pair being stepped.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Simulation {
    pub rattle: Rattle,
    pub solver: Solver<{ rattle::N }>,
    pub t: f64,
    pub y: State,
    pub drive: Drive,
}

fn param(values: &Values, vr: u32) -> f64 {
    values.real(vr)
}

/// The gear parameters as set.
pub fn gear_params(values: &Values) -> GearParams {
    GearParams {
        I_L: param(values, vr::I_L),
        r_L: param(values, vr::r_L),
        r_M: param(values, vr::r_M),
        K_star: param(values, vr::K_star),
        alpha: param(values, vr::alpha),
        epsilon: param(values, vr::epsilon),
        G: param(values, vr::G),
        C_LM: param(values, vr::C_LM),
        C: param(values, vr::C),
        B: param(values, vr::B),
        omega_S: param(values, vr::omega_S),
    }
}

/// Checks that a parameter outside the gear's nine is finite and within its range.
fn check(name: &str, value: f64, ok: bool, allowed: &str) -> FmiResult {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(FmiError::error(format!(
            "parameter {name} = {value:e} is invalid: allowed {allowed}"
        )))
    }
}

impl Simulation {
    /// Validates the parameters and builds the initial state at t0 (MODEL.md §1:
    /// ξ(0) = gap_start·G, ξ'(0) = xi_dot_start).
    pub fn new(values: &Values, t0: f64, rtol: f64) -> FmiResult<Self> {
        let params = gear_params(values);
        params
            .validate()
            .map_err(|e| FmiError::error(e.to_string()))?;
        let f_exc = param(values, vr::f_exc);
        let a_rms = param(values, vr::A_rms);
        let omega_mean = param(values, vr::omega_mean);
        let gap_start = param(values, vr::gap_start);
        let xi_dot_start = param(values, vr::xi_dot_start);
        check("f_exc", f_exc, f_exc > 0.0, "finite and > 0")?;
        check("A_rms", a_rms, true, "finite")?;
        check("omega_mean", omega_mean, true, "finite")?;
        check("gap_start", gap_start, true, "finite")?;
        check("xi_dot_start", xi_dot_start, true, "finite")?;
        let drive = match values.integer(vr::excitation) {
            EXCITATION_INPUTS => Drive::Inputs(Shaft {
                theta: param(values, vr::theta_M),
                omega: param(values, vr::omega_M),
                alpha: param(values, vr::alpha_M),
            }),
            EXCITATION_SINE => Drive::Sine(Sine::new(a_rms, f_exc, omega_mean)),
            other => {
                return Err(FmiError::error(format!(
                    "parameter excitation = {other} is invalid: allowed 0 (inputs) or 1 (sine)"
                )));
            }
        };
        let dynamics = Dynamics::new(params);
        let xi = gap_start * params.G;
        let excitation = Self::excitation_from(drive, t0);
        let rattle = Rattle::new(dynamics, excitation, xi);
        let mut y = [0.0; rattle::N];
        y[XI] = xi;
        y[XI_DOT] = xi_dot_start;
        let mut solver = Solver::with_method(rattle.tolerance(rtol), method(values)?);
        // The bench's sine does not change between steps: communication points are served
        // from the dense output of natural steps. Inputs change at every step: steps end on
        // the communication points, where the new inputs apply.
        solver.interpolate_ends = matches!(drive, Drive::Sine(_));
        Ok(Simulation {
            solver,
            rattle,
            t: t0,
            y,
            drive,
        })
    }

    fn excitation_from(drive: Drive, t: f64) -> Excitation {
        match drive {
            Drive::Sine(s) => Excitation::Sine(s),
            Drive::Inputs(shaft) => Excitation::Polynomial(Polynomial {
                t0: t,
                at_t0: shaft,
            }),
        }
    }

    /// The main shaft's motion now.
    pub fn shaft(&self) -> Shaft {
        self.rattle.excitation.at(self.t)
    }

    /// New input values for the main shaft (inputs mode). The loose gear does not move, so
    /// ξ and ξ' follow the shaft (ξ = r_L θ_L − r_M θ_M): reading them right after reflects
    /// the new inputs (direct feedthrough). In sine mode the inputs are not used.
    pub fn set_shaft(&mut self, shaft: Shaft) {
        let Drive::Inputs(old) = self.drive else {
            return;
        };
        let r_M = self.rattle.dynamics.params.r_M;
        self.y[XI] += r_M * (old.theta - shaft.theta);
        self.y[XI_DOT] += r_M * (old.omega - shaft.omega);
        self.drive = Drive::Inputs(shaft);
        self.rattle.excitation = Self::excitation_from(self.drive, self.t);
        self.rattle.settle(self.t, &self.y);
        self.solver.invalidate();
    }

    /// Advances to t_end. On failure the simulation is left as it was.
    pub fn step_to(&mut self, t_end: f64) -> Result<(), SolverError> {
        let mut next = *self;
        next.solver
            .advance(&mut next.rattle, &mut next.t, &mut next.y, t_end)?;
        next.t = t_end;
        if let Drive::Inputs(_) = next.drive {
            // The shaft continues along its extrapolation unless the master sets new inputs.
            next.drive = Drive::Inputs(next.rattle.excitation.at(t_end));
        }
        *self = next;
        Ok(())
    }

    /// The value of a Real output, computed now; None if `vr` is not a Real output.
    pub fn real_output(&self, vr: u32) -> Option<f64> {
        let dynamics = &self.rattle.dynamics;
        let shaft = self.shaft();
        let loads = || dynamics.loads(self.rattle.region, self.y[XI], self.y[XI_DOT], &shaft);
        Some(match vr {
            vr::theta_L => dynamics.theta_L(self.y[XI], &shaft),
            vr::omega_L => loads().omega_L,
            vr::alpha_L => loads().alpha_L,
            vr::a_pitch_L => dynamics.params.r_L * loads().alpha_L,
            vr::xi => self.y[XI],
            vr::xi_dot => self.y[XI_DOT],
            vr::F_contact => loads().force.total(),
            vr::tau_M => dynamics.tau_M(&loads()),
            vr::impact_speed => self.rattle.impacts.last_speed,
            vr::E_contact => self.y[E_CONTACT],
            vr::E_lubricant => self.y[E_LUBRICANT],
            vr::theta_M_out => shaft.theta,
            vr::omega_M_out => shaft.omega,
            vr::alpha_M_out => shaft.alpha,
            vr::solver_steps => self.solver.stats.accepted as f64,
            vr::solver_rejected => self.solver.stats.rejected as f64,
            vr::solver_rhs => self.solver.stats.rhs_evals as f64,
            vr::solver_implicit_steps => self.solver.stats.implicit_steps as f64,
            _ => return None,
        })
    }

    /// First time derivative of a Real output (maxOutputDerivativeOrder = 1), from the
    /// equations of motion at the current state; None where the model has none to give.
    pub fn real_output_derivative(&self, vr: u32) -> Option<f64> {
        let dynamics = &self.rattle.dynamics;
        let p = &dynamics.params;
        let shaft = self.shaft();
        let (xi, xi_dot) = (self.y[XI], self.y[XI_DOT]);
        let loads = dynamics.loads(self.rattle.region, xi, xi_dot, &shaft);
        let force_rate = || {
            let slopes = dynamics.law.slopes(self.rattle.region, xi, xi_dot);
            slopes.d_xi * xi_dot + slopes.d_xi_dot * loads.xi_ddot
        };
        Some(match vr {
            vr::xi => xi_dot,
            vr::xi_dot => loads.xi_ddot,
            vr::theta_L => loads.omega_L,
            vr::omega_L => loads.alpha_L,
            vr::F_contact => force_rate(),
            vr::tau_M => p.r_M * force_rate(),
            vr::theta_M_out => shaft.omega,
            vr::omega_M_out => shaft.alpha,
            _ => return None,
        })
    }

    /// ∂output/∂input at the current state: how an output read right after new inputs moves
    /// with them (direct feedthrough; MODEL.md §3 with ξ = r_L θ_L − r_M θ_M at fixed θ_L).
    /// Zero for inputs the current excitation does not use. ∂τ_M/∂θ_M and ∂τ_M/∂ω_M are the
    /// coupling stiffness and damping a master sees.
    pub fn partial(&self, output: u32, input: u32) -> f64 {
        if !matches!(self.drive, Drive::Inputs(_)) {
            return 0.0;
        }
        let dynamics = &self.rattle.dynamics;
        let p = &dynamics.params;
        let slopes = dynamics
            .law
            .slopes(self.rattle.region, self.y[XI], self.y[XI_DOT]);
        // ∂ξ/∂θ_M = −r_M and ∂ξ'/∂ω_M = −r_M; ∂F follows through the contact law.
        let d_force = match input {
            vr::theta_M => -p.r_M * slopes.d_xi,
            vr::omega_M => -p.r_M * slopes.d_xi_dot,
            _ => 0.0,
        };
        match (output, input) {
            (vr::xi, vr::theta_M) | (vr::xi_dot, vr::omega_M) => -p.r_M,
            (vr::theta_M_out, vr::theta_M)
            | (vr::omega_M_out, vr::omega_M)
            | (vr::alpha_M_out, vr::alpha_M) => 1.0,
            (vr::F_contact, _) => d_force,
            (vr::tau_M, _) => p.r_M * d_force,
            (vr::alpha_L, _) => -p.r_L / p.I_L * d_force,
            (vr::a_pitch_L, _) => -p.r_L * p.r_L / p.I_L * d_force,
            _ => 0.0,
        }
    }

    /// The value of an Integer output; None if `vr` is not an Integer output.
    pub fn integer_output(&self, vr: u32) -> Option<i64> {
        let count = &self.rattle.impacts.count;
        Some(match vr {
            vr::contact => self.rattle.region.flank() as i64,
            vr::impacts_Fplus => count[0] as i64,
            vr::impacts_Fminus => count[1] as i64,
            vr::solver_method => {
                if self.solver.is_implicit() {
                    2
                } else {
                    1
                }
            }
            _ => return None,
        })
    }
}
