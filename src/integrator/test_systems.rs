//! Systems with known solutions for the integrator's unit tests: a smooth nonlinear one, a
//! stiff linear one, Robertson's kinetics, and a mass bouncing on a stiff contact.

use super::{Crossing, Jacobian, Piecewise, System, Tolerance};

/// Tolerance with all components controlled.
pub(crate) fn tolerance<const N: usize>(rtol: f64, atol: [f64; N]) -> Tolerance<N> {
    Tolerance {
        rtol,
        atol,
        controlled: N,
    }
}

/// Numbers for a printed line, 3 digits each.
pub(crate) fn sci(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:.2e}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A system with one piece: implements Piecewise with an unbounded piece.
macro_rules! smooth {
    ($t:ty, $n:literal) => {
        impl Piecewise<$n> for $t {
            fn guard(_: usize) -> (usize, usize) {
                (0, 0)
            }
            fn piece(&self, _: usize) -> (f64, f64) {
                (f64::NEG_INFINITY, f64::INFINITY)
            }
            fn cross(&mut self, _: Crossing, _: f64, _: &[f64; $n]) {}
        }
    };
}

/// y1' = −2t y1², y2' = y1: y1 = 1/(1 + t²), y2 = atan t.
pub(crate) struct Nonlinear;
impl System<2> for Nonlinear {
    fn rhs(&self, t: f64, y: &[f64; 2]) -> [f64; 2] {
        [-2.0 * t * y[0] * y[0], y[0]]
    }
}
impl Jacobian<2> for Nonlinear {
    fn jacobian(&self, t: f64, y: &[f64; 2]) -> [[f64; 2]; 2] {
        [[-4.0 * t * y[0], 0.0], [1.0, 0.0]]
    }
}

/// y' = A y, A = V diag(−1, −1e6) V⁻¹ with V = [[1, 1], [1, 2]].
pub(crate) struct Linear;
pub(crate) const LAMBDA: [f64; 2] = [-1.0, -1e6];
impl Linear {
    pub(crate) const A: [[f64; 2]; 2] = [
        [2.0 * LAMBDA[0] - LAMBDA[1], LAMBDA[1] - LAMBDA[0]],
        [
            2.0 * LAMBDA[0] - 2.0 * LAMBDA[1],
            2.0 * LAMBDA[1] - LAMBDA[0],
        ],
    ];
    pub(crate) fn exact(t: f64, y0: [f64; 2]) -> [f64; 2] {
        // V⁻¹ = [[2, −1], [−1, 1]]
        let w = [2.0 * y0[0] - y0[1], -y0[0] + y0[1]];
        let e = [w[0] * (LAMBDA[0] * t).exp(), w[1] * (LAMBDA[1] * t).exp()];
        [e[0] + e[1], e[0] + 2.0 * e[1]]
    }
}
impl System<2> for Linear {
    fn rhs(&self, _: f64, y: &[f64; 2]) -> [f64; 2] {
        let a = Self::A;
        [
            a[0][0] * y[0] + a[0][1] * y[1],
            a[1][0] * y[0] + a[1][1] * y[1],
        ]
    }
}
impl Jacobian<2> for Linear {
    fn jacobian(&self, _: f64, _: &[f64; 2]) -> [[f64; 2]; 2] {
        Self::A
    }
}
smooth!(Linear, 2);

/// Robertson's chemical kinetics (Hairer & Wanner II, IV.1).
pub(crate) struct Robertson;
impl System<3> for Robertson {
    fn rhs(&self, _: f64, y: &[f64; 3]) -> [f64; 3] {
        let a = 0.04 * y[0];
        let b = 1e4 * y[1] * y[2];
        let c = 3e7 * y[1] * y[1];
        [-a + b, a - b - c, c]
    }
}
impl Jacobian<3> for Robertson {
    fn jacobian(&self, _: f64, y: &[f64; 3]) -> [[f64; 3]; 3] {
        [
            [-0.04, 1e4 * y[2], 1e4 * y[1]],
            [0.04, -1e4 * y[2] - 6e7 * y[1], -1e4 * y[1]],
            [0.0, 6e7 * y[1], 0.0],
        ]
    }
}
smooth!(Robertson, 3);

/// A mass falling onto a stiff, damped contact, like a gear tooth on its flank:
/// x'' = −g in free flight (x > 0), x'' = −g − k x − c x' in contact (x < 0),
/// k = 1e10 s⁻², damping ratio ζ = c/(2√k); at rest x = −g/k.
/// `forced`: the load −g + 1.5 g sin(2πt) instead of −g, which lifts the mass off the
/// contact from t = 0.12 to 0.38 in each second.
#[derive(Clone, Copy)]
pub(crate) struct Bounce {
    pub(crate) contact: bool,
    pub(crate) k: f64,
    pub(crate) c: f64,
    pub(crate) forced: bool,
}
pub(crate) const G: f64 = 10.0;
impl Bounce {
    pub(crate) fn new(zeta: f64, x: f64) -> Self {
        let k = 1e10;
        Bounce {
            contact: x < 0.0,
            k,
            c: 2.0 * zeta * k.sqrt(),
            forced: false,
        }
    }
}
impl System<2> for Bounce {
    fn rhs(&self, t: f64, y: &[f64; 2]) -> [f64; 2] {
        let f = if self.contact {
            -self.k * y[0] - self.c * y[1]
        } else {
            0.0
        };
        let load = if self.forced {
            -G + 1.5 * G * (std::f64::consts::TAU * t).sin()
        } else {
            -G
        };
        [y[1], load + f]
    }
}
impl Jacobian<2> for Bounce {
    fn jacobian(&self, _: f64, _: &[f64; 2]) -> [[f64; 2]; 2] {
        if self.contact {
            [[0.0, 1.0], [-self.k, -self.c]]
        } else {
            [[0.0, 1.0], [0.0, 0.0]]
        }
    }
}
impl Piecewise<2> for Bounce {
    fn guard(_: usize) -> (usize, usize) {
        (0, 1)
    }
    fn piece(&self, _: usize) -> (f64, f64) {
        if self.contact {
            (f64::NEG_INFINITY, 0.0)
        } else {
            (0.0, f64::INFINITY)
        }
    }
    fn cross(&mut self, _: Crossing, _: f64, _: &[f64; 2]) {
        self.contact = !self.contact;
    }
}
