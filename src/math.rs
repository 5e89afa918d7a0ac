//! Elementary functions on the hot path of the right-hand side, cheaper than the ones Rust
//! links by default and as accurate as the model needs (each documents the error measured
//! against the standard library by its test). Knows nothing of gears or integrators.
//!
//! Why: in this crate's release build (LTO), `f64::cbrt` resolves to compiler_builtins'
//! correctly rounded software cbrt and `sin_cos` to glibc's general routine, both on the
//! critical path of every right-hand side; these are cheaper there. The band's
//! smoothing sin² is a polynomial on its argument's range ([`sin_squared`]), which needs no
//! argument reduction. Figures: docs/DECISIONS.md, D8 and D13 to D15.

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

/// 1/k for k < 32 (1/0 left 0), for the Taylor recurrences: a multiply where a division by
/// the term's index would sit on their chain of dependent operations.
pub const INVERSES: [f64; 32] = {
    let mut t = [0.0; 32];
    let mut k = 1;
    while k < 32 {
        t[k] = 1.0 / k as f64;
        k += 1;
    }
    t
};

/// The first K coefficients of the product of two series: p_k = Σ_{i+j=k} a_i b_j. With K
/// known at compile time the loops unroll into independent multiply-adds.
#[inline(always)]
pub fn series_product<const K: usize>(a: &[f64; K], b: &[f64; K]) -> [f64; K] {
    let mut p = [0.0; K];
    for i in 0..K {
        for j in 0..K - i {
            p[i + j] += a[i] * b[j];
        }
    }
    p
}

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

/// Arguments up to this size are reduced by a three-part Cody-Waite π/2 (the quotient fits
/// 20 bits, so its products with the 33-bit parts are exact); beyond, `f64::sin_cos`.
const REDUCTION_LIMIT: f64 = 1_647_099.0; // ≈ 2^20 · π/2

/// (sin x, cos x): the argument reduced to [−π/4, π/4] by a three-part π/2, then fdlibm's
/// minimax kernels (__kernel_sin, __kernel_cos, both < 1 ulp on that interval).
///
/// Error against `f64::sin_cos`, measured by `sin_cos_matches_std` over 1e6 arguments up to
/// 1.6e6 rad, 1e6 excitation angles and the multiples of π/2 up to ±1000: at most 1.2e-16
/// absolute (half an ulp of 1), and within 2 ulp of std's where |sin| or |cos| > 2^-10.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    // Large or not finite (NaN fails every comparison): the standard library's.
    if x.is_nan() || x.abs() > REDUCTION_LIMIT {
        return x.sin_cos();
    }
    let (n, r, y) = reduce(x);
    let (s, c) = (kernel_sin(r, y), kernel_cos(r, y));
    match n & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// x = n·π/2 + (r + y) with |r| ≤ π/4 (about) and y a correction below ulp(r), for
/// |x| ≤ REDUCTION_LIMIT.
#[inline]
fn reduce(x: f64) -> (i64, f64, f64) {
    const INV_PIO2: f64 = std::f64::consts::FRAC_2_PI;
    // π/2 in parts of 33 bits: PIO2_1 + PIO2_2 + PIO2_3 + PIO2_3T.
    const PIO2_1: f64 = 1.570_796_326_734_125_6;
    const PIO2_2: f64 = 6.077_100_506_303_966e-11;
    const PIO2_3: f64 = 2.022_266_248_711_166_5e-21;
    const PIO2_3T: f64 = 8.478_427_660_368_9e-32;
    // Round to nearest by adding and removing 1.5·2^52 (|x·2/π| < 2^51): `f64::round` is a
    // library call on the baseline x86-64 target, which has no rounding instruction.
    const TOINT: f64 = 6_755_399_441_055_744.0;
    let n = (x * INV_PIO2 + TOINT) - TOINT;
    // x − n·π/2: the first two products are exact, the subtractions nearly so.
    let r1 = x - n * PIO2_1;
    let r2 = r1 - n * PIO2_2;
    let tail = n * PIO2_3;
    let r = r2 - tail;
    // What the last subtraction lost, and the fourth part of π/2, as a correction.
    let y = ((r2 - r) - tail) - n * PIO2_3T;
    (n as i64, r, y)
}

