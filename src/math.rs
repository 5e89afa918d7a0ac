//! Elementary functions on the hot path of the right-hand side, cheaper than the ones Rust
//! links by default and as accurate as the model needs (each documents the error measured
//! against the standard library by its test). Knows nothing of gears or integrators.
//!
//! Why: in this crate's release build (LTO), `f64::cbrt` resolves to compiler_builtins'
//! correctly rounded software cbrt; on the gear-rattle benchmark (S1) it took 25 % of the
//! samples. Measured on S1 (1 s, rtol 1e-7, GearRattle alone, the two builds alternated
//! 8 times): the run's median CPU time fell by about a fifth with the cube root below.

/// Bits of the mantissa that index the tables of `cbrt`.
const TABLE_BITS: u32 = 8;
const ENTRIES: usize = 1 << TABLE_BITS;
const SHIFT: u32 = 52 - TABLE_BITS;

/// cbrt(v) for v in [1, 8), by Newton's iteration in constant evaluation.
const fn const_cbrt(v: f64) -> f64 {
    let mut y = 1.5;
    let mut k = 0;
    while k < 60 {
        y = (2.0 * y + v / (y * y)) / 3.0;
        k += 1;
    }
    y
}

/// Midpoint of mantissa interval i: 1 + (i + 1/2) / ENTRIES (exact).
const fn midpoint(i: usize) -> f64 {
    1.0 + (i as f64 + 0.5) / ENTRIES as f64
}

/// ROOTS[j][i] = cbrt(2^j · midpoint(i)), RECIPROCALS[i] = 1 / midpoint(i).
const ROOTS: [[f64; ENTRIES]; 3] = {
    let mut t = [[0.0; ENTRIES]; 3];
    let mut j = 0;
    while j < 3 {
        let mut i = 0;
        while i < ENTRIES {
            t[j][i] = const_cbrt((1u64 << j) as f64 * midpoint(i));
            i += 1;
        }
        j += 1;
    }
    t
};
const RECIPROCALS: [f64; ENTRIES] = {
    let mut t = [0.0; ENTRIES];
    let mut i = 0;
    while i < ENTRIES {
        t[i] = 1.0 / midpoint(i);
        i += 1;
    }
    t
};

/// Cube root, for any f64, without division: x = 2^(3q+j)·m with m ∈ [1, 2) taken apart
/// from its bits, cbrt(2^j·m_i) read from a table at the midpoint m_i of m's interval
/// (256 intervals), and cbrt(1 + u), u = (m − m_i)/m_i, |u| < 2^-9, from its binomial series
/// to u^5. Zero, subnormal (scaled by 2^54 first), infinite and NaN arguments behave as
/// `f64::cbrt`'s. The tables are computed at compile time (Newton's iteration).
///
/// Why not `f64::cbrt`: in this crate's release build it is compiler_builtins' correctly
/// rounded cbrt, whose chain of divisions sits on the critical path of every contact RHS
/// (each stage of a step waits for the previous one); this one has no division and about
/// half its latency (measured in a loop where each argument depends on the last result).
///
/// Error against `f64::cbrt` (correctly rounded), measured by `cbrt_matches_std` over 2e6
/// arguments log-uniform from 1e-310 to 1e300 (both signs, subnormals included): at most
/// 2 ulp (1 ulp or less for 99.8 % of them); exact cubes may come out 1 ulp off (27 → 3 − 1 ulp).
#[inline]
pub fn cbrt(x: f64) -> f64 {
    // Binomial series of (1 + u)^(1/3).
    const A1: f64 = 1.0 / 3.0;
    const A2: f64 = -1.0 / 9.0;
    const A3: f64 = 5.0 / 81.0;
    const A4: f64 = -10.0 / 243.0;
    const A5: f64 = 22.0 / 729.0;
    let bits = x.to_bits();
    let sign = bits & 0x8000_0000_0000_0000;
    let mut biased = ((bits >> 52) & 0x7ff) as i64;
    let mut frac = bits & 0x000f_ffff_ffff_ffff;
    if biased == 0x7ff {
        return x + x;
    }
    if biased == 0 {
        if frac == 0 {
            return x;
        }
        let scaled = (x.abs() * f64::from_bits(0x4350_0000_0000_0000)).to_bits(); // · 2^54
        biased = ((scaled >> 52) & 0x7ff) as i64 - 54;
        frac = scaled & 0x000f_ffff_ffff_ffff;
    }
    // x = 2^(3q + j) · m, m in [1, 2).
    let e = biased - 1023 + 3 * 1023;
    let (q, j) = (e / 3 - 1023, (e % 3) as usize);
    let i = (frac >> SHIFT) as usize;
    let m = f64::from_bits(0x3ff0_0000_0000_0000 | frac);
    let mid = f64::from_bits(
        0x3ff0_0000_0000_0000 | (frac & !((1u64 << SHIFT) - 1)) | (1u64 << (SHIFT - 1)),
    );
    let u = (m - mid) * RECIPROCALS[i];
    let u2 = u * u;
    let p = (A1 + u * A2) + u2 * ((A3 + u * A4) + u2 * A5);
    let scale = f64::from_bits(sign | (((q + 1023) as u64) << 52)) * ROOTS[j][i];
    scale + scale * (u * p)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reproducible stream of uniform numbers in [0, 1) (xorshift64*).
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s ^= s >> 12;
            s ^= s << 25;
            s ^= s >> 27;
            (s.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn ulps(a: f64, b: f64) -> u64 {
        (a.to_bits() as i64).abs_diff(b.to_bits() as i64)
    }

    #[test]
    fn cbrt_matches_std() {
        let mut u = uniform(0x9e37_79b9_7f4a_7c15);
        let mut worst = 0;
        for k in 0..2_000_000 {
            // log-uniform over 1e-310 .. 1e300, both signs.
            let x = 10f64.powf(-310.0 + 610.0 * u());
            let x = if k % 2 == 0 { x } else { -x };
            let d = ulps(cbrt(x), x.cbrt());
            worst = worst.max(d);
        }
        // The ratios of the contact law: |δ|/G from 0 to a few.
        for k in 0..=100_000 {
            let x = k as f64 * 1e-5;
            worst = worst.max(ulps(cbrt(x), x.cbrt()));
        }
        assert!(worst <= 2, "cbrt off by {worst} ulp");
        for x in [0.0, -0.0] {
            assert_eq!(cbrt(x).to_bits(), x.to_bits());
        }
        for x in [
            f64::MIN_POSITIVE,
            5e-324,
            -5e-324,
            f64::MAX,
            1.0,
            8.0,
            -27.0,
            1e-300,
        ] {
            assert!(ulps(cbrt(x), x.cbrt()) <= 2, "cbrt({x:e})");
        }
        assert_eq!(cbrt(f64::INFINITY), f64::INFINITY);
        assert_eq!(cbrt(f64::NEG_INFINITY), f64::NEG_INFINITY);
        assert!(cbrt(f64::NAN).is_nan());
    }
}
