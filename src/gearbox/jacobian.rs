//! ∂f/∂y of the gearbox's right-hand side for Radau IIA, analytic. The structure is an
//! arrow: each gear's ξ_i, ξ_i' couple with themselves and, through α_I, with φ' and with
//! every other gear's contact force; φ, φ' couple with every gear through α_I. With
//! u = ω_I = ω_F − φ' and the slopes of the contact law (docs/MODEL.md §2) and of the damper
//! (docs/GEARBOX.md §2):
//!
//!   ∂α_I/∂φ = T_φ / I_I,  ∂α_I/∂φ' = (T_φ' + c_I) / I_I,
//!   ∂α_I/∂ξ_j = ρ_j r_M,j F_ξ,j / I_I,  ∂α_I/∂ξ_j' = ρ_j r_M,j F_ξ',j / I_I,
//!   ∂ω_L,i'/∂ξ_i = −r_L F_ξ / I_L,  ∂ω_L,i'/∂ξ_i' = −(r_L F_ξ' + C / r_L) / I_L,
//!   ∂ω_L,i'/∂u = −C r_M ρ / (r_L I_L),
//!
//! φ'' = α_F − α_I and ξ_i'' = r_L ω_L,i' − r_M ρ α_I. Under a ramp ω_F is a state whose
//! column enters through u. The quadratures' rows stay zero, as for the gear pair
//! ([`crate::rattle::Rattle`]'s Jacobian).

use super::{Gearbox, N, PHI, PHI_DOT, State, omega_F, xi, xi_dot};
use crate::integrator::Jacobian;

impl Jacobian<N> for Gearbox {
    fn jacobian(&self, _t: f64, y: &State) -> [[f64; N]; N] {
        if self.imposed_input().is_some() {
            return self.imposed_jacobian(y);
        }
        let n = self.n;
        let ramp = self.integrates_flywheel();
        let damper = self.damper.slopes(self.stage, y[PHI_DOT]);
        // ∂α_I/∂y over the dynamic columns.
        let mut d_alpha_I = [0.0; N];
        d_alpha_I[PHI] = damper.d_phi * self.inv_I_I;
        d_alpha_I[PHI_DOT] = (damper.d_phi_dot + self.c_I) * self.inv_I_I;
        if ramp {
            d_alpha_I[omega_F(n)] = -self.c_I * self.inv_I_I;
        }
        for (i, gear) in self.gears[..n].iter().enumerate() {
            let slopes = gear
                .dynamics
                .law
                .slopes(gear.region, y[xi(i)], y[xi_dot(i)]);
            let lever = gear.rho * gear.dynamics.params.r_M * self.inv_I_I;
            d_alpha_I[xi(i)] = lever * slopes.d_xi;
            d_alpha_I[xi_dot(i)] = lever * slopes.d_xi_dot;
        }
        let mut j = [[0.0; N]; N];
        j[PHI][PHI_DOT] = 1.0;
        for c in 0..xi(n) + usize::from(ramp) {
            j[PHI_DOT][c] = -d_alpha_I[c];
        }
        for (i, gear) in self.gears[..n].iter().enumerate() {
            let p = &gear.dynamics.params;
            let slopes = gear
                .dynamics
                .law
                .slopes(gear.region, y[xi(i)], y[xi_dot(i)]);
            let coupling = gear.rho * p.r_M;
            let row = &mut j[xi_dot(i)];
            for c in 0..xi(n) + usize::from(ramp) {
                row[c] = -coupling * d_alpha_I[c];
            }
            // r_L ∂ω_L'/∂·, own columns and through u = ω_F − φ'.
            let d_omega_L_du = -p.C * coupling / (p.r_L * p.I_L);
            row[xi(i)] -= p.r_L * p.r_L * slopes.d_xi / p.I_L;
            row[xi_dot(i)] -= (p.r_L * p.r_L * slopes.d_xi_dot + p.C) / p.I_L;
            row[PHI_DOT] -= p.r_L * d_omega_L_du;
            if ramp {
                row[omega_F(n)] += p.r_L * d_omega_L_du;
            }
            j[xi(i)][xi_dot(i)] = 1.0;
        }
        j
    }
}

impl Gearbox {
    /// With the input side's motion imposed the gears are GearRattle's pairs side by side:
    /// each gear's own block only, φ and φ' constant.
    fn imposed_jacobian(&self, y: &State) -> [[f64; N]; N] {
        let mut j = [[0.0; N]; N];
        for (i, gear) in self.gears[..self.n].iter().enumerate() {
            let p = &gear.dynamics.params;
            let slopes = gear
                .dynamics
                .law
                .slopes(gear.region, y[xi(i)], y[xi_dot(i)]);
            j[xi(i)][xi_dot(i)] = 1.0;
            j[xi_dot(i)][xi(i)] = -p.r_L * p.r_L * slopes.d_xi / p.I_L;
            j[xi_dot(i)][xi_dot(i)] = -(p.r_L * p.r_L * slopes.d_xi_dot + p.C) / p.I_L;
        }
        j
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gearbox::{Drive, GearboxParams, PHI};
    use crate::integrator::System;
    use crate::physics::{Engine, EngineParams, Polynomial, Shaft};

    /// The analytic Jacobian matches central differences of the right-hand side on every
    /// dynamic row and column, with the gears in different regions, the damper in each
    /// stage, ρ ≠ 1, under an engine ramp (ω_F a state) and with the input side imposed.
    #[test]
    fn jacobian_matches_finite_differences() {
        let mut p = GearboxParams::default_box();
        p.gears[1].rho = 1.7;
        p.gears[2].pair.omega_S = 3.0;
        let engine = |rpm_rate| {
            Drive::Engine(Engine::new(&EngineParams {
                rpm_rate,
                ..p.engine
            }))
        };
        let imposed = Drive::InputSide(Polynomial {
            t0: 0.0,
            at_t0: Shaft {
                theta: 1.0,
                omega: 80.0,
                alpha: 500.0,
            },
        });
        for drive in [engine(0.0), engine(900.0), imposed] {
            for phi in [-0.08, 0.01, 0.07] {
                let mut y = [0.0; N];
                (y[PHI], y[PHI_DOT]) = (phi, 0.004);
                let xis = [-3e-6, -0.5e-6, 30e-6, 70e-6 + 0.4e-6, 60e-6 + 3e-6];
                for (i, &x) in xis.iter().enumerate() {
                    (y[xi(i)], y[xi_dot(i)]) = (x, 0.01 * (i as f64 - 2.0));
                }
                let sys = Gearbox::new(&p, drive, &y);
                let n = sys.n;
                let dynamic = xi(n) + usize::from(sys.integrates_flywheel());
                if sys.integrates_flywheel() {
                    y[omega_F(n)] = 85.0;
                }
                let t = 0.0123;
                let j = sys.jacobian(t, &y);
                for c in 0..dynamic {
                    let h = if c % 2 == 0 && c < xi(n) && c > PHI_DOT {
                        1e-12
                    } else {
                        1e-7
                    };
                    let (mut up, mut down) = (y, y);
                    up[c] += h;
                    down[c] -= h;
                    let (fu, fd) = (sys.rhs(t, &up), sys.rhs(t, &down));
                    for r in 0..dynamic {
                        let fd_slope = (fu[r] - fd[r]) / (2.0 * h);
                        let err = (j[r][c] - fd_slope).abs();
                        assert!(
                            err <= 1e-5 * fd_slope.abs().max(1.0),
                            "{drive:?}, φ {phi}: ∂f{r}/∂y{c} = {} vs {fd_slope}",
                            j[r][c]
                        );
                    }
                }
            }
        }
    }
}