/// sin(x + y) for |x| ≤ π/4, y a correction below ulp(x) (fdlibm's __kernel_sin).
#[inline]
fn kernel_sin(x: f64, y: f64) -> f64 {
    const S1: f64 = -1.666_666_666_666_663_2e-1;
    const S2: f64 = 8.333_333_333_322_49e-3;
    const S3: f64 = -1.984_126_982_985_795e-4;
    const S4: f64 = 2.755_731_370_707_006_8e-6;
    const S5: f64 = -2.505_076_025_340_686_3e-8;
    const S6: f64 = 1.589_690_995_211_55e-10;
    let z = x * x;
    let v = z * x;
    let r = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    x - ((z * (0.5 * y - v * r) - y) - v * S1)
}

/// cos(x + y) for |x| ≤ π/4, y a correction below ulp(x) (fdlibm's __kernel_cos).
#[inline]
fn kernel_cos(x: f64, y: f64) -> f64 {
    const C1: f64 = 4.166_666_666_666_66e-2;
    const C2: f64 = -1.388_888_888_887_411e-3;
    const C3: f64 = 2.480_158_728_947_673e-5;
    const C4: f64 = -2.755_731_435_139_066_3e-7;
    const C5: f64 = 2.087_572_321_298_175e-9;
    const C6: f64 = -1.135_964_755_778_819_5e-11;
    let z = x * x;
    let w = z * z;
    let r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    w + (((1.0 - w) - hz) + (z * r - x * y))
}

/// Taylor coefficients of (sin x / x)² in u = x²: (−1)^k 2^(2k+1) / (2k+2)!, k = 0..12.
const SIN_SQUARED: [f64; 13] = {
    let mut c = [0.0; 13];
    let mut k = 0;
    while k < 13 {
        // 2^(2k+1) / (2k+2)! as a product of 2·2/((2j+1)(2j+2)), j = 0..k, halved.
        let mut term = 0.5;
        let mut j = 0;
        while j <= k {
            term *= 4.0 / ((2 * j + 1) as f64 * (2 * j + 2) as f64);
            j += 1;
        }
        c[k] = if k % 2 == 0 { term } else { -term };
        k += 1;
    }
    c
};

/// sin² x for |x| ≤ π/2: the smoothing factor of the contact bands (docs/MODEL.md §2), to
/// 6e-16 absolute, under 3 ulp of 1 (test `sin_squared_matches_std`, measured 5.6e-16).
/// x² times the Taylor series of (sin x / x)² to u^12 (u = x², truncation below 2e-16 at
/// π/2), summed by Estrin's scheme.
///
/// Why not `f64::sin`: the band's factor lies on the critical path of every band RHS (the
/// next stage waits for it), and glibc's sin has an argument reduction and branches; this
/// one needs neither, the argument being within π/2 (docs/DECISIONS.md, D15).
#[inline]
pub fn sin_squared(x: f64) -> f64 {
    let c = &SIN_SQUARED;
    let u = x * x;
    let (u2, u4) = (u * u, (u * u) * (u * u));
    let u8 = u4 * u4;
    let q0 = (c[0] + c[1] * u) + (c[2] + c[3] * u) * u2;
    let q1 = (c[4] + c[5] * u) + (c[6] + c[7] * u) * u2;
    let q2 = (c[8] + c[9] * u) + (c[10] + c[11] * u) * u2;
    let p = (q0 + q1 * u4) + (q2 + c[12] * u4) * u8;
    u * p
}

