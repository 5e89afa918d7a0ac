//! The 3-stage Radau IIA method of order 5 (Hairer & Wanner, *Solving ODEs II*, IV.8, the
//! code RADAU5), one step at a time, for the stiff phases that DOPRI5 can only cross with
//! steps bounded by stability:
//!
//! - the collocation system is solved by a simplified Newton iteration in Hairer's
//!   transformed variables W = (T⁻¹ ⊗ I) Z, which split the 3N×3N linear system into one real
//!   N×N system with (γ/h) I − J and one complex N×N system with ((α + iβ)/h) I − J
//!   (cheaper than the full 3N×3N system, in the decompositions and in each iteration, for
//!   every N from 2 to 7: docs/DECISIONS.md, D17);
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
//! `solver` drives it (edges, the end time, the hand-over from and to DOPRI5).
// RADAU5's constants are kept with the 20 digits it publishes.
#![allow(clippy::excessive_precision)]

use nalgebra::{Complex, SMatrix};
use serde::{Deserialize, Serialize};

use super::control::{Tolerance, Verdict};
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
    #[serde(with = "super::serde_array::rows")]
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

    /// The increment ΔW of one simplified Newton iteration in the transformed variables
    /// W = T⁻¹ Z (Hairer & Wanner, IV.8), from the stages' values F_s = f(t + c_s h, y0 + Z_s):
    /// ((γ/h) I − J) ΔW₁ = (T⁻¹F)₁ − (γ/h) W₁ and, for ΔW₂ + iΔW₃, the complex system with
    /// (α + iβ)/h, given (γ/h, α/h, β/h) for this h.
    #[inline]
    fn newton_increment(
        &self,
        f: &[[f64; N]; 3],
        w: &[[f64; N]; 3],
        (fac1, alphn, betan): (f64, f64, f64),
    ) -> ([f64; N], [Complex<f64>; N]) {
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
        self.real.solve(&mut r1);
        self.complex.solve(&mut r23);
        (r1, r23)
    }
}

/// W += ΔW (the real system's part and the complex one's) and Z = T W, the stages'
/// increments Z_s = y_s − y0.
#[inline]
fn apply_increment<const N: usize>(
    w: &mut [[f64; N]; 3],
    z: &mut [[f64; N]; 3],
    r1: &[f64; N],
    r23: &[Complex<f64>; N],
) {
    for i in 0..N {
        w[0][i] += r1[i];
        w[1][i] += r23[i].re;
        w[2][i] += r23[i].im;
        let (w1, w2, w3) = (w[0][i], w[1][i], w[2][i]);
        z[0][i] = T11 * w1 + T12 * w2 + T13 * w3;
        z[1][i] = T21 * w1 + T22 * w2 + T23 * w3;
        z[2][i] = T31 * w1 + w2;
    }
}

/// The collocation polynomial's divided differences from the end of the step (RADAU5's
/// CONT), from the stages' increments z: the dense output of [`RadauTrial::dense`].
fn dense_output<const N: usize>(z: &[[f64; N]; 3]) -> [[f64; N]; 3] {
    let mut cont = [[0.0; N]; 3];
    for i in 0..N {
        let (z1, z2, z3) = (z[0][i], z[1][i], z[2][i]);
        cont[0][i] = (z2 - z3) / C2M1;
        let ak = (z1 - z2) / C1MC2;
        let acont3 = (ak - z1 / C1) / C2;
        cont[1][i] = (ak - cont[0][i]) / C1M1;
        cont[2][i] = cont[1][i] - acont3;
    }
    cont
}

