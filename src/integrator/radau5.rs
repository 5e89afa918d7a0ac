//! The 3-stage Radau IIA method of order 5 (Hairer & Wanner, *Solving ODEs II*, IV.8, the
//! code RADAU5), one step at a time, for the stiff phases that DOPRI5 can only cross with
//! steps bounded by stability:
//!
//! - the collocation system is solved by a simplified Newton iteration in Hairer's
//!   transformed variables W = (T⁻¹ ⊗ I) Z, which split the 3N×3N linear system into one real
//!   N×N system with (γ/h) I − J and one complex N×N system with ((α + iβ)/h) I − J
//!   (measured cheaper than the full 3N×3N system for every N from 2 to 7, see the test
//!   `measure_linear_algebra`);
//! - the Jacobian J = ∂f/∂y comes from the system ([`Jacobian`]); it is kept from step to step
//!   while the Newton iteration contracts fast (θ ≤ 0.001), and the two LU decompositions
//!   are kept while J and h stay (the controller keeps h when it would grow by less than 20 %);
//! - the error estimate is Hairer's, filtered by ((γ/h) I − J)⁻¹ so that it stays bounded
//!   for stiff components, with one more filtering through f on the first step and after a
//!   rejection when the first estimate fails;
//! - the step size follows RADAU5's controller with Gustafsson's predictive correction, on
//!   the tolerance RADAU5 derives from the user's (rtol' = 0.1 rtol^(2/3), atol scaled
//!   alike), because the embedded estimate is of order 3 while the solution is of order 5;
//! - the dense output is the collocation polynomial (of degree 3), in the shape of DOPRI5's,
//!   so that edges are located on it the same way.
//!
//! [`stiffness`] and [`StiffnessDetector`] give the explicit side its switching rule (Hairer's
//! DOPRI5: h·ρ estimated from the last two stages, stiff after 15 accepted steps above a
//! threshold; the estimate weighed by the tolerance scales and the threshold lowered from 3.25
//! to 2, see [`STIFF_H_RHO`]), and [`spectral_radius`] of the Jacobian gives the implicit side
//! the way back.
// RADAU5's constants are kept with the 20 digits it publishes.
#![allow(clippy::excessive_precision)]

use nalgebra::{Complex, DMatrix, SMatrix};
use serde::{Deserialize, Serialize};

use super::control::{Tolerance, Verdict};
use super::dopri5;
use super::linalg::Lu;
use super::{Dense, System};

/// A system that supplies its Jacobian: `jacobian(t, y)[i][j]` = ∂f_i/∂y_j at (t, y).
pub trait Jacobian<const N: usize>: System<N> {
    fn jacobian(&self, t: f64, y: &[f64; N]) -> [[f64; N]; N];
}

/// Nodes c1, c2 (c3 = 1) of Radau IIA: (4 ∓ √6)/10.
const C1: f64 = 0.155_051_025_721_682_19;
const C2: f64 = 0.644_948_974_278_317_8;
const C1M1: f64 = C1 - 1.0;
const C2M1: f64 = C2 - 1.0;
const C1MC2: f64 = C1 - C2;
/// Weights of the error estimate: −(13 + 7√6)/3, (−13 + 7√6)/3, −1/3.
const DD1: f64 = -10.048_809_399_827_416;
const DD2: f64 = 1.382_142_733_160_749;
const DD3: f64 = -1.0 / 3.0;
/// Eigenvalues of the inverse of the Butcher matrix A: γ and α ± iβ.
const GAMMA: f64 = 3.637_834_252_744_496;
const ALPHA: f64 = 2.681_082_873_627_752;
const BETA: f64 = 3.050_430_199_247_410_6;
/// T⁻¹ A⁻¹ T = [[γ, 0, 0], [0, α, −β], [0, β, α]] (RADAU5's T and T⁻¹; T32 = 1, T33 = 0).
const T11: f64 = 9.123_239_487_089_294_279e-2;
const T12: f64 = -0.141_255_295_020_954_208_43;
const T13: f64 = -3.002_919_410_514_742_449_2e-2;
const T21: f64 = 0.241_717_932_707_107_018_96;
const T22: f64 = 0.204_129_352_293_799_931_99;
const T23: f64 = 0.382_942_112_757_261_937_79;
const T31: f64 = 0.966_048_182_615_092_936_19;
const TI11: f64 = 4.325_579_890_063_155_351;
const TI12: f64 = 0.339_199_251_815_809_869_54;
const TI13: f64 = 0.541_770_539_935_874_871_19;
const TI21: f64 = -4.178_718_591_551_904_727_3;
const TI22: f64 = -0.327_682_820_761_062_387_08;
const TI23: f64 = 0.476_623_554_500_550_451_96;
const TI31: f64 = -0.502_872_634_945_786_875_95;
const TI32: f64 = 2.571_926_949_855_605_429_2;
const TI33: f64 = -0.596_039_204_828_224_924_97;

/// RADAU5's defaults: Newton iterations per step, safety factor, the contraction below
/// which J is kept, the bounds of h_next/h (1/8 ≤ quot ≤ 5), the band of h_next/h in which
/// h (and so the LU) is kept.
const NIT: u32 = 7;
const SAFE: f64 = 0.9;
const THET: f64 = 0.001;
const FACR: f64 = 1.0 / 8.0;
const FACL: f64 = 5.0;
const QUOT1: f64 = 1.0;
const QUOT2: f64 = 1.2;
const CFAC: f64 = SAFE * (1 + 2 * NIT) as f64;
const UROUND: f64 = f64::EPSILON;

/// Work counters of the implicit stepper.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RadauStats {
    /// Calls to [`Stepper::step`].
    pub steps: u64,
    /// Right-hand sides evaluated by the stepper (3 per Newton iteration, 1 per refined
    /// error estimate); f(t, y0), passed in, is the caller's.
    pub rhs_evals: u64,
    pub jacobians: u64,
    /// LU decompositions, each of the real and the complex N×N matrix together.
    pub decompositions: u64,
    pub newton_iterations: u64,
    /// Steps whose Newton iteration failed.
    pub diverged: u64,
}

/// Why a Newton iteration was abandoned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Divergence {
    /// The contraction factor θ reached 0.99.
    Contraction,
    /// Convergence within the iteration limit predicted impossible from θ.
    Slow,
    /// The iteration limit (7) reached.
    Limit,
    /// (γ/h) I − J or ((α + iβ)/h) I − J is singular.
    Singular,
    /// A right-hand side or an iterate is not finite.
    NonFinite,
}

/// Outcome of the Newton iteration of a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Newton {
    Converged {
        iterations: u32,
    },
    /// The step is void; retry from the same point with `h_next` (RADAU5's choice: 0.5 h,
    /// or less when the contraction predicts it).
    Diverged {
        cause: Divergence,
        h_next: f64,
    },
}

/// A Radau IIA step from (t, y0) with size h, not yet accepted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadauTrial<const N: usize> {
    pub t: f64,
    pub h: f64,
    pub y0: [f64; N],
    /// y(t + h); equal to y0 when the Newton iteration diverged.
    pub y1: [f64; N],
    /// Local error estimate per component (filtered, see the module's doc).
    pub err: [f64; N],
    /// Its weighted RMS norm against RADAU5's internal tolerance (≤ 1: accurate enough;
    /// at least 1e-10; infinite when the Newton iteration diverged).
    pub error: f64,
    pub newton: Newton,
    /// Contraction factor of the Newton iteration (0.001 when one iteration sufficed).
    pub theta: f64,
    /// Divided differences of the collocation polynomial, from the end of the step.
    cont: [[f64; N]; 3],
}

impl<const N: usize> RadauTrial<N> {
    pub fn converged(&self) -> bool {
        matches!(self.newton, Newton::Converged { .. })
    }

