//! LU decomposition with partial pivoting of a small square matrix held on the stack
//! (nalgebra's `SMatrix`), real or complex, for any const size N.
//!
//! nalgebra's own `LU` needs `Const<N>: DimMin<Const<N>>`, which a generic `const N` cannot
//! satisfy without typenum bounds leaking into every signature up to the FMU instance; its
//! dynamic-size `LU` allocates twice per decomposition. This is the same algorithm (row
//! pivoting on the largest |re| + |im|, like nalgebra's `icamax`) on a fixed-size matrix, with
//! the pivots in an array: no allocation, fully unrolled by the compiler for N ≤ 7.

use nalgebra::{ComplexField, SMatrix};

/// P·A = L·U, L unit lower triangular, both stored in one matrix; `perm[k]` is the row
/// swapped with row k at elimination step k.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lu<T, const N: usize> {
    lu: SMatrix<T, N, N>,
    perm: [usize; N],
}

impl<T, const N: usize> Lu<T, N>
where
    T: ComplexField<RealField = f64> + Copy,
{
    /// Decomposes `a`; `None` if a pivot is zero or not finite (singular, or NaN/Inf inside).
    #[inline]
    pub fn new(mut a: SMatrix<T, N, N>) -> Option<Self> {
        let mut perm = [0usize; N];
        for k in 0..N {
            let mut p = k;
            let mut best = a[(k, k)].norm1();
            for i in k + 1..N {
                let v = a[(i, k)].norm1();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            if best == 0.0 || !best.is_finite() {
                return None;
            }
            perm[k] = p;
            if p != k {
                a.swap_rows(k, p);
            }
            let inv = T::one() / a[(k, k)];
            for i in k + 1..N {
                let l = a[(i, k)] * inv;
                a[(i, k)] = l;
                for j in k + 1..N {
                    let u = a[(k, j)];
                    a[(i, j)] -= l * u;
                }
            }
        }
        Some(Lu { lu: a, perm })
    }

    /// Overwrites b with A⁻¹·b.
    #[inline]
    #[allow(clippy::needless_range_loop)]
    pub fn solve(&self, b: &mut [T; N]) {
        for k in 0..N {
            let p = self.perm[k];
            if p != k {
                b.swap(k, p);
            }
        }
        for i in 0..N {
            let mut s = b[i];
            for j in 0..i {
                s -= self.lu[(i, j)] * b[j];
            }
            b[i] = s;
        }
        for i in (0..N).rev() {
            let mut s = b[i];
            for j in i + 1..N {
                s -= self.lu[(i, j)] * b[j];
            }
            b[i] = s / self.lu[(i, i)];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Complex;

    #[test]
    fn solves_real_and_complex_systems_that_need_pivoting() {
        let a = SMatrix::<f64, 3, 3>::new(0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0);
        let x = [1.0, -2.0, 0.5];
        let mut b = [0.0; 3];
        for i in 0..3 {
            for j in 0..3 {
                b[i] += a[(i, j)] * x[j];
            }
        }
        Lu::new(a).unwrap().solve(&mut b);
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14, "{b:?}");
        }
        let c = |re, im| Complex::new(re, im);
        let a =
            SMatrix::<Complex<f64>, 2, 2>::new(c(0.0, 0.0), c(1.0, 2.0), c(3.0, -1.0), c(0.5, 0.0));
        let x = [c(1.0, 1.0), c(-2.0, 0.5)];
        let mut b = [c(0.0, 0.0); 2];
        for i in 0..2 {
            for j in 0..2 {
                b[i] += a[(i, j)] * x[j];
            }
        }
        Lu::new(a).unwrap().solve(&mut b);
        for i in 0..2 {
            assert!((b[i] - x[i]).norm() < 1e-14, "{b:?}");
        }
        assert!(Lu::new(SMatrix::<f64, 2, 2>::new(1.0, 2.0, 2.0, 4.0)).is_none());
        assert!(Lu::new(SMatrix::<f64, 2, 2>::new(f64::NAN, 2.0, 2.0, 4.0)).is_none());
    }
}
