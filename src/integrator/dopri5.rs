//! One step of the Dormand-Prince 5(4) pair (FSAL) with its dense output, after Hairer's
//! DOPRI5: the 5th-order solution is propagated, the embedded 4th-order one gives the error
//! estimate, and a continuous extension of order 4 interpolates inside the step.

use serde::{Deserialize, Serialize};

use super::{Dense, System};

const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
/// Difference between the 5th- and 4th-order weights.
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
/// Dense output coefficients.
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// Number of right-hand-side evaluations per step (the 7th is reused as the next k1).
pub const EVALS_PER_STEP: u64 = 6;

/// A step taken from (t, y0) with size h, not yet accepted. Plain data: a step taken past a
/// communication point is kept in the solver's state (and the FMU state) for its dense output.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Trial<const N: usize> {
    pub h: f64,
    #[serde(with = "super::serde_array")]
    pub y0: [f64; N],
    #[serde(with = "super::serde_array")]
    pub y1: [f64; N],
    /// Local error estimate per component (0 for the quadratures, which no norm weighs).
    #[serde(with = "super::serde_array")]
    pub err: [f64; N],
    /// f(t, y0) and the stages needed by the dense output; k7 = f(t + h, y1).
    #[serde(with = "super::serde_array::rows")]
    k: [[f64; N]; 6],
    /// The argument of the 6th stage (at t + h, like k7): Hairer's stiffness estimate
    /// compares k7 − k6 with y1 − y6.
    #[serde(with = "super::serde_array")]
    y6: [f64; N],
}

/// y + h Σ a_j k_j over components 0..m; the others are y's.
#[inline(always)]
fn combine<const N: usize>(y: &[f64; N], h: f64, terms: &[(f64, &[f64; N])], m: usize) -> [f64; N] {
    let mut out = *y;
    for i in 0..m {
        let mut acc = 0.0;
        for (a, k) in terms {
            acc += a * k[i];
        }
        out[i] += h * acc;
    }
    out
}

/// Takes one step of size h from (t, y0), with k1 = f(t, y0) already known, into `out`
/// (written in place: a step is about 50 numbers, and returning it by value puts a copy on
/// the stepping path; docs/DECISIONS.md, D9).
///
/// Components `dynamic..N` are quadratures (∫ of a rate, like a dissipated energy) that
/// the right-hand side does not read: the stages' arguments and the error estimate form only
/// components `0..dynamic`; the quadratures advance with the 5th-order weights (three of the
/// gear's five components).
pub fn step<S: System<N>, const N: usize>(
    sys: &S,
    t: f64,
    y0: &[f64; N],
    k1: &[f64; N],
    h: f64,
    dynamic: usize,
    out: &mut Trial<N>,
) {
    let m = dynamic;
    let k2 = sys.rhs(t + C2 * h, &combine(y0, h, &[(A21, k1)], m));
    let k3 = sys.rhs(t + C3 * h, &combine(y0, h, &[(A31, k1), (A32, &k2)], m));
    let k4 = sys.rhs(
        t + C4 * h,
        &combine(y0, h, &[(A41, k1), (A42, &k2), (A43, &k3)], m),
    );
    let k5 = sys.rhs(
        t + C5 * h,
        &combine(y0, h, &[(A51, k1), (A52, &k2), (A53, &k3), (A54, &k4)], m),
    );
    out.y6 = combine(
        y0,
        h,
        &[(A61, k1), (A62, &k2), (A63, &k3), (A64, &k4), (A65, &k5)],
        m,
    );
    let k6 = sys.rhs(t + h, &out.y6);
    out.y1 = combine(
        y0,
        h,
        &[(A71, k1), (A73, &k3), (A74, &k4), (A75, &k5), (A76, &k6)],
        N,
    );
    let k7 = sys.rhs(t + h, &out.y1);
    out.err = combine(
        &[0.0; N],
        h,
        &[
            (E1, k1),
            (E3, &k3),
            (E4, &k4),
            (E5, &k5),
            (E6, &k6),
            (E7, &k7),
        ],
        m,
    );
    out.h = h;
    out.y0 = *y0;
    out.k = [*k1, k3, k4, k5, k6, k7];
}

impl<const N: usize> Trial<N> {
    /// A step of size 0 from the origin: the buffer `step` writes into.
    pub fn empty() -> Self {
        Trial {
            h: 0.0,
            y0: [0.0; N],
            y1: [0.0; N],
            err: [0.0; N],
            k: [[0.0; N]; 6],
            y6: [0.0; N],
        }
    }

    /// f(t + h, y1): the first stage of the next step (FSAL).
    pub fn k_end(&self) -> &[f64; N] {
        &self.k[5]
    }