    /// Component i of the collocation polynomial at t + θh, θ ∈ [0, 1] (RADAU5's CONTR5):
    /// y0 at θ = 0, the stage values at θ = c1, c2, y1 at θ = 1.
    #[inline]
    pub fn dense(&self, i: usize, theta: f64) -> f64 {
        let s = theta - 1.0;
        let [c1, c2, c3] = &self.cont;
        self.y1[i] + s * (c1[i] + (s - C2M1) * (c2[i] + (s - C1M1) * c3[i]))
    }
}

impl<const N: usize> Dense<N> for RadauTrial<N> {
    fn ends(&self) -> (&[f64; N], &[f64; N]) {
        (&self.y0, &self.y1)
    }
    fn dense(&self, i: usize, theta: f64) -> f64 {
        RadauTrial::dense(self, i, theta)
    }
}

/// The Jacobian in use and the point where it was evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct Jac<const N: usize> {
    t: f64,
    #[serde(with = "super::serde_array")]
    y: [f64; N],
    #[serde(with = "rows")]
    m: [[f64; N]; N],
}

/// LU decompositions of (γ/h) I − J and ((α + iβ)/h) I − J; a pure function of (J, h).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Factors<const N: usize> {
    h: f64,
    real: Lu<f64, N>,
    complex: Lu<Complex<f64>, N>,
}

impl<const N: usize> Factors<N> {
    fn new(j: &[[f64; N]; N], h: f64) -> Option<Self> {
        let (fac1, alphn, betan) = (GAMMA / h, ALPHA / h, BETA / h);
        let e1 = SMatrix::<f64, N, N>::from_fn(|r, c| (if r == c { fac1 } else { 0.0 }) - j[r][c]);
        let e2 = SMatrix::<Complex<f64>, N, N>::from_fn(|r, c| {
            if r == c {
                Complex::new(alphn - j[r][c], betan)
            } else {
                Complex::new(-j[r][c], 0.0)
            }
        });
        Some(Factors {
            h,
            real: Lu::new(e1)?,
            complex: Lu::new(e2)?,
        })
    }
}

/// The last accepted step: where it ended, its size and polynomial (starting values of the
/// next Newton iteration by extrapolation).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct Accepted<const N: usize> {
    t1: f64,
    #[serde(with = "super::serde_array")]
    y1: [f64; N],
    h: f64,
    #[serde(with = "rows")]
    cont: [[f64; N]; 3],
}

/// serde for `[[f64; N]; M]` (rows of `serde_array`), as M·N numbers.
mod rows {
    use serde::de::Error;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer, const N: usize, const M: usize>(
        a: &[[f64; N]; M],
        s: S,
    ) -> Result<S::Ok, S::Error> {
        a.iter()
            .flatten()
            .copied()
            .collect::<Vec<f64>>()
            .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>, const N: usize, const M: usize>(
        d: D,
    ) -> Result<[[f64; N]; M], D::Error> {
        let v = Vec::<f64>::deserialize(d)?;
        if v.len() != N * M {
            return Err(D::Error::invalid_length(v.len(), &"M·N numbers"));
        }
        let mut a = [[0.0; N]; M];
        for (k, x) in v.into_iter().enumerate() {
            a[k / N][k % N] = x;
        }
        Ok(a)
    }
}

/// Radau IIA stepper: the Jacobian and LU caches, the Newton and step-size controllers'
/// memory, and the work counters. Plain data (copyable), serializable for the FMU state: the
/// LU factors are left out, being a function of the kept Jacobian and h, and a restored copy
/// recomputes the same ones (only `stats.decompositions` tells).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stepper<const N: usize> {
    tol: Tolerance<N>,
    /// RADAU5's internal tolerance, derived from `tol`.
    inner: Tolerance<N>,
    /// Stopping threshold of the Newton iteration (RADAU5's FNEWT).
    fnewt: f64,
    pub stats: RadauStats,
    jac: Option<Jac<N>>,
    #[serde(skip)]
    factors: Option<Factors<N>>,
    /// θ/(1 − θ) of the last Newton iteration: the first iteration of the next step may stop
    /// when faccon·‖ΔW‖ ≤ fnewt.
    faccon: f64,
    accepted: Option<Accepted<N>>,
    /// Gustafsson's memory: the last accepted step size and its error.
    gustafsson: Option<(f64, f64)>,
    rejected_last: bool,
    /// An accepted step since `new` (RADAU5's FIRST is its negation).
    started: bool,
    /// No accepted step since `new` or `invalidate`: the error estimate is refined when it fails.
    fresh: bool,
}

impl<const N: usize> Stepper<N> {
    pub fn new(tol: Tolerance<N>) -> Self {
        let mut stepper = Stepper {
            tol,
            inner: tol,
            fnewt: 0.0,
            stats: RadauStats::default(),
            jac: None,
            factors: None,
            faccon: 1.0,
            accepted: None,
            gustafsson: None,
            rejected_last: false,
            started: false,
            fresh: true,
        };
        stepper.set_tolerance(tol);
        stepper
    }

    pub fn tolerance(&self) -> &Tolerance<N> {
        &self.tol
    }

    /// RADAU5's transformation: rtol' = 0.1 rtol^(2/3), atol' = atol · rtol'/rtol; the Newton
    /// iteration stops at max(10 ε/rtol', min(0.03, √rtol')) in the weighted norm.
    pub fn set_tolerance(&mut self, tol: Tolerance<N>) {
        let rtol = 0.1 * tol.rtol.powf(2.0 / 3.0);
        let mut inner = tol;
        inner.rtol = rtol;
        for a in inner.atol.iter_mut() {
            *a *= rtol / tol.rtol;
        }
        self.tol = tol;
        self.inner = inner;
        self.fnewt = (10.0 * UROUND / rtol).max(0.03f64.min(rtol.sqrt()));
    }

    /// To be called when the system changed (an edge crossed, new inputs) or the state jumped:
    /// drops the Jacobian, the LU factors, the extrapolation and the controllers' memory.
    pub fn invalidate(&mut self) {
        self.jac = None;
        self.factors = None;
        self.accepted = None;
        self.gustafsson = None;
        self.faccon = 1.0;
        self.rejected_last = false;
        self.fresh = true;
    }

    /// The Jacobian the Newton iteration uses now, if any (see [`spectral_radius`]).
    pub fn jacobian(&self) -> Option<&[[f64; N]; N]> {
        self.jac.as_ref().map(|j| &j.m)
    }

    fn jacobian_is_from(&self, t: f64, y0: &[f64; N]) -> bool {
        matches!(&self.jac, Some(j) if j.t == t && j.y == *y0)
    }

    /// After a failed attempt from (t, y0): a Jacobian evaluated elsewhere is refreshed
    /// (RADAU5: "IF (CALJAC) GOTO 20; GOTO 10").
    fn distrust_jacobian(&mut self, t: f64, y0: &[f64; N]) {
        if !self.jacobian_is_from(t, y0) {
            self.jac = None;
            self.factors = None;
        }
    }