/// log2 x for a positive, finite, normal x, to 7.3e-4 absolute: x = 2^e·m with m ∈ [1, 2)
/// taken apart from its bits, log2 m by a cubic (Chebyshev fit). For the step-size
/// controller's powers of the error, where a relative error of 1e-4 in the step factor does
/// not matter but latency does: the next step waits for the factor, which two `f64::powf`
/// delay (docs/DECISIONS.md, D8). Zero gives −1025.
#[inline]
pub const fn log2_coarse(x: f64) -> f64 {
    const C: [f64; 4] = [
        -2.144_960_694_619_865_4,
        3.029_512_035_753_271,
        -1.039_275_851_181_590_5,
        0.155_448_654_104_430_98,
    ];
    let bits = x.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let m = f64::from_bits(0x3ff0_0000_0000_0000 | (bits & 0x000f_ffff_ffff_ffff));
    // Estrin's scheme: two independent halves.
    let (lo, hi) = (C[0] + C[1] * m, C[2] + C[3] * m);
    e as f64 + (lo + (m * m) * hi)
}

/// 2^z to 1.1e-4 relative, saturating to 2^−1022 below −1022 and to 2^1023 above:
/// z = k + f with f ∈ [−½, ½], 2^f by a cubic (Chebyshev fit). With [`log2_coarse`].
#[inline]
pub fn exp2_coarse(z: f64) -> f64 {
    const C: [f64; 4] = [
        0.999_924_443_677_381_6,
        0.693_121_023_535_892,
        0.242_640_687_283_026,
        0.055_922_119_292_500_586,
    ];
    let z = z.clamp(-1022.0, 1023.0);
    // Round to nearest by adding and removing 1.5·2^52 (no rounding instruction on baseline
    // x86-64, see `reduce`).
    const TOINT: f64 = 6_755_399_441_055_744.0;
    let k = (z + TOINT) - TOINT;
    let f = z - k;
    let (lo, hi) = (C[0] + C[1] * f, C[2] + C[3] * f);
    (lo + (f * f) * hi) * f64::from_bits(((k as i64 + 1023) as u64) << 52)
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

    #[test]
    fn sin_cos_matches_std() {
        let mut u = uniform(0x2545_f491_4f6c_dd1d);
        let (mut worst_abs, mut worst_ulps) = (0.0f64, 0);
        let mut check = |x: f64| {
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            worst_abs = worst_abs.max((s - s0).abs()).max((c - c0).abs());
            for (a, b) in [(s, s0), (c, c0)] {
                if b.abs() > 1.0 / 1024.0 {
                    worst_ulps = worst_ulps.max(ulps(a, b));
                }
            }
        };
        for _ in 0..1_000_000 {
            check(REDUCTION_LIMIT * (2.0 * u() - 1.0));
        }
        // The excitation's arguments: w t for f up to 1 kHz over the first seconds, and
        // multiples of π/2 where the reduction cancels most.
        for k in 0..1_000_000 {
            check(2.0 * std::f64::consts::PI * 1e3 * k as f64 * 1.3e-6);
        }
        for k in -1000..=1000 {
            let x = k as f64 * std::f64::consts::FRAC_PI_2;
            check(x);
            check(x * (1.0 + f64::EPSILON));
        }
        assert!(worst_abs <= 1.2e-16, "sin_cos off by {worst_abs:e}");
        assert!(worst_ulps <= 2, "sin_cos off by {worst_ulps} ulp");
        for x in [0.0, -0.0, 1e-300, 1e7, -3e9, f64::INFINITY, f64::NAN] {
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            assert!(
                s.to_bits() == s0.to_bits() || (s - s0).abs() <= 1.2e-16,
                "{x:e}"
            );
            assert!(
                c.to_bits() == c0.to_bits() || (c - c0).abs() <= 1.2e-16,
                "{x:e}"
            );
        }
    }

    /// e^x · e^(2x) = e^(3x): the product of the series 1/k! and 2^k/k! has the terms 3^k/k!,
    /// each within 1e-14 (a sum of k + 1 positive products); and 1/k from the table is the
    /// division's.
    #[test]
    fn series_product_of_exponentials() {
        const K: usize = 12;
        let mut factorial = 1.0;
        let (mut a, mut b, mut expected) = ([0.0; K], [0.0; K], [0.0; K]);
        for k in 0..K {
            if k > 0 {
                factorial *= k as f64;
            }
            a[k] = 1.0 / factorial;
            b[k] = 2f64.powi(k as i32) / factorial;
            expected[k] = 3f64.powi(k as i32) / factorial;
        }
        let p = series_product(&a, &b);
        for k in 0..K {
            assert!(
                (p[k] - expected[k]).abs() <= 1e-14 * expected[k],
                "k {k}: {} vs {}",
                p[k],
                expected[k]
            );
        }
        for (k, inverse) in INVERSES.iter().enumerate().skip(1) {
            assert_eq!(*inverse, 1.0 / k as f64);
        }
    }

    /// sin_squared against std's sin, squared, over 1e6 arguments uniform in [−π/2, π/2]
    /// and the ends: within 6e-16 absolute.
    #[test]
    fn sin_squared_matches_std() {
        let mut u = uniform(0x1405_7b7e_f767_814f);
        let half_pi = std::f64::consts::FRAC_PI_2;
        let mut worst = 0.0f64;
        for k in 0..1_000_002 {
            let x = match k {
                0 => half_pi,
                1 => -half_pi,
                _ => half_pi * (2.0 * u() - 1.0),
            };
            worst = worst.max((sin_squared(x) - x.sin().powi(2)).abs());
        }
        assert!(worst < 6e-16, "worst {worst:e}");
        assert_eq!(sin_squared(0.0), 0.0);
    }

    /// log2_coarse and exp2_coarse against the standard library's: over 1e6 arguments
    /// log-uniform from 1e-300 to 1e300, and 1e6 in [−1000, 1000], within their documented
    /// bounds; saturation as documented.
    #[test]
    fn coarse_log2_exp2_match_std() {
        let mut u = uniform(0x5851_f42d_4c95_7f2d);
        for _ in 0..1_000_000 {
            let x = 10f64.powf(600.0 * u() - 300.0);
            let err = (log2_coarse(x) - x.log2()).abs();
            assert!(err < 7.3e-4, "log2_coarse({x:e}) = {}", log2_coarse(x));
            let z = 2000.0 * u() - 1000.0;
            let rel = (exp2_coarse(z) / z.exp2() - 1.0).abs();
            assert!(rel < 1.1e-4, "exp2_coarse({z}) = {}", exp2_coarse(z));
        }
        assert!(log2_coarse(0.0) < -1000.0);
        assert!((exp2_coarse(-5000.0) / 2f64.powi(-1022) - 1.0).abs() < 1.1e-4);
        assert!((exp2_coarse(5000.0) / 2f64.powi(1023) - 1.0).abs() < 1.1e-4);
    }

    /// log2_coarse does not decrease as its argument grows, but for its rounding (a few ulps
    /// of the result: the step-size controller's floors compare errors by their log2):
    /// over 2^20 mantissas evenly spread on [1, 2), across a power of two, and ulp by ulp
    /// about the controller's floors 1e-4 and 1e-2.
    #[test]
    fn log2_coarse_never_decreases() {
        let rising = |xs: &mut dyn Iterator<Item = f64>| {
            let mut last = (0.0, f64::NEG_INFINITY);
            for x in xs {
                let l = log2_coarse(x);
                let rounding = 4.0 * f64::EPSILON * l.abs().max(1.0);
                assert!(
                    l >= last.1 - rounding,
                    "log2_coarse({x:e}) = {l} < log2_coarse({:e}) = {}",
                    last.0,
                    last.1
                );
                last = (x, l);
            }
        };
        rising(&mut (0..1u64 << 20).map(|k| 1.0 + k as f64 / (1u64 << 20) as f64));
        for x0 in [2.0f64, 1e-4, 1e-2] {
            let bits = x0.to_bits();
            rising(&mut (bits - 100_000..bits + 100_000).map(f64::from_bits));
        }
    }
}
