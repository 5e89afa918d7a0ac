//! The drivetrain at idle: engine flywheel, clutch torsional damper, gearbox main shaft.
//! The variables, value references and start values are the contract's
//! (modelDescription/Flywheel.toml, through [`crate::contract`]).
//!
//! Equations (θ_E = θ_M + φ, φ the damper twist; τ_M the input):
//!
//! ```text
//! T_E = T_mean + T_2 sin(2 θ_E)                  gas torque, 2nd engine order (4-cyl. 4-stroke)
//! T_d = k_d φ + c_d (ω_E − ω_M)                  clutch torsional damper
//! I_E ω_E' = T_E − d_E ω_E − T_d                 d_E = T_mean / omega_idle (engine losses)
//! I_M ω_M' = T_d + τ_M                           τ_M: the gear contact's torque on the main shaft
//! θ_M' = ω_M,  φ' = ω_E − ω_M
//! ```
//!
//! The state integrates θ_M itself (what the gear pair needs to the micrometre on its pitch
//! line) and the twist φ, never θ_E − θ_M as a difference of two large angles.
#![allow(non_snake_case)]

use crate::contract::vr;

/// Parameters, validated.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Params {
    pub I_E: f64,
    pub I_M: f64,
    pub k_d: f64,
    pub c_d: f64,
    pub T_mean: f64,
    pub T_2: f64,
    pub omega_idle: f64,
    pub h_max: f64,
}

/// State: θ_M, ω_M, φ = θ_E − θ_M, ω_E.
pub type State = [f64; 4];
const TH_M: usize = 0;
const OM_M: usize = 1;
const PHI: usize = 2;
const OM_E: usize = 3;

impl Params {
    /// Reads the parameters through `get` (value reference -> value) and checks them.
    pub fn from(get: impl Fn(u32) -> f64) -> Result<Self, String> {
        let p = Params {
            I_E: get(vr::I_E),
            I_M: get(vr::I_M),
            k_d: get(vr::k_d),
            c_d: get(vr::c_d),
            T_mean: get(vr::T_mean),
            T_2: get(vr::T_2),
            omega_idle: get(vr::omega_idle),
            h_max: get(vr::h_max),
        };
        let checks = [
            ("I_E", p.I_E, p.I_E > 0.0, "> 0"),
            ("I_M", p.I_M, p.I_M > 0.0, "> 0"),
            ("k_d", p.k_d, p.k_d > 0.0, "> 0"),
            ("c_d", p.c_d, p.c_d >= 0.0, ">= 0"),
            ("T_mean", p.T_mean, p.T_mean >= 0.0, ">= 0"),
            ("T_2", p.T_2, true, "finite"),
            ("omega_idle", p.omega_idle, p.omega_idle > 0.0, "> 0"),
            ("h_max", p.h_max, p.h_max > 0.0, "> 0"),
        ];
        for (name, value, ok, allowed) in checks {
            if !(ok && value.is_finite()) {
                return Err(format!(
                    "parameter {name} = {value:e} is invalid: allowed {allowed}"
                ));
            }
        }
        Ok(p)
    }

    /// Engine losses per unit speed.
    pub fn d_E(&self) -> f64 {
        self.T_mean / self.omega_idle
    }

    /// Both shafts at idle speed, no twist, θ = 0.
    pub fn initial_state(&self) -> State {
        [0.0, self.omega_idle, 0.0, self.omega_idle]
    }

    pub fn engine_torque(&self, y: &State) -> f64 {
        self.T_mean + self.T_2 * (2.0 * (y[TH_M] + y[PHI])).sin()
    }

    pub fn damper_torque(&self, y: &State) -> f64 {
        self.k_d * y[PHI] + self.c_d * (y[OM_E] - y[OM_M])
    }

    pub fn rhs(&self, y: &State, tau_M: f64) -> State {
        let t_d = self.damper_torque(y);
        [
            y[OM_M],
            (t_d + tau_M) / self.I_M,
            y[OM_E] - y[OM_M],
            (self.engine_torque(y) - self.d_E() * y[OM_E] - t_d) / self.I_E,
        ]
    }

    /// One classical Runge-Kutta step of size h, τ_M = tau_M + tau_dot (t − t_start).
    pub fn rk4(&self, y: &State, tau_M: f64, tau_dot: f64, h: f64) -> State {
        let add = |a: &State, k: &State, c: f64| std::array::from_fn(|i| a[i] + c * k[i]);
        let tau_mid = tau_M + 0.5 * h * tau_dot;
        let k1 = self.rhs(y, tau_M);
        let k2 = self.rhs(&add(y, &k1, 0.5 * h), tau_mid);
        let k3 = self.rhs(&add(y, &k2, 0.5 * h), tau_mid);
        let k4 = self.rhs(&add(y, &k3, h), tau_M + h * tau_dot);
        std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
    }

    /// Advances over h in equal RK4 sub-steps no longer than h_max, with the input
    /// τ_M(t_start + s) = tau_M + tau_dot s (tau_dot = 0 without input derivatives).
    pub fn advance(&self, y: &State, tau_M: f64, tau_dot: f64, h: f64) -> State {
        let n = (h / self.h_max * (1.0 - 1e-12)).ceil().max(1.0) as u64;
        let dt = h / n as f64;
        (0..n).fold(*y, |y, i| {
            self.rk4(&y, tau_M + tau_dot * (i as f64 * dt), tau_dot, dt)
        })
    }