    /// Takes one step of size h from (t, y0), with f0 = f(t, y0) known (it enters the error
    /// estimate only).
    pub fn step<S: Jacobian<N>>(
        &mut self,
        sys: &S,
        t: f64,
        y0: &[f64; N],
        f0: &[f64; N],
        h: f64,
    ) -> RadauTrial<N> {
        self.stats.steps += 1;
        let jac = match self.jac {
            Some(j) => j,
            None => {
                self.stats.jacobians += 1;
                self.factors = None;
                let j = Jac {
                    t,
                    y: *y0,
                    m: sys.jacobian(t, y0),
                };
                self.jac = Some(j);
                j
            }
        };
        let factors = match self.factors {
            Some(f) if f.h == h => f,
            _ => {
                self.stats.decompositions += 1;
                match Factors::new(&jac.m, h) {
                    Some(f) => {
                        self.factors = Some(f);
                        f
                    }
                    None => return self.fail(t, y0, h, Divergence::Singular, 0.5 * h),
                }
            }
        };

        // Starting values: the last accepted collocation polynomial, extrapolated, when this
        // step continues it; zero otherwise.
        let mut z = [[0.0; N]; 3];
        let mut w = [[0.0; N]; 3];
        if let Some(a) = &self.accepted
            && a.y1 == *y0
            && (a.t1 - t).abs() <= 8.0 * f64::EPSILON * a.t1.abs().max(t.abs())
        {
            let c3q = h / a.h;
            let [c1q, c2q] = [C1 * c3q, C2 * c3q];
            let [k1, k2, k3] = &a.cont;
            for i in 0..N {
                let at = |q: f64| q * (k1[i] + (q - C2M1) * (k2[i] + (q - C1M1) * k3[i]));
                let (z1, z2, z3) = (at(c1q), at(c2q), at(c3q));
                z[0][i] = z1;
                z[1][i] = z2;
                z[2][i] = z3;
                w[0][i] = TI11 * z1 + TI12 * z2 + TI13 * z3;
                w[1][i] = TI21 * z1 + TI22 * z2 + TI23 * z3;
                w[2][i] = TI31 * z1 + TI32 * z2 + TI33 * z3;
            }
        }

        let m = self.inner.controlled;
        let mut scal = [1.0; N];
        for i in 0..m {
            scal[i] = self.inner.atol[i] + self.inner.rtol * y0[i].abs();
        }
        let (fac1, alphn, betan) = (GAMMA / h, ALPHA / h, BETA / h);
        self.faccon = self.faccon.max(UROUND).powf(0.8);
        let mut theta = THET;
        let (mut thq_old, mut dyno_old) = (0.0, 0.0);
        let mut newt = 0u32;
        loop {
            if newt >= NIT {
                return self.fail(t, y0, h, Divergence::Limit, 0.5 * h);
            }
            let stage = |c: f64, zi: &[f64; N]| {
                let mut y = *y0;
                for i in 0..N {
                    y[i] += zi[i];
                }
                sys.rhs(t + c * h, &y)
            };
            let f = [stage(C1, &z[0]), stage(C2, &z[1]), stage(1.0, &z[2])];
            self.stats.rhs_evals += 3;
            let mut r1 = [0.0; N];
            let mut r23 = [Complex::new(0.0, 0.0); N];
            for i in 0..N {
                let (a1, a2, a3) = (f[0][i], f[1][i], f[2][i]);
                r1[i] = TI11 * a1 + TI12 * a2 + TI13 * a3 - fac1 * w[0][i];
                r23[i] = Complex::new(
                    TI21 * a1 + TI22 * a2 + TI23 * a3 - alphn * w[1][i] + betan * w[2][i],
                    TI31 * a1 + TI32 * a2 + TI33 * a3 - alphn * w[2][i] - betan * w[1][i],
                );
            }
            factors.real.solve(&mut r1);
            factors.complex.solve(&mut r23);
            newt += 1;
            self.stats.newton_iterations += 1;
            let mut sum = 0.0;
            for i in 0..m {
                let s = scal[i];
                sum += (r1[i] / s).powi(2) + (r23[i].re / s).powi(2) + (r23[i].im / s).powi(2);
            }
            let dyno = (sum / (3 * m) as f64).sqrt();
            if !dyno.is_finite() {
                return self.fail(t, y0, h, Divergence::NonFinite, 0.5 * h);
            }
            if newt > 1 && newt < NIT {
                let thq = dyno / dyno_old;
                theta = if newt == 2 {
                    thq
                } else {
                    (thq * thq_old).sqrt()
                };
                thq_old = thq;
                if theta < 0.99 {
                    self.faccon = theta / (1.0 - theta);
                    let dyth =
                        self.faccon * dyno * theta.powi((NIT - 1 - newt) as i32) / self.fnewt;
                    if dyth >= 1.0 {
                        let qnewt = dyth.clamp(1e-4, 20.0);
                        let hhfac = 0.8 * qnewt.powf(-1.0 / (4.0 + (NIT - 1 - newt) as f64));
                        return self.fail(t, y0, h, Divergence::Slow, hhfac * h);
                    }
                } else {
                    return self.fail(t, y0, h, Divergence::Contraction, 0.5 * h);
                }
            }
            dyno_old = dyno.max(UROUND);
            for i in 0..N {
                w[0][i] += r1[i];
                w[1][i] += r23[i].re;
                w[2][i] += r23[i].im;
                let (w1, w2, w3) = (w[0][i], w[1][i], w[2][i]);
                z[0][i] = T11 * w1 + T12 * w2 + T13 * w3;
                z[1][i] = T21 * w1 + T22 * w2 + T23 * w3;
                z[2][i] = T31 * w1 + w2;
            }
            if self.faccon * dyno <= self.fnewt {
                break;
            }
        }

        let mut y1 = *y0;
        let mut e = [0.0; N];
        let mut err = [0.0; N];
        for i in 0..N {
            y1[i] += z[2][i];
            e[i] = (DD1 * z[0][i] + DD2 * z[1][i] + DD3 * z[2][i]) / h;
            err[i] = e[i] + f0[i];
        }
        factors.real.solve(&mut err);
        let mut error = self.inner.norm(y0, &y1, &err).max(1e-10);
        if error >= 1.0 && (self.fresh || self.rejected_last) {
            let mut y = *y0;
            for i in 0..N {
                y[i] += err[i];
            }
            let f = sys.rhs(t, &y);
            self.stats.rhs_evals += 1;
            for i in 0..N {
                err[i] = f[i] + e[i];
            }
            factors.real.solve(&mut err);
            error = self.inner.norm(y0, &y1, &err).max(1e-10);
        }

        let mut cont = [[0.0; N]; 3];
        for i in 0..N {
            let (z1, z2, z3) = (z[0][i], z[1][i], z[2][i]);
            cont[0][i] = (z2 - z3) / C2M1;
            let ak = (z1 - z2) / C1MC2;
            let acont3 = (ak - z1 / C1) / C2;
            cont[1][i] = (ak - cont[0][i]) / C1M1;
            cont[2][i] = cont[1][i] - acont3;
        }
        RadauTrial {
            t,
            h,
            y0: *y0,
            y1,
            err,
            error,
            newton: Newton::Converged { iterations: newt },
            theta,
            cont,
        }
    }

    fn fail(
        &mut self,
        t: f64,
        y0: &[f64; N],
        h: f64,
        cause: Divergence,
        h_next: f64,
    ) -> RadauTrial<N> {
        self.stats.diverged += 1;
        self.distrust_jacobian(t, y0);
        RadauTrial {
            t,
            h,
            y0: *y0,
            y1: *y0,
            err: [0.0; N],
            error: f64::INFINITY,
            newton: Newton::Diverged { cause, h_next },
            theta: 1.0,
            cont: [[0.0; N]; 3],
        }
    }

    /// Records a converged trial as accepted whatever its error (as `judge` does when the
    /// error is small enough; for a step taken on purpose, like fixed steps): its polynomial
    /// gives the next step's starting values, and its Jacobian is kept for the next step if
    /// the Newton iteration contracted fast (θ ≤ 0.001).
    pub fn accept(&mut self, trial: &RadauTrial<N>) {
        if !trial.converged() {
            return;
        }
        if trial.theta > THET {
            self.jac = None;
            self.factors = None;
        }
        self.accepted = Some(Accepted {
            t1: trial.t + trial.h,
            y1: trial.y1,
            h: trial.h,
            cont: trial.cont,
        });
        self.rejected_last = false;
        self.started = true;
        self.fresh = false;
    }

