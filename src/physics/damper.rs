//! The clutch damper between the flywheel and the input side (docs/GEARBOX.md §2): a two-stage
//! spring (the pre-damper k_1 over |φ| ≤ φ_1, the main stage k_2 beyond), each stage with its
//! hysteresis friction H regularised by tanh(φ'/ω_h), and a viscous c_cl:
//!
//!   T_cl = T_k(φ) + H(φ) tanh(φ'/ω_h) + c_cl φ'
//!
//! T_k has a kink and H a jump at ±φ_1: the stages are pieces whose edges ±φ_1 a step ends
//! on, as the contact law's bands are.
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

/// The damper's parameters (docs/GEARBOX.md §2, §6), in SI units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DamperParams {
    /// Pre-damper (idle stage) stiffness k_1 [N m/rad].
    pub k_1: f64,
    /// Main-stage stiffness k_2 [N m/rad].
    pub k_2: f64,
    /// Pre-damper travel φ_1 [rad] (each way).
    pub phi_1: f64,
    /// Hysteresis friction of the pre-damper H_1 and of the main stage H_2 [N m].
    pub H_1: f64,
    pub H_2: f64,
    /// Viscous damping c_cl [N m s/rad].
    pub c_cl: f64,
    /// Speed ω_h of the friction's tanh [rad/s].
    pub omega_h: f64,
}

impl DamperParams {
    /// docs/GEARBOX.md §6: k_1 = 0.5 N m/° over ±3°, k_2 = 15 N m/°, H = 0.2 / 3 N m.
    pub fn default_box() -> Self {
        let per_degree = 180.0 / std::f64::consts::PI;
        DamperParams {
            k_1: 0.5 * per_degree,
            k_2: 15.0 * per_degree,
            phi_1: 3.0 / per_degree,
            H_1: 0.2,
            H_2: 3.0,
            c_cl: 0.02,
            omega_h: 0.01,
        }
    }
}

/// The stage the twist φ is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Stage {
    /// φ < −φ_1: main stage, coast side.
    MainMinus,
    /// |φ| ≤ φ_1: pre-damper.
    PreDamper,
    /// φ > φ_1: main stage, drive side.
    MainPlus,
}

impl Stage {
    /// The FMU's stage flag: −1, 0 (pre-damper), +1.
    pub fn sign(self) -> i32 {
        match self {
            Stage::MainMinus => -1,
            Stage::PreDamper => 0,
            Stage::MainPlus => 1,
        }
    }
}

/// ∂T_cl/∂φ and ∂T_cl/∂φ' [N m/rad, N m s/rad].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DamperSlopes {
    pub d_phi: f64,
    pub d_phi_dot: f64,
}

/// The damper's torque as a function of the twist and its rate, stage by stage.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Damper {
    pub params: DamperParams,
    inv_omega_h: f64,
}

impl Damper {
    pub fn new(params: DamperParams) -> Self {
        Damper {
            params,
            inv_omega_h: 1.0 / params.omega_h,
        }
    }

    /// The stage that contains φ (the pre-damper taken closed, [−φ_1, φ_1]).
    pub fn classify(&self, phi: f64) -> Stage {
        let phi_1 = self.params.phi_1;
        if phi < -phi_1 {
            Stage::MainMinus
        } else if phi <= phi_1 {
            Stage::PreDamper
        } else {
            Stage::MainPlus
        }
    }

    /// Interval of φ over which `stage`'s formula is the damper's law.
    pub fn bounds(&self, stage: Stage) -> (f64, f64) {
        let phi_1 = self.params.phi_1;
        match stage {
            Stage::MainMinus => (f64::NEG_INFINITY, -phi_1),
            Stage::PreDamper => (-phi_1, phi_1),
            Stage::MainPlus => (phi_1, f64::INFINITY),
        }
    }

    /// The stage entered when φ leaves `stage` downwards.
    pub fn below(&self, stage: Stage) -> Stage {
        match stage {
            Stage::MainPlus => Stage::PreDamper,
            Stage::PreDamper | Stage::MainMinus => Stage::MainMinus,
        }
    }

    /// The stage entered when φ leaves `stage` upwards.
    pub fn above(&self, stage: Stage) -> Stage {
        match stage {
            Stage::MainMinus => Stage::PreDamper,
            Stage::PreDamper | Stage::MainPlus => Stage::MainPlus,
        }
    }

    /// The spring's torque T_k(φ) with `stage`'s formula: k_1 φ, or
    /// ±k_1 φ_1 + k_2 (φ ∓ φ_1) in the main stage.
    #[inline]
    pub fn spring(&self, stage: Stage, phi: f64) -> f64 {
        let p = &self.params;
        match stage {
            Stage::PreDamper => p.k_1 * phi,
            Stage::MainPlus => p.k_1 * p.phi_1 + p.k_2 * (phi - p.phi_1),
            Stage::MainMinus => -p.k_1 * p.phi_1 + p.k_2 * (phi + p.phi_1),
        }
    }

    /// The friction and viscous torque H tanh(φ'/ω_h) + c_cl φ' with `stage`'s H: what the
    /// damper dissipates, at the power (this) · φ' ≥ 0.
    #[inline]
    pub fn dissipative(&self, stage: Stage, phi_dot: f64) -> f64 {
        let p = &self.params;
        self.friction(stage) * (phi_dot * self.inv_omega_h).tanh() + p.c_cl * phi_dot
    }