    /// The 6th stage's argument and value (y6, k6 = f(t + h, y6)), for the stiffness estimate
    /// h·‖k7 − k6‖ / ‖y1 − y6‖ of Hairer's DOPRI5 (see `radau5::stiffness`).
    pub fn stage6(&self) -> (&[f64; N], &[f64; N]) {
        (&self.y6, &self.k[4])
    }

    /// Hairer's coefficients of component i's dense output (see [`Continuous`]).
    fn coefficients(&self, i: usize) -> [f64; 5] {
        let [k1, k3, k4, k5, k6, k7] = &self.k;
        let h = self.h;
        let ydiff = self.y1[i] - self.y0[i];
        let bspl = h * k1[i] - ydiff;
        let r4 = ydiff - h * k7[i] - bspl;
        let r5 = h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]);
        [self.y0[i], ydiff, bspl, r4, r5]
    }

    /// Component i of the dense output at t + θh, θ ∈ [0, 1].
    pub fn dense(&self, i: usize, theta: f64) -> f64 {
        hairer(&self.coefficients(i), theta)
    }

    /// The dense output of every component, its coefficients computed once (for a step that
    /// serves many points).
    pub fn continuous(&self) -> Continuous<N> {
        Continuous {
            rows: std::array::from_fn(|i| self.coefficients(i)),
        }
    }
}

/// y0 + θ(Δ + (1−θ)(b + θ(r4 + (1−θ) r5))): Hairer's form of DOPRI5's continuous extension.
#[inline]
fn hairer(c: &[f64; 5], theta: f64) -> f64 {
    let theta1 = 1.0 - theta;
    c[0] + theta * (c[1] + theta1 * (c[2] + theta * (c[3] + theta1 * c[4])))
}

/// The dense output of one step with its coefficients precomputed: a point inside the step
/// costs four multiply-adds per component.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Continuous<const N: usize> {
    #[serde(with = "super::serde_array::rows")]
    rows: [[f64; 5]; N],
}

impl<const N: usize> Continuous<N> {
    /// The state at t + θh, θ ∈ [0, 1].
    #[inline]
    pub fn at(&self, theta: f64) -> [f64; N] {
        std::array::from_fn(|i| hairer(&self.rows[i], theta))
    }

    /// Component i of [`at`](Self::at), to the bit.
    #[inline]
    pub fn component(&self, i: usize, theta: f64) -> f64 {
        hairer(&self.rows[i], theta)
    }

    /// Whether every component stays below `bound` in magnitude for θ ∈ [0, 1], each of
    /// Hairer's partial sums too: the sum of its coefficients' magnitudes does (θ and 1 − θ
    /// are at most 1).
    pub fn bounded(&self, bound: f64) -> bool {
        self.rows
            .iter()
            .all(|c| c.iter().map(|c| c.abs()).sum::<f64>() < bound)
    }
}

impl<const N: usize> Dense<N> for Trial<N> {
    fn ends(&self) -> (&[f64; N], &[f64; N]) {
        (&self.y0, &self.y1)
    }
    fn dense(&self, i: usize, theta: f64) -> f64 {
        Trial::dense(self, i, theta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An oscillator with the quadrature ∫ x² dt, which its right-hand side does not read.
    struct WithQuadrature;
    impl System<3> for WithQuadrature {
        fn rhs(&self, t: f64, y: &[f64; 3]) -> [f64; 3] {
            [y[1], -y[0] + t.sin(), y[0] * y[0]]
        }
    }

    /// Stages formed on the dynamic components only give the same step, to the bit, as
    /// stages on all of them: the quadrature at the end, ξ and ξ' everywhere.
    #[test]
    fn quadratures_outside_the_stages_change_no_bit() {
        let (t, y0, h) = (0.3, [0.7, -0.2, 0.05], 0.1);
        let k1 = WithQuadrature.rhs(t, &y0);
        let (mut all, mut dynamic) = (Trial::empty(), Trial::empty());
        step(&WithQuadrature, t, &y0, &k1, h, 3, &mut all);
        step(&WithQuadrature, t, &y0, &k1, h, 2, &mut dynamic);
        assert_eq!(all.y1, dynamic.y1);
        assert_eq!(all.k, dynamic.k);
        assert_eq!(all.err[..2], dynamic.err[..2]);
        assert_eq!(dynamic.err[2], 0.0);
        // The quadrature is integrated, not carried: ∫ x² over the step is about h x0².
        assert!((dynamic.y1[2] - y0[2] - h * y0[0] * y0[0]).abs() < 0.1 * h * y0[0] * y0[0]);
    }
}