    /// RADAU5's step-size control on a trial (every trial should be judged, accepted or
    /// not: the verdict also sets the Jacobian and LU reuse and the extrapolation):
    /// h_next = h / quot, quot = err^¼ / fac within [1/8, 5], fac = min(0.9, 13.5/(newt + 14)),
    /// with Gustafsson's predictive quot ≥ (h_acc/h)·(err²/err_acc)^¼ / 0.9 after the first
    /// accepted step; no growth right after a rejection; h kept when it would grow by less than
    /// 20 % and J is kept, so that the LU is reused; the first step ever shrinks tenfold when
    /// rejected; a diverged Newton iteration gives its own h_next.
    pub fn judge(&mut self, trial: &RadauTrial<N>) -> Verdict {
        let h = trial.h;
        let iterations = match trial.newton {
            Newton::Converged { iterations } => iterations,
            Newton::Diverged { h_next, .. } => {
                self.rejected_last = true;
                return Verdict {
                    accept: false,
                    h_next,
                };
            }
        };
        let err = trial.error;
        if !err.is_finite() {
            self.rejected_last = true;
            self.distrust_jacobian(trial.t, &trial.y0);
            return Verdict {
                accept: false,
                h_next: 0.5 * h,
            };
        }
        let fac = SAFE.min(CFAC / (iterations + 2 * NIT) as f64);
        let mut quot = (err.powf(0.25) / fac).clamp(FACR, FACL);
        let mut h_next = h / quot;
        if err < 1.0 {
            if let Some((h_acc, err_acc)) = self.gustafsson {
                let facgus =
                    (h_acc / h * (err * err / err_acc).powf(0.25) / SAFE).clamp(FACR, FACL);
                quot = quot.max(facgus);
                h_next = h / quot;
            }
            self.gustafsson = Some((h, err.max(1e-2)));
            if self.rejected_last {
                h_next = h_next.min(h);
            }
            if trial.theta <= THET && (QUOT1..=QUOT2).contains(&(h_next / h)) {
                h_next = h;
            }
            self.accept(trial);
            Verdict {
                accept: true,
                h_next,
            }
        } else {
            if !self.started {
                h_next = 0.1 * h;
            }
            self.rejected_last = true;
            self.distrust_jacobian(trial.t, &trial.y0);
            Verdict {
                accept: false,
                h_next,
            }
        }
    }
}

/// Spectral radius max |λ| of a Jacobian (Schur decomposition; infinite if J is not finite).
/// With the step size h of the implicit method, h·ρ(J) tells whether DOPRI5 could take that
/// step stably (its stability interval on the negative real axis is about [−3.3, 0]).
pub fn spectral_radius<const N: usize>(j: &[[f64; N]; N]) -> f64 {
    if j.iter().flatten().any(|v| !v.is_finite()) {
        return f64::INFINITY;
    }
    DMatrix::from_fn(N, N, |r, c| j[r][c])
        .complex_eigenvalues()
        .iter()
        .map(|l| l.norm())
        .fold(0.0, f64::max)
}

/// Hairer's stiffness estimate from an explicit DOPRI5 step: h·ρ ≈ h·‖k7 − k6‖ / ‖y1 − y6‖
/// (both stages at t + h), in the tolerance's weighted norm over its controlled components.
/// Hairer's DOPRI5 takes the plain Euclidean norm; with components of unlike units (a
/// position and a velocity) that estimate sees the singular values of J rather than its
/// eigenvalues (from 1 to k for x'' = −k x) and missed a resting stiff contact entirely;
/// weighed by the tolerance scales (atol of a velocity = atol of the position × the contact
/// frequency, as `Rattle::tolerance` sets them) it sees |λ|. 0 when y1 = y6.
pub fn stiffness<const N: usize>(trial: &dopri5::Trial<N>, tol: &Tolerance<N>) -> f64 {
    let (y6, k6) = trial.stage6();
    let k7 = trial.k_end();
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..tol.controlled {
        let scale = tol.atol[i] + tol.rtol * trial.y0[i].abs().max(trial.y1[i].abs());
        num += ((k7[i] - k6[i]) / scale).powi(2);
        den += ((trial.y1[i] - y6[i]) / scale).powi(2);
    }
    if den > 0.0 {
        trial.h * (num / den).sqrt()
    } else {
        0.0
    }
}

/// Hairer's DOPRI5 threshold of h·ρ: the radius of DOPRI5's stability domain on the negative
/// real axis (3.3).
pub const HAIRER_H_RHO: f64 = 3.25;
/// The threshold [`StiffnessDetector`] uses by default. The radius of DOPRI5's stability
/// domain shrinks towards the imaginary axis: 3.3 for real eigenvalues, 3.0 for a contact
/// mode with damping ratio ζ = 0.2 (where DOPRI5's steps were measured to hover at
/// h·|λ| = 3.0 ± 0.6 on a resting contact, so that 3.25 never fired), 2.6 for ζ = 0.09,
/// 2.3 for ζ = 0.035. An accepted step with h·|λ| > 2 leaves that mode an error of about
/// (h·|λ|)⁶/720 ≈ 9 % of its amplitude per step: it is accepted only when the mode has died
/// out, which is what stiffness means.
pub const STIFF_H_RHO: f64 = 2.0;
/// Stiff verdicts (not interrupted by 6 non-stiff ones in a row) that make a problem stiff.
pub const STIFF_STEPS: u32 = 15;
const CALM_STEPS: u32 = 6;

/// Hairer's DOPRI5 switching rule, fed with [`stiffness`] of each accepted step: stiff after
/// 15 verdicts h·ρ > threshold, the count restarting after 6 non-stiff verdicts in a row.
/// The threshold is [`STIFF_H_RHO`] by default (Hairer's [`HAIRER_H_RHO`] misses lightly
/// damped oscillatory stiffness, see there).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StiffnessDetector {
    threshold: f64,
    stiff: u32,
    calm: u32,
}

impl Default for StiffnessDetector {
    fn default() -> Self {
        Self::with_threshold(STIFF_H_RHO)
    }
}

impl StiffnessDetector {
    pub fn with_threshold(threshold: f64) -> Self {
        StiffnessDetector {
            threshold,
            stiff: 0,
            calm: 0,
        }
    }

    /// Records one accepted step's h·ρ; true when the problem is now judged stiff.
    pub fn observe(&mut self, h_rho: f64) -> bool {
        if h_rho > self.threshold {
            self.calm = 0;
            self.stiff += 1;
            self.stiff >= STIFF_STEPS
        } else {
            self.calm += 1;
            if self.calm >= CALM_STEPS {
                self.stiff = 0;
            }
            false
        }
    }