    /// T_cl = T_k + H tanh(φ'/ω_h) + c_cl φ' with `stage`'s formulas.
    #[inline]
    pub fn torque(&self, stage: Stage, phi: f64, phi_dot: f64) -> f64 {
        self.spring(stage, phi) + self.dissipative(stage, phi_dot)
    }

    /// ∂T_cl/∂φ and ∂T_cl/∂φ' with `stage`'s formulas.
    pub fn slopes(&self, stage: Stage, phi_dot: f64) -> DamperSlopes {
        let p = &self.params;
        let tanh = (phi_dot * self.inv_omega_h).tanh();
        DamperSlopes {
            d_phi: if stage == Stage::PreDamper {
                p.k_1
            } else {
                p.k_2
            },
            d_phi_dot: self.friction(stage) * (1.0 - tanh * tanh) * self.inv_omega_h + p.c_cl,
        }
    }

    /// The spring's energy V_cl(φ) = ∫_0^φ T_k dφ (continuous across ±φ_1).
    pub fn potential(&self, phi: f64) -> f64 {
        let p = &self.params;
        let a = phi.abs();
        if a <= p.phi_1 {
            0.5 * p.k_1 * phi * phi
        } else {
            let beyond = a - p.phi_1;
            0.5 * p.k_1 * p.phi_1 * p.phi_1
                + p.k_1 * p.phi_1 * beyond
                + 0.5 * p.k_2 * beyond * beyond
        }
    }

    fn friction(&self, stage: Stage) -> f64 {
        if stage == Stage::PreDamper {
            self.params.H_1
        } else {
            self.params.H_2
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn damper() -> Damper {
        Damper::new(DamperParams::default_box())
    }

    /// docs/GEARBOX.md §2 by hand: 2° in the pre-damper is 1 N m, 5° is 0.5·3 + 15·2 = 31.5 N m
    /// (−31.5 at −5°); the friction is ±H at speeds well above ω_h, 0 at rest.
    #[test]
    fn torque_by_hand() {
        let d = damper();
        let deg = std::f64::consts::PI / 180.0;
        assert!((d.spring(d.classify(2.0 * deg), 2.0 * deg) - 1.0).abs() < 1e-12);
        assert!((d.spring(d.classify(5.0 * deg), 5.0 * deg) - 31.5).abs() < 1e-12);
        assert!((d.spring(d.classify(-5.0 * deg), -5.0 * deg) + 31.5).abs() < 1e-12);
        assert_eq!(d.dissipative(Stage::PreDamper, 0.0), 0.0);
        let fast = d.dissipative(Stage::MainPlus, 10.0);
        assert!((fast - (3.0 + 0.02 * 10.0)).abs() < 1e-12, "{fast}");
        assert!((d.dissipative(Stage::PreDamper, -10.0) + 0.2 + 0.2).abs() < 1e-12);
    }

    /// T_k is continuous at ±φ_1 (both stages' formulas agree there), V_cl' = T_k, and the
    /// slopes match central differences.
    #[test]
    fn spring_is_continuous_and_its_potential_integrates_it() {
        let d = damper();
        let phi_1 = d.params.phi_1;
        for edge in [-phi_1, phi_1] {
            let outer = d.classify(edge * 1.5);
            let gap = d.spring(Stage::PreDamper, edge) - d.spring(outer, edge);
            assert!(gap.abs() < 1e-12, "{gap}");
        }
        for phi in [-0.2, -0.06, -0.01, 0.0, 0.03, 0.052, 0.07, 0.3] {
            let h = 1e-7;
            let stage = d.classify(phi);
            let dv = (d.potential(phi + h) - d.potential(phi - h)) / (2.0 * h);
            assert!((dv - d.spring(stage, phi)).abs() < 1e-6, "{phi}: {dv}");
            for phi_dot in [-0.3, -0.004, 0.0, 0.02, 5.0] {
                let s = d.slopes(stage, phi_dot);
                let t = |x: f64, v: f64| d.torque(stage, x, v);
                let d_phi = (t(phi + h, phi_dot) - t(phi - h, phi_dot)) / (2.0 * h);
                let d_dot = (t(phi, phi_dot + 1e-6) - t(phi, phi_dot - 1e-6)) / 2e-6;
                assert!((s.d_phi - d_phi).abs() < 1e-5 * d_phi.abs(), "{phi}");
                assert!(
                    (s.d_phi_dot - d_dot).abs() < 1e-5 * d_dot.abs().max(1.0),
                    "{phi} {phi_dot}: {} vs {d_dot}",
                    s.d_phi_dot
                );
            }
        }
    }

    #[test]
    fn stages_are_consistent_with_bounds() {
        let d = damper();
        for k in -40..=40 {
            let phi = k as f64 * 0.005;
            let (lo, hi) = d.bounds(d.classify(phi));
            assert!(lo <= phi && phi <= hi, "{phi}");
        }
        assert_eq!(d.above(Stage::PreDamper), Stage::MainPlus);
        assert_eq!(d.below(Stage::MainPlus), Stage::PreDamper);
        assert_eq!(d.below(Stage::PreDamper), Stage::MainMinus);
        assert_eq!(d.above(Stage::MainMinus), Stage::PreDamper);
    }
}