/// The last accepted step: where it ended, its size and polynomial (starting values of the
/// next Newton iteration by extrapolation).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct Accepted<const N: usize> {
    t1: f64,
    #[serde(with = "super::serde_array")]
    y1: [f64; N],
    h: f64,
    #[serde(with = "super::serde_array::rows")]
    cont: [[f64; N]; 3],
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

    /// The Jacobian the Newton iteration uses now, if any.
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
    /// estimate only): the Newton iteration from the starting values, then the error
    /// estimate and the dense output.
    pub fn step<S: Jacobian<N>>(
        &mut self,
        sys: &S,
        t: f64,
        y0: &[f64; N],
        f0: &[f64; N],
        h: f64,
    ) -> RadauTrial<N> {
        self.stats.steps += 1;
        let Some(factors) = self.factors(sys, t, y0, h) else {
            return self.fail(t, y0, h, Divergence::Singular, 0.5 * h);
        };
        let (mut z, mut w) = self.starting_values(t, y0, h);
        let (iterations, theta) = match self.newton(sys, &factors, (t, y0, h), &mut z, &mut w) {
            Ok(converged) => converged,
            Err((cause, h_next)) => return self.fail(t, y0, h, cause, h_next),
        };
        let (y1, err, error) = self.error_estimate(sys, &factors, (t, y0, f0, h), &z);
        RadauTrial {
            t,
            h,
            y0: *y0,
            y1,
            err,
            error,
            newton: Newton::Converged { iterations },
            theta,
            cont: dense_output(&z),
        }
    }

    /// The LU factors for a step of size h from (t, y0): those in use if made for h, else
    /// made anew, from the Jacobian in use or, if none, one evaluated at (t, y0). None if a
    /// matrix is singular.
    fn factors<S: Jacobian<N>>(
        &mut self,
        sys: &S,
        t: f64,
        y0: &[f64; N],
        h: f64,
    ) -> Option<Factors<N>> {
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
        match self.factors {
            Some(f) if f.h == h => Some(f),
            _ => {
                self.stats.decompositions += 1;
                let f = Factors::new(&jac.m, h)?;
                self.factors = Some(f);
                Some(f)
            }
        }
    }

    /// The Newton iteration's starting values (Z, W = T⁻¹ Z): the last accepted collocation
    /// polynomial, extrapolated, when this step continues it; zero otherwise.
    fn starting_values(&self, t: f64, y0: &[f64; N], h: f64) -> ([[f64; N]; 3], [[f64; N]; 3]) {
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
        (z, w)
    }

    /// RADAU5's simplified Newton iteration on the stages' increments z (and w = T⁻¹ z) of a
    /// step of size h from (t, y0), from their starting values: its iterations and
    /// contraction factor θ when it converges, else why not and the size to retry with.
    fn newton<S: System<N>>(
        &mut self,
        sys: &S,
        factors: &Factors<N>,
        (t, y0, h): (f64, &[f64; N], f64),
        z: &mut [[f64; N]; 3],
        w: &mut [[f64; N]; 3],
    ) -> Result<(u32, f64), (Divergence, f64)> {
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
                return Err((Divergence::Limit, 0.5 * h));
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
            let (r1, r23) = factors.newton_increment(&f, w, (fac1, alphn, betan));
            newt += 1;
            self.stats.newton_iterations += 1;
            let mut sum = 0.0;
            for i in 0..m {
                let s = scal[i];
                sum += (r1[i] / s).powi(2) + (r23[i].re / s).powi(2) + (r23[i].im / s).powi(2);
            }
            let dyno = (sum / (3 * m) as f64).sqrt();
            if !dyno.is_finite() {
                return Err((Divergence::NonFinite, 0.5 * h));
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
                        return Err((Divergence::Slow, hhfac * h));
                    }
                } else {
                    return Err((Divergence::Contraction, 0.5 * h));
                }
            }
            dyno_old = dyno.max(UROUND);
            apply_increment(w, z, &r1, &r23);
            if self.faccon * dyno <= self.fnewt {
                return Ok((newt, theta));
            }
        }
    }

    /// The end of the step from the converged stages' increments z, with Hairer's error
    /// estimate (filtered by ((γ/h) I − J)⁻¹, once more through f on a fresh start or after a
    /// rejection when the first estimate fails): y1, the estimate and its norm.
    fn error_estimate<S: System<N>>(
        &mut self,
        sys: &S,
        factors: &Factors<N>,
        (t, y0, f0, h): (f64, &[f64; N], &[f64; N], f64),
        z: &[[f64; N]; 3],
    ) -> ([f64; N], [f64; N], f64) {
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
        (y1, err, error)
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

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::integrator::test_systems::{Nonlinear, Robertson, sci, tolerance};

    /// The Butcher matrix of the 3-stage Radau IIA method in closed form (Hairer & Wanner, IV.5).
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

    #[test]
    fn constants_diagonalise_the_butcher_matrix() {
        let s6 = 6f64.sqrt();
        assert!((C1 - (4.0 - s6) / 10.0).abs() < 1e-16 && (C2 - (4.0 + s6) / 10.0).abs() < 1e-16);
        assert!((DD1 + (13.0 + 7.0 * s6) / 3.0).abs() < 1e-14);
        assert!((DD2 - (-13.0 + 7.0 * s6) / 3.0).abs() < 1e-14);
        // Radau IIA, s = 3.
        let b = butcher();
        let a = nalgebra::Matrix3::from_fn(|r, c| b[r][c]);
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
}