    /// Forgets the verdicts so far (after a switch).
    pub fn reset(&mut self) {
        self.stiff = 0;
        self.calm = 0;
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::integrator::control::Controller;
    use crate::integrator::solver::locate_edge;
    use crate::integrator::{Edge, Piecewise, Solver};

    fn tolerance<const N: usize>(rtol: f64, atol: [f64; N]) -> Tolerance<N> {
        Tolerance {
            rtol,
            atol,
            controlled: N,
        }
    }

    /// What edge location needs of a trial: both ends and the dense output (DOPRI5's and
    /// Radau's have the same shape).
    #[derive(Debug)]
    struct Run<const N: usize> {
        y: [f64; N],
        accepted: u64,
        rejected: u64,
        edges: u64,
        /// All right-hand sides: the stepper's plus f(t, y0) at each new point.
        rhs: u64,
        stats: RadauStats,
    }

    impl<const N: usize> Default for Run<N> {
        fn default() -> Self {
            Run {
                y: [0.0; N],
                accepted: 0,
                rejected: 0,
                edges: 0,
                rhs: 0,
                stats: RadauStats::default(),
            }
        }
    }

    fn sci(v: &[f64]) -> String {
        v.iter()
            .map(|x| format!("{x:.2e}"))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The driver of solver.rs with Radau in place of DOPRI5: reaches t_end exactly, ends
    /// steps on the edges (redoing the step to the edge found on the dense output).
    fn radau_run<S: Jacobian<N> + Piecewise<N>, const N: usize>(
        sys: &mut S,
        tol: Tolerance<N>,
        (mut t, t_end): (f64, f64),
        mut y: [f64; N],
        mut h: f64,
    ) -> Run<N> {
        let mut st = Stepper::new(tol);
        let mut run = Run::<N>::default();
        let mut f0: Option<[f64; N]> = None;
        while t < t_end {
            if sys.settle(t, &y) > 0 {
                f0 = None;
                st.invalidate();
            }
            let f = *f0.get_or_insert_with(|| {
                run.rhs += 1;
                sys.rhs(t, &y)
            });
            let last = t + 1.01 * h >= t_end;
            let hs = if last { t_end - t } else { h };
            assert!(
                hs > 1e-15 * t.abs().max(1e-300),
                "step size {hs} at t = {t}"
            );
            assert!(run.accepted + run.rejected < 1_000_000, "too many steps");
            let trial = st.step(sys, t, &y, &f, hs);
            let verdict = st.judge(&trial);
            if !verdict.accept {
                run.rejected += 1;
                h = verdict.h_next;
                continue;
            }
            run.accepted += 1;
            let (lo, hi) = sys.piece();
            if let Some((edge, theta)) = locate_edge(&trial, (S::GUARD, S::RATE), lo, hi) {
                if theta > 0.0 {
                    let redo = st.step(sys, t, &y, &f, theta * hs);
                    if !redo.converged() {
                        h = 0.5 * theta * hs;
                        continue;
                    }
                    y = redo.y1;
                    t += theta * hs;
                }
                y[S::GUARD] = if edge == Edge::Lower { lo } else { hi };
                sys.cross(edge, t, &y);
                run.edges += 1;
                f0 = None;
                st.invalidate();
                h = verdict.h_next.max(theta * hs);
                continue;
            }
            t = if last { t_end } else { t + hs };
            y = trial.y1;
            f0 = None;
            h = if last {
                verdict.h_next.max(h)
            } else {
                verdict.h_next
            };
        }
        run.y = y;
        run.rhs += st.stats.rhs_evals;
        run.stats = st.stats;
        run
    }

    #[derive(Debug, Default)]
    struct AutoRun {
        explicit_steps: u64,
        implicit_steps: u64,
        rejected: u64,
        rhs: u64,
        jacobians: u64,
        decompositions: u64,
        to_implicit: u64,
        to_explicit: u64,
        edges: u64,
    }

    /// A prototype of automatic switching, to measure the rule: DOPRI5 until Hairer's detector
    /// judges the problem stiff (h·ρ > 3.25 on 15 accepted steps), then Radau with DOPRI5's
    /// step size; back to DOPRI5 (fresh controller) once Radau's next step h satisfies
    /// h·ρ(J) ≤ `back` on 15 accepted steps in a row. Edges are located on either dense output.
    fn auto_run<S: Jacobian<N> + Piecewise<N>, const N: usize>(
        sys: &mut S,
        tol: Tolerance<N>,
        (mut t, t_end): (f64, f64),
        y: &mut [f64; N],
        mut h: f64,
        back: f64,
    ) -> AutoRun {
        let mut run = AutoRun::default();
        let mut implicit = false;
        let mut st = Stepper::new(tol);
        let mut controller = Controller::default();
        let mut detector = StiffnessDetector::default();
        let mut calm = 0u32;
        let mut f0: Option<[f64; N]> = None;
        while t < t_end {
            if sys.settle(t, y) > 0 {
                f0 = None;
                st.invalidate();
            }
            let f = *f0.get_or_insert_with(|| {
                run.rhs += 1;
                sys.rhs(t, y)
            });
            let last = t + 1.01 * h >= t_end;
            let hs = if last { t_end - t } else { h };
            assert!(
                hs > 1e-15 * t.abs().max(1e-300),
                "step size {hs} at t = {t}"
            );
            let (lo, hi) = sys.piece();
            let gr = (S::GUARD, S::RATE);
            // One trial: (accepted, h_next, edge, y1, f(t + h, y1) if known, h·ρ if explicit).
            let (accept, h_next, edge, y1, k_end, h_rho) = if implicit {
                let tr = st.step(sys, t, y, &f, hs);
                let v = st.judge(&tr);
                let edge = if v.accept {
                    locate_edge(&tr, gr, lo, hi)
                } else {
                    None
                };
                (v.accept, v.h_next, edge, tr.y1, None, None)
            } else {
                let tr = dopri5::step(sys, t, y, &f, hs);
                run.rhs += dopri5::EVALS_PER_STEP;
                let v = controller.judge(tol.norm(&tr.y0, &tr.y1, &tr.err), hs);
                let edge = if v.accept {
                    locate_edge(&tr, gr, lo, hi)
                } else {
                    None
                };
                let h_rho = stiffness(&tr, &tol);
                (
                    v.accept,
                    v.h_next,
                    edge,
                    tr.y1,
                    Some(*tr.k_end()),
                    Some(h_rho),
                )
            };
            if !accept {
                run.rejected += 1;
                h = h_next;
                continue;
            }
            if let Some((edge, theta)) = edge {
                if theta > 0.0 {
                    let y_edge = if implicit {
                        let redo = st.step(sys, t, y, &f, theta * hs);
                        if !redo.converged() {
                            h = 0.5 * theta * hs;
                            continue;
                        }
                        redo.y1
                    } else {
                        run.rhs += dopri5::EVALS_PER_STEP;
                        dopri5::step(sys, t, y, &f, theta * hs).y1
                    };
                    *y = y_edge;
                    t += theta * hs;
                }
                y[S::GUARD] = if edge == Edge::Lower { lo } else { hi };
                sys.cross(edge, t, y);
                run.edges += 1;
                f0 = None;
                st.invalidate();
                h = h_next.max(theta * hs);
                continue;
            }
            t = if last { t_end } else { t + hs };
            *y = y1;
            f0 = k_end;
            h = if last { h_next.max(h) } else { h_next };
            if implicit {
                run.implicit_steps += 1;
                let rho = spectral_radius(st.jacobian().expect("a Jacobian after a step"));
                calm = if h * rho <= back { calm + 1 } else { 0 };
                if calm >= STIFF_STEPS {
                    implicit = false;
                    controller = Controller::default();
                    run.to_explicit += 1;
                }
            } else {
                run.explicit_steps += 1;
                if detector.observe(h_rho.unwrap()) {
                    implicit = true;
                    st.invalidate();
                    detector.reset();
                    calm = 0;
                    run.to_implicit += 1;
                }
            }
        }
        run.rhs += st.stats.rhs_evals;
        run.jacobians = st.stats.jacobians;
        run.decompositions = st.stats.decompositions;
        run
    }

    /// A system with one piece: implements Piecewise with an unbounded piece.
    macro_rules! smooth {
        ($t:ty, $n:literal) => {
            impl Piecewise<$n> for $t {
                const GUARD: usize = 0;
                const RATE: usize = 0;
                fn piece(&self) -> (f64, f64) {
                    (f64::NEG_INFINITY, f64::INFINITY)
                }
                fn cross(&mut self, _: Edge, _: f64, _: &[f64; $n]) {}
            }
        };
    }

    /// y1' = −2t y1², y2' = y1: y1 = 1/(1 + t²), y2 = atan t.
    struct Nonlinear;
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
    struct Linear;
    const LAMBDA: [f64; 2] = [-1.0, -1e6];
    impl Linear {
        const A: [[f64; 2]; 2] = [
            [2.0 * LAMBDA[0] - LAMBDA[1], LAMBDA[1] - LAMBDA[0]],
            [
                2.0 * LAMBDA[0] - 2.0 * LAMBDA[1],
                2.0 * LAMBDA[1] - LAMBDA[0],
            ],
        ];
        fn exact(t: f64, y0: [f64; 2]) -> [f64; 2] {
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
    struct Robertson;
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
    struct Bounce {
        contact: bool,
        k: f64,
        c: f64,
        forced: bool,
    }
    const G: f64 = 10.0;
    impl Bounce {
        fn new(zeta: f64, x: f64) -> Self {
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
        const GUARD: usize = 0;
        const RATE: usize = 1;
        fn piece(&self) -> (f64, f64) {
            if self.contact {
                (f64::NEG_INFINITY, 0.0)
            } else {
                (0.0, f64::INFINITY)
            }
        }
        fn cross(&mut self, _: Edge, _: f64, _: &[f64; 2]) {
            self.contact = !self.contact;
        }
    }

    #[test]
    fn constants_diagonalise_the_butcher_matrix() {
        let s6 = 6f64.sqrt();
        assert!((C1 - (4.0 - s6) / 10.0).abs() < 1e-16 && (C2 - (4.0 + s6) / 10.0).abs() < 1e-16);
        assert!((DD1 + (13.0 + 7.0 * s6) / 3.0).abs() < 1e-14);
        assert!((DD2 - (-13.0 + 7.0 * s6) / 3.0).abs() < 1e-14);
        // Radau IIA, s = 3.
        let a = nalgebra::Matrix3::new(
            (88.0 - 7.0 * s6) / 360.0,
            (296.0 - 169.0 * s6) / 1800.0,
            (-2.0 + 3.0 * s6) / 225.0,
            (296.0 + 169.0 * s6) / 1800.0,
            (88.0 + 7.0 * s6) / 360.0,
            (-2.0 - 3.0 * s6) / 225.0,
            (16.0 - s6) / 36.0,
            (16.0 + s6) / 36.0,
            1.0 / 9.0,
        );
        let t = nalgebra::Matrix3::new(T11, T12, T13, T21, T22, T23, T31, 1.0, 0.0);
        let ti = nalgebra::Matrix3::new(TI11, TI12, TI13, TI21, TI22, TI23, TI31, TI32, TI33);
        assert!((t * ti - nalgebra::Matrix3::identity()).abs().max() < 1e-14);
        let lambda = ti * a.try_inverse().unwrap() * t;
        let expect = nalgebra::Matrix3::new(GAMMA, 0.0, 0.0, 0.0, ALPHA, -BETA, 0.0, BETA, ALPHA);
        assert!((lambda - expect).abs().max() < 1e-12, "{lambda}");
    }

    #[test]
    fn order_five_with_fixed_steps() {
        let exact = |t: f64| [1.0 / (1.0 + t * t), t.atan()];
        let tol = tolerance(1e-13, [1e-13; 2]);
        let mut errors = vec![];
        // (Further halvings reach the floor of the Newton iteration's stopping rule, ~1e-12.)
        for n in [20, 40, 80] {
            let mut st = Stepper::new(tol);
            let h = 2.0 / n as f64;
            let mut y = exact(0.0);
            for k in 0..n {
                let t = k as f64 * h;
                let f0 = Nonlinear.rhs(t, &y);
                let trial = st.step(&Nonlinear, t, &y, &f0, h);
                assert!(trial.converged(), "{:?}", trial.newton);
                st.accept(&trial);
                // The collocation polynomial passes through both ends of the step.
                for i in 0..2 {
                    assert!((trial.dense(i, 0.0) - y[i]).abs() < 1e-15);
                    assert_eq!(trial.dense(i, 1.0), trial.y1[i]);
                }
                y = trial.y1;
            }
            let e = exact(2.0);
            errors.push((y[0] - e[0]).abs().max((y[1] - e[1]).abs()));
        }
        let orders: Vec<f64> = errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect();
        println!(
            "fixed steps 2/20, 2/40, 2/80: errors {}, observed orders {orders:.2?}",
            sci(&errors)
        );
        for p in orders {
            assert!((4.6..5.6).contains(&p), "observed order {p}");
        }
    }

    #[test]
    fn stiff_linear_system_against_its_eigendecomposition() {
        let y0 = [1.0, 0.0];
        for rtol in [1e-4, 1e-7, 1e-10] {
            let tol = tolerance(rtol, [rtol; 2]);
            let mut worst = 0.0f64;
            let mut t0 = 0.0;
            let mut y = y0;
            let mut total = Run::<2>::default();
            // Several calls, like communication steps: the error is checked at each end.
            for t1 in [1e-6, 1e-3, 0.1, 1.0, 5.0] {
                let run = radau_run(&mut Linear, tol, (t0, t1), y, 1e-6);
                let exact = Linear::exact(t1, y0);
                for i in 0..2 {
                    let e = (run.y[i] - exact[i]).abs() / (rtol + rtol * exact[i].abs());
                    worst = worst.max(e);
                }
                y = run.y;
                t0 = t1;
                total.accepted += run.accepted;
                total.rejected += run.rejected;
                total.rhs += run.rhs;
                total.stats.jacobians += run.stats.jacobians;
                total.stats.decompositions += run.stats.decompositions;
            }
            println!(
                "linear, λ = −1, −1e6, t = 5, rtol = {rtol:e}: error {worst:.2} × tol, {} steps \
                 ({} rejected), {} rhs, {} Jacobians, {} LU",
                total.accepted,
                total.rejected,
                total.rhs,
                total.stats.jacobians,
                total.stats.decompositions
            );
            assert!(worst < 10.0, "error {worst} × tol");
            assert!(total.accepted < 300, "{} steps", total.accepted);
        }
    }

    #[test]
    fn robertson_at_40_against_the_published_reference() {
        let reference = [0.715_827_068_7, 9.185_534_764e-6, 0.284_163_745_7];
        for rtol in [1e-6, 1e-9] {
            let tol = tolerance(rtol, [rtol * 1e-2, rtol * 1e-6, rtol * 1e-2]);
            let run = radau_run(&mut Robertson, tol, (0.0, 40.0), [1.0, 0.0, 0.0], 1e-6);
            let rel: Vec<f64> = (0..3)
                .map(|i| (run.y[i] - reference[i]).abs() / reference[i])
                .collect();
            println!(
                "Robertson t = 40, rtol = {rtol:e}: relative errors {}, {} steps ({} \
                 rejected), {} rhs, {} Jacobians, {} LU, {} Newton iterations",
                sci(&rel),
                run.accepted,
                run.rejected,
                run.rhs,
                run.stats.jacobians,
                run.stats.decompositions,
                run.stats.newton_iterations
            );
            for e in rel {
                // The reference has 10 digits.
                assert!(e < (10.0 * rtol).max(2e-9), "relative error {e}");
            }
        }
    }

    #[test]
    fn stiff_contact_costs_radau_far_fewer_right_hand_sides() {
        // Falls from 5 cm, bounces a dozen times (restitution 0.53), then rests on the contact.
        let zeta = 0.2;
        let y0 = [0.05, 0.0];
        let t_end = 1.0;
        let tol = Tolerance {
            rtol: 1e-8,
            atol: [1e-14, 1e-14 * 1e5],
            controlled: 2,
        };
        let rest = -G / 1e10;

        let mut sys = Bounce::new(zeta, y0[0]);
        let radau = radau_run(&mut sys, tol, (0.0, t_end), y0, 1e-4);

        let mut sys = Bounce::new(zeta, y0[0]);
        let mut solver = Solver::new(tol);
        let (mut t, mut y) = (0.0, y0);
        solver.advance(&mut sys, &mut t, &mut y, t_end).unwrap();
        let dopri = solver.stats;

        println!(
            "bounce ζ = {zeta}, k = 1e10, 1 s: Radau {} steps ({} rejected), {} edges, {} rhs, {} \
             Jacobians, {} LU, {} Newton it., x = {:e}; DOPRI5 {} steps ({} rejected), {} edges, \
             {} rhs, x = {:e}",
            radau.accepted,
            radau.rejected,
            radau.edges,
            radau.rhs,
            radau.stats.jacobians,
            radau.stats.decompositions,
            radau.stats.newton_iterations,
            radau.y[0],
            dopri.accepted,
            dopri.rejected,
            dopri.edges,
            dopri.rhs_evals,
            y[0]
        );
        for x in [radau.y, y] {
            assert!((x[0] - rest).abs() < 1e-13, "x = {:e}", x[0]);
            assert!(x[1].abs() < 1e-6, "x' = {:e}", x[1]);
        }
        assert!(dopri.rhs_evals > 20 * radau.rhs);
    }

    #[test]
    fn automatic_switching_on_the_contact() {
        let tol = Tolerance {
            rtol: 1e-8,
            atol: [1e-14, 1e-14 * 1e5],
            controlled: 2,
        };
        let rest = -G / 1e10;
        let y0 = [0.05, 0.0];
        // Settling on the contact: stiff once the bounces have died out.
        let mut sys = Bounce::new(0.2, y0[0]);
        let mut y = y0;
        let run = auto_run(&mut sys, tol, (0.0, 1.0), &mut y, 1e-4, 3.25);
        println!("auto, bounce ζ = 0.2, 1 s: {run:?}, x = {:e}", y[0]);
        assert!((y[0] - rest).abs() < 1e-13 && y[1].abs() < 1e-6, "{y:?}");
        assert!(run.to_implicit >= 1 && run.rhs < 10_000, "{run:?}");

        // Undamped bouncing: every contact is resolved, never stiff: DOPRI5 all along, at
        // DOPRI5's cost.
        let mut sys = Bounce::new(0.0, y0[0]);
        let mut y = y0;
        let run = auto_run(&mut sys, tol, (0.0, 0.5), &mut y, 1e-4, 3.25);
        let mut sys = Bounce::new(0.0, y0[0]);
        let mut solver = Solver::new(tol);
        let (mut t, mut y_ref) = (0.0, y0);
        solver.advance(&mut sys, &mut t, &mut y_ref, 0.5).unwrap();
        println!(
            "auto, bounce ζ = 0, 0.5 s: {run:?}; DOPRI5 alone {} rhs; x = {:e} vs {:e}",
            solver.stats.rhs_evals, y[0], y_ref[0]
        );
        assert_eq!(run.to_implicit, 0, "{run:?}");
        assert!((y[0] - y_ref[0]).abs() < 1e-9, "{y:?} {y_ref:?}");

        // Resting on the contact, lifted off by the load, landing and settling, each second:
        // stiff, not stiff, stiff again; against DOPRI5 alone.
        let y0 = [rest, 0.0];
        let forced = |x| Bounce {
            forced: true,
            ..Bounce::new(0.2, x)
        };
        let mut sys = forced(y0[0]);
        let mut y = y0;
        let run = auto_run(&mut sys, tol, (0.0, 2.0), &mut y, 1e-4, STIFF_H_RHO);
        let mut sys = forced(y0[0]);
        let mut solver = Solver::new(tol);
        let (mut t, mut y_ref) = (0.0, y0);
        solver.advance(&mut sys, &mut t, &mut y_ref, 2.0).unwrap();
        println!(
            "auto, bounce ζ = 0.2 lifted off each second, 2 s: {run:?}; DOPRI5 alone {} rhs; \
             x = {:e} vs {:e}",
            solver.stats.rhs_evals, y[0], y_ref[0]
        );
        assert!(run.to_implicit >= 2 && run.to_explicit >= 1, "{run:?}");
        assert!(run.rhs * 5 < solver.stats.rhs_evals, "{run:?}");
        assert!((y[0] - y_ref[0]).abs() < 1e-11, "{y:?} {y_ref:?}");
    }

    #[test]
    fn stiffness_estimate_of_dopri5() {
        // Scalar y' = λ y: k7 − k6 = λ (y1 − y6) exactly.
        struct Scalar(f64);
        impl System<1> for Scalar {
            fn rhs(&self, _: f64, y: &[f64; 1]) -> [f64; 1] {
                [self.0 * y[0]]
            }
        }
        let trial = dopri5::step(&Scalar(-300.0), 0.0, &[1.0], &[-300.0], 0.01);
        assert!((stiffness(&trial, &tolerance(1e-6, [1e-6])) - 3.0).abs() < 1e-12);

        // The stiff linear system under DOPRI5 with its own controller: once the fast mode has
        // died out the steps hover at the stability limit and the detector fires.
        let tol = tolerance(1e-6, [1e-6; 2]);
        let mut controller = Controller::default();
        let mut detector = StiffnessDetector::default();
        let (mut t, mut y, mut h) = (0.0, [1.0, 0.0], 1e-7);
        let mut k1 = Linear.rhs(t, &y);
        let mut accepted = 0;
        let mut fired_at = None;
        while t < 1e-3 && fired_at.is_none() {
            let trial = dopri5::step(&Linear, t, &y, &k1, h);
            let verdict = controller.judge(tol.norm(&trial.y0, &trial.y1, &trial.err), h);
            if verdict.accept {
                accepted += 1;
                t += h;
                y = trial.y1;
                k1 = *trial.k_end();
                if detector.observe(stiffness(&trial, &tol)) {
                    fired_at = Some((t, accepted, stiffness(&trial, &tol)));
                }
            }
            h = verdict.h_next;
        }
        println!("DOPRI5 on λ = −1, −1e6: judged stiff at (t, steps, h·ρ) = {fired_at:?}");
        let (t, steps, h_rho) = fired_at.expect("stiffness not detected");
        assert!(t < 1e-4 && steps < 100, "{t} {steps}");
        assert!((2.0..4.0).contains(&h_rho));
    }

    #[test]
    fn a_restored_stepper_continues_bit_for_bit() {
        let tol = tolerance(1e-7, [1e-10, 1e-14, 1e-10]);
        let mut st = Stepper::new(tol);
        let (mut t, mut y, mut h) = (0.0, [1.0, 0.0, 0.0], 1e-6);
        let go = |st: &mut Stepper<3>, t: &mut f64, y: &mut [f64; 3], h: &mut f64, n: usize| {
            let mut trace = vec![];
            for _ in 0..n {
                let f0 = Robertson.rhs(*t, y);
                let trial = st.step(&Robertson, *t, y, &f0, *h);
                let verdict = st.judge(&trial);
                if verdict.accept {
                    *t += *h;
                    *y = trial.y1;
                }
                *h = verdict.h_next;
                trace.push((*t, *y));
            }
            trace
        };
        go(&mut st, &mut t, &mut y, &mut h, 30);
        // Saved with a Jacobian and LU factors in use, which the copy must recompute alike.
        assert!(st.jac.is_some() && st.factors.is_some());
        let bytes = postcard::to_allocvec(&st).unwrap();
        let mut restored: Stepper<3> = postcard::from_bytes(&bytes).unwrap();
        let (t2, y2, h2) = (t, y, h);
        let a = go(&mut st, &mut t, &mut y, &mut h, 30);
        let (mut t, mut y, mut h) = (t2, y2, h2);
        let b = go(&mut restored, &mut t, &mut y, &mut h, 30);
        assert_eq!(a, b);
        assert_eq!(st.stats.jacobians, restored.stats.jacobians);
        println!(
            "restored after 30 steps: {} bytes; LU decompositions {} vs {}",
            bytes.len(),
            st.stats.decompositions,
            restored.stats.decompositions
        );
    }

    #[test]
    fn spectral_radius_of_a_contact_jacobian() {
        let k: f64 = 1e10;
        let c = 0.4 * k.sqrt();
        let rho = spectral_radius(&[[0.0, 1.0], [-k, -c]]);
        assert!((rho / k.sqrt() - 1.0).abs() < 1e-12, "{rho}");
        let rho = spectral_radius(&Linear::A);
        assert!((rho / 1e6 - 1.0).abs() < 1e-9, "{rho}");
        assert_eq!(spectral_radius(&[[f64::NAN]]), f64::INFINITY);
    }
}

/// Cost of the linear algebra of one Newton iteration and of one decomposition: Hairer's
/// transformed system (real N×N + complex N×N) against the full 3N×3N real system
/// (I − h A⊗J) ΔZ = −Z + h (A⊗I) F, which also needs (γ/h) I − J for the error estimate.
/// `cargo test --release --lib measure_linear_algebra -- --ignored --nocapture`
#[cfg(test)]
mod measure {
    use super::*;
    use nalgebra::{LU, SVector};
    use std::hint::black_box;
    use std::time::Instant;

    fn butcher() -> [[f64; 3]; 3] {
        let s6 = 6f64.sqrt();
        [
            [
                (88.0 - 7.0 * s6) / 360.0,
                (296.0 - 169.0 * s6) / 1800.0,
                (-2.0 + 3.0 * s6) / 225.0,
            ],
            [
                (296.0 + 169.0 * s6) / 1800.0,
                (88.0 + 7.0 * s6) / 360.0,
                (-2.0 - 3.0 * s6) / 225.0,
            ],
            [(16.0 - s6) / 36.0, (16.0 + s6) / 36.0, 1.0 / 9.0],
        ]
    }

    fn random<const N: usize>(seed: &mut u64) -> [[f64; N]; N] {
        let mut j = [[0.0; N]; N];
        for row in j.iter_mut() {
            for v in row.iter_mut() {
                *seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                *v = ((*seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2e3;
            }
        }
        j
    }

    /// Nanoseconds per call of f, best of 40 rounds (short rounds: a shared machine).
    fn time(reps: u32, mut f: impl FnMut()) -> f64 {
        (0..40)
            .map(|_| {
                let start = Instant::now();
                for _ in 0..reps {
                    f();
                }
                start.elapsed().as_nanos() as f64 / reps as f64
            })
            .fold(f64::INFINITY, f64::min)
    }

    macro_rules! measure {
        ($n:literal, $n3:literal) => {{
            const N: usize = $n;
            let mut seed = 42u64;
            let j: [[f64; N]; N] = random(&mut seed);
            let h = 1e-2;
            let a = butcher();
            let reps = 10_000;
            let f: [[f64; N]; 3] = [random::<N>(&mut seed)[0], random::<N>(&mut seed)[0], random::<N>(&mut seed)[0]];

            // Transformed: decompositions.
            let dec_t = time(reps, || {
                black_box(Factors::new(black_box(&j), black_box(h)));
            });
            let e1 = SMatrix::<f64, N, N>::from_fn(|r, c| (if r == c { GAMMA / h } else { 0.0 }) - j[r][c]);
            let dec_nalgebra = time(reps, || {
                black_box(LU::new(black_box(e1)));
            });
            let dec_ours = time(reps, || {
                black_box(Lu::new(black_box(e1)));
            });
            // Transformed: one Newton iteration's algebra (T⁻¹ F, two solves, W += ΔW, Z = T W).
            let fac = Factors::new(&j, h).unwrap();
            let mut w = [[0.0; N]; 3];
            let mut z = [[0.0; N]; 3];
            let (fac1, alphn, betan) = (GAMMA / h, ALPHA / h, BETA / h);
            let it_t = time(reps, || {
                let f = black_box(&f);
                let mut r1 = [0.0; N];
                let mut r23 = [Complex::new(0.0, 0.0); N];
                for i in 0..N {
                    let (a1, a2, a3) = (f[0][i], f[1][i], f[2][i]);
                    r1[i] = TI11 * a1 + TI12 * a2 + TI13 * a3 - fac1 * w[0][i];
                    r23[i] = Complex::new(
                        TI21 * a1 + TI22 * a2 + TI23 * a3 - alphn * w[1][i] + betan * w[2][i],
                        TI31 * a1 + TI32 * a2 + TI33 * a3 - alphn * w[2][i] - betan * w[1][i],
                    );
                }
                fac.real.solve(&mut r1);
                fac.complex.solve(&mut r23);
                for i in 0..N {
                    w[0][i] = 1e-3 * (w[0][i] + r1[i]);
                    w[1][i] = 1e-3 * (w[1][i] + r23[i].re);
                    w[2][i] = 1e-3 * (w[2][i] + r23[i].im);
                    let (w1, w2, w3) = (w[0][i], w[1][i], w[2][i]);
                    z[0][i] = T11 * w1 + T12 * w2 + T13 * w3;
                    z[1][i] = T21 * w1 + T22 * w2 + T23 * w3;
                    z[2][i] = T31 * w1 + w2;
                }
                black_box(&z);
            });

            // Full 3N×3N: decomposition (nalgebra's LU on the stack, concrete size) plus the
            // real N×N one the error estimate needs.
            let full = SMatrix::<f64, $n3, $n3>::from_fn(|r, c| {
                let (si, i, sj, jj) = (r / N, r % N, c / N, c % N);
                (if r == c { 1.0 } else { 0.0 }) - h * a[si][sj] * j[i][jj]
            });
            let dec_f = time(reps, || {
                black_box(LU::new(black_box(full)));
                black_box(Lu::new(black_box(e1)));
            });
            let dec_f_ours = time(reps, || {
                black_box(Lu::<f64, $n3>::new(black_box(full)));
                black_box(Lu::new(black_box(e1)));
            });
            // Full: one Newton iteration (residual −Z + h (A⊗I) F, one 3N solve, Z += ΔZ).
            let lu = Lu::<f64, $n3>::new(full).unwrap();
            let mut zf = [0.0; $n3];
            let it_f = time(reps, || {
                let f = black_box(&f);
                let mut g = [0.0; $n3];
                for s in 0..3 {
                    for i in 0..N {
                        g[s * N + i] = -zf[s * N + i]
                            + h * (a[s][0] * f[0][i] + a[s][1] * f[1][i] + a[s][2] * f[2][i]);
                    }
                }
                lu.solve(&mut g);
                for k in 0..$n3 {
                    zf[k] = 1e-3 * (zf[k] + g[k]);
                }
                black_box(&zf);
            });
            let lu_n = LU::new(full);
            let it_f_nalgebra = time(reps, || {
                let f = black_box(&f);
                let mut g = SVector::<f64, $n3>::zeros();
                for s in 0..3 {
                    for i in 0..N {
                        g[s * N + i] = -zf[s * N + i]
                            + h * (a[s][0] * f[0][i] + a[s][1] * f[1][i] + a[s][2] * f[2][i]);
                    }
                }
                lu_n.solve_mut(&mut g);
                for k in 0..$n3 {
                    zf[k] = 1e-3 * (zf[k] + g[k]);
                }
                black_box(&zf);
            });
            println!(
                "| {N} | {dec_t:.0} | {it_t:.0} | {dec_f:.0} ({dec_f_ours:.0}) | {it_f_nalgebra:.0} ({it_f:.0}) | {dec_nalgebra:.0} / {dec_ours:.0} |"
            );
        }};
    }

    #[test]
    #[ignore]
    fn measure_linear_algebra() {
        println!(
            "| N | transformed: LU pair [ns] | transformed: Newton iteration [ns] | full 3N: LU + error LU [ns] nalgebra (ours) | full 3N: Newton iteration [ns] nalgebra (ours) | N×N real LU: nalgebra / ours [ns] |"
        );
        println!("|---|---|---|---|---|---|");
        measure!(2, 6);
        measure!(3, 9);
        measure!(4, 12);
        measure!(5, 15);
        measure!(6, 18);
        measure!(7, 21);
    }
}