    /// The value of an output at state y and input τ_M; None if `vr` is not an output.
    pub fn output(&self, vr: u32, y: &State, tau_M: f64) -> Option<f64> {
        let dy = || self.rhs(y, tau_M);
        Some(match vr {
            vr::theta_M => y[TH_M],
            vr::omega_M => y[OM_M],
            vr::alpha_M => dy()[OM_M],
            vr::theta_E => y[TH_M] + y[PHI],
            vr::omega_E => y[OM_E],
            vr::T_E => self.engine_torque(y),
            vr::T_d => self.damper_torque(y),
            _ => return None,
        })
    }

    /// First time derivative of an output, with τ_M' = tau_dot (fmi2GetRealOutputDerivatives).
    pub fn output_derivative(&self, vr: u32, y: &State, tau_M: f64, tau_dot: f64) -> Option<f64> {
        let dy = self.rhs(y, tau_M);
        // d/dt T_d = k_d φ' + c_d (ω_E' − ω_M')
        let dt_d = self.k_d * dy[PHI] + self.c_d * (dy[OM_E] - dy[OM_M]);
        Some(match vr {
            vr::theta_M => dy[TH_M],
            vr::omega_M => dy[OM_M],
            vr::alpha_M => (dt_d + tau_dot) / self.I_M,
            vr::theta_E => y[OM_E],
            vr::omega_E => dy[OM_E],
            vr::T_E => 2.0 * self.T_2 * (2.0 * (y[TH_M] + y[PHI])).cos() * y[OM_E],
            vr::T_d => dt_d,
            _ => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contract::{Causality, VARIABLES};
    use fmi2_shell::values::Values;

    fn defaults() -> Params {
        let values = Values::start(VARIABLES);
        Params::from(|vr| values.real(vr)).unwrap()
    }

    #[test]
    fn rk4_is_fourth_order() {
        // with tau_M = 0 the error of one RK4 run over 10 ms falls ~16x when h halves
        let p = defaults();
        let y0 = p.initial_state();
        let run = |n: u32| (0..n).fold(y0, |y, _| p.rk4(&y, 0.0, 0.0, 0.01 / f64::from(n)));
        let exact = run(4096);
        let e1 = (run(8)[1] - exact[1]).abs();
        let e2 = (run(16)[1] - exact[1]).abs();
        assert!(e1 / e2 > 12.0 && e1 / e2 < 20.0, "ratio {}", e1 / e2);
    }

    #[test]
    fn energy_balance_without_losses() {
        // T_mean = 0 (no losses), c_d = 0, T_2 = 0: kinetic + damper energy is constant
        let p = Params {
            T_mean: 0.0,
            T_2: 0.0,
            c_d: 0.0,
            ..defaults()
        };
        let y0 = [0.0, 80.0, 0.01, 90.0];
        let energy = |y: &State| {
            0.5 * p.I_M * y[1] * y[1] + 0.5 * p.I_E * y[3] * y[3] + 0.5 * p.k_d * y[2] * y[2]
        };
        let y = p.advance(&y0, 0.0, 0.0, 0.2);
        assert!((energy(&y) / energy(&y0) - 1.0).abs() < 1e-10);
    }

    #[test]
    fn output_derivatives_match_finite_differences() {
        // tau_M(t) = -0.3 + 40 (t - t1) around t1: central differences of the outputs
        let p = defaults();
        let (tau, tau_dot, h) = (-0.3, 40.0, 1e-7);
        let y = p.advance(&p.initial_state(), tau, 0.0, 0.0137);
        let ya = p.advance(&y, tau, tau_dot, h);
        let yb = p.advance(&y, tau, tau_dot, -h);
        for v in VARIABLES
            .iter()
            .filter(|v| v.causality == Causality::Output)
        {
            let out = |y: &State, dt: f64| p.output(v.vr, y, tau + tau_dot * dt).unwrap();
            let fd = (out(&ya, h) - out(&yb, -h)) / (2.0 * h);
            let d = p.output_derivative(v.vr, &y, tau, tau_dot).unwrap();
            assert!(
                (fd - d).abs() <= 1e-5 * d.abs().max(1.0),
                "{}: {d} vs {fd}",
                v.name
            );
        }
    }

    #[test]
    fn input_derivative_is_integrated_exactly_enough() {
        // a ramp of tau_M over one 1 ms step: 10 sub-steps agree with 1000 of them (RK4 error)
        let p = defaults();
        let y0 = p.initial_state();
        let coarse = p.advance(&y0, -1.0, 500.0, 1e-3);
        let fine = Params { h_max: 1e-6, ..p }.advance(&y0, -1.0, 500.0, 1e-3);
        assert!(
            (coarse[1] - fine[1]).abs() < 1e-9,
            "{} vs {}",
            coarse[1],
            fine[1]
        );
        // and differs from a held tau_M by the ramp's effect, 500 h^2 / (2 I_M), to within the
        // damper's reaction over the step (c_d h / (3 I_M) ~ 1 %)
        let held = p.advance(&y0, -1.0, 0.0, 1e-3);
        let effect = 500.0 * 1e-6 / (2.0 * p.I_M);
        assert!(((coarse[1] - held[1]) / effect - 1.0).abs() < 0.05);
    }
}
