//! docs/MODEL.md's contact law written out again, term by term as printed there (the sine form
//! of the smoothing factor), independently of the crate's implementation, for the tests to
//! compare against.
#![allow(non_snake_case, dead_code)]

use std::f64::consts::PI;

pub struct Paper {
    pub K_star: f64,
    pub alpha: f64,
    pub epsilon: f64,
    pub G: f64,
    pub C_LM: f64,
}

pub const PAPER: Paper = Paper {
    K_star: 3e6,
    alpha: 4.0 / 3.0,
    epsilon: 1e-6,
    G: 25e-6,
    C_LM: 67.0,
};

/// s(ξ) of docs/MODEL.md §2.
pub fn s(p: &Paper, xi: f64) -> f64 {
    let (e, g) = (p.epsilon, p.G);
    if xi <= -e {
        1.0
    } else if xi <= 0.0 {
        0.5 * (1.0 - (PI / e * (e / 2.0 + xi)).sin())
    } else if xi <= g {
        0.0
    } else if xi <= g + e {
        0.5 * (1.0 - (PI / e * (e / 2.0 - (xi - g))).sin())
    } else {
        1.0
    }
}

/// Penetration δ: ξ on the F+ side, ξ − G on the F− side.
pub fn delta(p: &Paper, xi: f64) -> f64 {
    if xi <= 0.0 { xi } else { xi - p.G }
}

/// F_k = s K* δ |δ/G|^(α−1).
pub fn F_k(p: &Paper, xi: f64) -> f64 {
    let d = delta(p, xi);
    s(p, xi) * p.K_star * d * (d / p.G).abs().powf(p.alpha - 1.0)
}

/// F = F_k + s C_LM ξ'.
pub fn F(p: &Paper, xi: f64, xi_dot: f64) -> f64 {
    F_k(p, xi) + s(p, xi) * p.C_LM * xi_dot
}

/// ∫ f over [a, b] by composite 16-point Gauss-Legendre on `pieces` sub-intervals.
pub fn integrate(f: impl Fn(f64) -> f64, a: f64, b: f64, pieces: usize) -> f64 {
    // Nodes and weights on [-1, 1] (positive half; symmetric).
    const X: [f64; 8] = [
        0.0950125098376374,
        0.2816035507792589,
        0.4580167776572274,
        0.6178762444026438,
        0.755404408355003,
        0.8656312023878318,
        0.9445750230732326,
        0.9894009349916499,
    ];
    const W: [f64; 8] = [
        0.1894506104550685,
        0.1826034150449236,
        0.1691565193950025,
        0.1495959888165767,
        0.1246289712555339,
        0.0951585116824928,
        0.0622535239386479,
        0.0271524594117541,
    ];
    let h = (b - a) / pieces as f64;
    (0..pieces)
        .map(|k| {
            let mid = a + (k as f64 + 0.5) * h;
            let half = 0.5 * h;
            X.iter()
                .zip(W)
                .map(|(x, w)| w * (f(mid - half * x) + f(mid + half * x)))
                .sum::<f64>()
                * half
        })
        .sum()
}

/// Potential V(ξ) = ∫ F_k dξ from the nearest gap edge (zero in the gap), split at the band
/// edges so that each piece is smooth.
pub fn V(p: &Paper, xi: f64) -> f64 {
    let fk = |x| F_k(p, x);
    let (e, g) = (p.epsilon, p.G);
    if xi < 0.0 {
        let band = integrate(fk, xi.max(-e), 0.0, 64);
        let contact = if xi < -e {
            integrate(fk, xi, -e, 64)
        } else {
            0.0
        };
        -(band + contact)
    } else if xi > g {
        let band = integrate(fk, g, xi.min(g + e), 64);
        let contact = if xi > g + e {
            integrate(fk, g + e, xi, 64)
        } else {
            0.0
        };
        band + contact
    } else {
        0.0
    }
}
