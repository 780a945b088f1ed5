//! Elementary functions for the force evaluation: `atan2`, `asin` and `exp`, inlined.
//!
//! Every force evaluation needs an `atan2` (angle of attack), an `asin` (sideslip) and an
//! `exp` (interference decay); through the system math library they
//! are opaque calls that cost more than the rest of the evaluation and, because every
//! floating-point register is caller-saved, force the evaluation's live values to memory
//! around each call. These versions are plain Rust, inlined into the force evaluation, and give
//! the same bits on every platform (the system libraries differ between versions and CPU
//! features), which keeps runs bit-identical across the hosts of a distributed fit.
//!
//! Sources: the rational approximations are S. L. Moshier's Cephes Math Library (`atan.c`,
//! `asin.c`; public domain): atan on the argument reduced to [0, 0.66] (with the pi/4 shift
//! above that and 1/x above tan(3 pi/8)), a 4/5 rational in x^2, peak relative error
//! 1.9e-16 in IEEE double; asin as a + a^3 P(a^2)/Q(a^2) for |a| <= 0.625 and through
//! sqrt((1 - a)/2) above, peak relative error 2.5e-16. exp is P. T. P. Tang's table method
//! (ACM TOMS 15, 1989; as in ARM's optimized-routines): a table of 2^(j/64) and a short
//! polynomial, no division. The tests check each against the standard library to a few units
//! in the last place.
//!
//! The polynomials are evaluated by Horner's rule with fused multiply-adds (`f64::mul_add`,
//! one rounding per step): exactly the same bits with or without an FMA unit (see
//! [`crate::propagator::propagate`] for the build that uses one).

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// Extra bits of pi/2 beyond its double (Cephes `MOREBITS`).
const MOREBITS: f64 = 6.123_233_995_736_766e-17;

/// Cephes atan.c: atan(t) = t + t z P(z) / Q(z), z = t^2 (Q's leading coefficient is 1).
const ATAN_P: [f64; 5] = [
    -8.750_608_600_031_904e-1,
    -1.615_753_718_733_365e1,
    -7.500_855_792_314_705e1,
    -1.228_866_684_490_136_2e2,
    -6.485_021_904_942_025e1,
];
const ATAN_Q: [f64; 5] = [
    2.485_846_490_142_306_3e1,
    1.650_270_098_316_988_6e2,
    4.328_810_604_912_903e2,
    4.853_903_996_359_137e2,
    1.945_506_571_482_614e2,
];
/// Cephes asin.c: asin(a) = a + a z P(z) / Q(z), z = a^2, |a| <= 0.625 (Q's leading
/// coefficient is 1).
const ASIN_P: [f64; 6] = [
    4.253_011_369_004_428e-3,
    -6.019_598_008_014_124e-1,
    5.444_622_390_564_711,
    -1.626_247_967_210_700_2e1,
    1.956_261_983_317_594_8e1,
    -8.198_089_802_484_825,
];
const ASIN_Q: [f64; 5] = [
    -1.474_091_372_988_853_8e1,
    7.049_610_280_856_842e1,
    -1.471_791_292_232_726e2,
    1.395_105_614_657_485_7e2,
    -4.918_853_881_490_881e1,
];

/// atan(x) for x in [0, inf].
#[inline(always)]
fn atan_nonnegative(x: f64) -> f64 {
    // Cephes atan.c: reduce to [0, 0.66].
    const T3P8: f64 = 2.414_213_562_373_095; // tan(3 pi / 8)
    if x <= 0.66 {
        // The store's case (|alpha| < 33 deg): no reduction.
        return x.mul_add(atan_ratio(x * x), x);
    }
    let (offset, extra, t) = if x > T3P8 {
        (FRAC_PI_2, MOREBITS, -1.0 / x)
    } else {
        (FRAC_PI_4, 0.5 * MOREBITS, (x - 1.0) / (x + 1.0))
    };
    offset + (t + t.mul_add(atan_ratio(t * t), extra))
}

/// Cephes atan.c's rational part: atan(t) = t + t z P(z) / Q(z), z = t^2 <= 0.66^2; returns
/// z P(z) / Q(z).
#[inline(always)]
fn atan_ratio(z: f64) -> f64 {
    let p = horner(z, ATAN_P[0], &[ATAN_P[1], ATAN_P[2], ATAN_P[3], ATAN_P[4]]);
    let q = horner(z, 1.0, &ATAN_Q);
    z * p / q
}

/// `c0 x^n + c[0] x^(n-1) + ... + c[n-1]` by Horner's rule with fused multiply-adds.
#[inline(always)]
fn horner<const N: usize>(x: f64, c0: f64, c: &[f64; N]) -> f64 {
    c.iter().fold(c0, |acc, &ci| acc.mul_add(x, ci))
}

/// Four-quadrant arc tangent of y / x, as `f64::atan2` (to within a few ulp), in [-pi, pi].
#[inline(always)]
pub fn atan2(y: f64, x: f64) -> f64 {
    if x > 0.0 {
        // The store's case: flying forward. One division, no quadrant logic.
        let a = atan_nonnegative((y / x).abs());
        // The sign of y, as f64::atan2 (which keeps that of a zero y too).
        return a.copysign(y);
    }
    atan2_other_quadrants(y, x)
}

#[cold]
#[inline(never)]
fn atan2_other_quadrants(y: f64, x: f64) -> f64 {
    if x.is_nan() || y.is_nan() {
        return f64::NAN;
    }
    if x == 0.0 {
        return if y > 0.0 {
            FRAC_PI_2
        } else if y < 0.0 {
            -FRAC_PI_2
        } else {
            0.0
        };
    }
    // x < 0: atan2 = +-(pi - atan(|y / x|)).
    let a = PI - atan_nonnegative((y / x).abs());
    if y < 0.0 { -a } else { a }
}

/// 2^(j/64), j = 0..63, rounded to nearest (bit patterns; computed with 200-bit arithmetic).
#[rustfmt::skip]
const EXP2_TABLE: [u64; 64] = [
    0x3ff0000000000000, 0x3ff02c9a3e778061, 0x3ff059b0d3158574, 0x3ff0874518759bc8,
    0x3ff0b5586cf9890f, 0x3ff0e3ec32d3d1a2, 0x3ff11301d0125b51, 0x3ff1429aaea92de0,
    0x3ff172b83c7d517b, 0x3ff1a35beb6fcb75, 0x3ff1d4873168b9aa, 0x3ff2063b88628cd6,
    0x3ff2387a6e756238, 0x3ff26b4565e27cdd, 0x3ff29e9df51fdee1, 0x3ff2d285a6e4030b,
    0x3ff306fe0a31b715, 0x3ff33c08b26416ff, 0x3ff371a7373aa9cb, 0x3ff3a7db34e59ff7,
    0x3ff3dea64c123422, 0x3ff4160a21f72e2a, 0x3ff44e086061892d, 0x3ff486a2b5c13cd0,
    0x3ff4bfdad5362a27, 0x3ff4f9b2769d2ca7, 0x3ff5342b569d4f82, 0x3ff56f4736b527da,
    0x3ff5ab07dd485429, 0x3ff5e76f15ad2148, 0x3ff6247eb03a5585, 0x3ff6623882552225,
    0x3ff6a09e667f3bcd, 0x3ff6dfb23c651a2f, 0x3ff71f75e8ec5f74, 0x3ff75feb564267c9,
    0x3ff7a11473eb0187, 0x3ff7e2f336cf4e62, 0x3ff82589994cce13, 0x3ff868d99b4492ed,
    0x3ff8ace5422aa0db, 0x3ff8f1ae99157736, 0x3ff93737b0cdc5e5, 0x3ff97d829fde4e50,
    0x3ff9c49182a3f090, 0x3ffa0c667b5de565, 0x3ffa5503b23e255d, 0x3ffa9e6b5579fdbf,
    0x3ffae89f995ad3ad, 0x3ffb33a2b84f15fb, 0x3ffb7f76f2fb5e47, 0x3ffbcc1e904bc1d2,
    0x3ffc199bdd85529c, 0x3ffc67f12e57d14b, 0x3ffcb720dcef9069, 0x3ffd072d4a07897c,
    0x3ffd5818dcfba487, 0x3ffda9e603db3285, 0x3ffdfc97337b9b5f, 0x3ffe502ee78b3ff6,
    0x3ffea4afa2a490da, 0x3ffefa1bee615a27, 0x3fff50765b6e4540, 0x3fffa7c1819e90d8,
];

/// e^x, as `f64::exp` (to within a few ulp).
///
/// Tang's table method, without a division: x = (64 e + j) ln 2 / 64 + r with |r| <= ln 2 / 128,
/// e^x = 2^e 2^(j/64) e^r, and e^r - 1 by its Taylor polynomial of degree 5 (truncation error
/// below 4e-17 relative). Error: the rounding of the table entry and a few of the last
/// multiply-add, about 1 ulp.
#[inline(always)]
pub fn exp(x: f64) -> f64 {
    const SHIFT: f64 = 6_755_399_441_055_744.0; // 1.5 * 2^52
    const N_OVER_LN2: f64 = 92.332_482_616_893_66; // 64 / ln 2
    const LN2_OVER_N_HI: f64 = 0.010_830_424_696_249_145; // ln 2 / 64, rounded
    const LN2_OVER_N_LO: f64 = 3.623_510_646_634_843e-19; // ln 2 / 64 - LN2_OVER_N_HI
    if !(-708.0..=709.0).contains(&x) {
        return exp_out_of_range(x);
    }
    // k = 64 e + j = round(64 x / ln 2) by the 1.5 * 2^52 trick: k sits in the low bits of
    // `shifted` (two's complement, |k| < 2^17).
    let shifted = x.mul_add(N_OVER_LN2, SHIFT);
    let k = shifted - SHIFT;
    let r = (-k).mul_add(LN2_OVER_N_LO, (-k).mul_add(LN2_OVER_N_HI, x));
    // 2^e 2^(j/64): e added to the exponent field of the table entry (the result is normal
    // for x >= -708).
    let bits = shifted.to_bits();
    let j = bits & 63;
    let scale = f64::from_bits(EXP2_TABLE[j as usize].wrapping_add((bits - j) << 46));
    // e^r - 1 = r + r^2 (1/2 + r/6) + r^4 (1/24 + r/120).
    let r2 = r * r;
    let low = r.mul_add(1.0 / 6.0, 0.5);
    let high = r.mul_add(1.0 / 120.0, 1.0 / 24.0);
    let expm1 = (r2 * r2).mul_add(high, r2.mul_add(low, r));
    scale.mul_add(expm1, scale)
}

/// Arc sine, as `f64::asin` (to within a few ulp), for x in [-1, 1]; NaN outside.
#[inline(always)]
pub fn asin(x: f64) -> f64 {
    let a = x.abs();
    if a > 0.625 {
        return asin_large(x);
    }
    // Cephes asin.c: asin(a) = a + a^3 P(a^2) / Q(a^2) for a <= 0.625.
    let z = a * a;
    let p = horner(
        z,
        ASIN_P[0],
        &[ASIN_P[1], ASIN_P[2], ASIN_P[3], ASIN_P[4], ASIN_P[5]],
    );
    let q = horner(z, 1.0, &ASIN_Q);
    let r = a.mul_add(z * p / q, a);
    // The sign of x, as f64::asin (which keeps that of a zero x too).
    r.copysign(x)
}

#[cold]
#[inline(never)]
fn asin_large(x: f64) -> f64 {
    let a = x.abs();
    if a > 1.0 || x.is_nan() {
        return f64::NAN;
    }
    // Cephes asin.c: asin(a) = pi/2 - 2 asin(sqrt((1 - a) / 2)), in its rational form.
    let zz = 1.0 - a;
    let p = zz
        * ((((2.967_721_961_301_243e-3 * zz - 5.634_242_780_008_964e-1) * zz
            + 6.968_710_824_104_713)
            * zz
            - 2.556_901_049_652_825e1)
            * zz
            + 2.853_665_548_261_061_4e1)
        / ((((zz - 2.194_779_531_642_920_6e1) * zz + 1.470_656_354_026_815e2) * zz
            - 383.877_095_760_369_1)
            * zz
            + 3.424_398_657_913_078_5e2);
    let s = (zz + zz).sqrt();
    let r = FRAC_PI_4 - ((s * p - MOREBITS) - (FRAC_PI_4 - s));
    if x < 0.0 { -r } else { r }
}

/// The flow angles of the force evaluation together: `atan2(w, u)` and `asin(a)`, where the
/// caller also passes `a^2` as the quotient `a2_num / a2_den` (so that it need not wait for
/// `a` itself, which takes a square root and a division more).
///
/// In the store's range (u > 0, |w / u| <= 0.66, |a| <= 0.625: no range reduction) the two
/// Cephes rationals of [`atan2`] and [`asin`] are evaluated side by side, lane by lane: one
/// division gives `w / u` and `a^2`, one Horner pass the four polynomials (numerator and
/// denominator of each; atan's shorter numerator has a zero leading coefficient, which is
/// exact), one division both factors `1 + z P(z) / Q(z)`. Each lane is the same sequence of
/// correctly rounded operations whether or not the compiler packs the lanes into one vector
/// register, so every build gives the same bits. Outside that range this is [`atan2`] and
/// [`asin`] (`a` then must be within [-1, 1]).
#[inline(always)]
pub fn atan2_asin(w: f64, u: f64, a: f64, a2_num: f64, a2_den: f64) -> (f64, f64) {
    // Cephes's ranges without reduction: atan for |t| <= 0.66, asin for |a| <= 0.625.
    const ATAN_Z_MAX: f64 = 0.66 * 0.66;
    const ASIN_Z_MAX: f64 = 0.625 * 0.625;
    let [t, z_asin] = lanes(|i| [w, a2_num][i] / [u, a2_den][i]);
    let z_atan = t * t;
    // NaN fails the comparisons too.
    if !(u > 0.0 && z_atan <= ATAN_Z_MAX && z_asin <= ASIN_Z_MAX) {
        return atan2_asin_reduced(w, u, a);
    }
    // Lanes: atan numerator, asin numerator, atan denominator, asin denominator.
    const C: [[f64; 4]; 6] = [
        [0.0, ASIN_P[0], 1.0, 1.0],
        [ATAN_P[0], ASIN_P[1], ATAN_Q[0], ASIN_Q[0]],
        [ATAN_P[1], ASIN_P[2], ATAN_Q[1], ASIN_Q[1]],
        [ATAN_P[2], ASIN_P[3], ATAN_Q[2], ASIN_Q[2]],
        [ATAN_P[3], ASIN_P[4], ATAN_Q[3], ASIN_Q[3]],
        [ATAN_P[4], ASIN_P[5], ATAN_Q[4], ASIN_Q[4]],
    ];
    let z = [z_atan, z_asin, z_atan, z_asin];
    let pq = C[1..]
        .iter()
        .fold(C[0], |acc, c| lanes(|i| acc[i].mul_add(z[i], c[i])));
    // t (1 + z P(z) / Q(z)) = t (Q(z) + z P(z)) / Q(z), and likewise for a: the factor is
    // positive, so a zero t or a keeps its sign (as f64::atan2 and f64::asin).
    let factor: [f64; 2] = lanes(|i| z[i].mul_add(pq[i], pq[i + 2]) / pq[i + 2]);
    let [alpha, beta] = lanes(|i| [t, a][i] * factor[i]);
    (alpha, beta)
}

/// `[f(0), f(1), ...]`: lane-wise arithmetic written so the compiler may vectorise it.
#[inline(always)]
fn lanes<const N: usize>(f: impl FnMut(usize) -> f64) -> [f64; N] {
    std::array::from_fn(f)
}

#[cold]
#[inline(never)]
fn atan2_asin_reduced(w: f64, u: f64, a: f64) -> (f64, f64) {
    (atan2(w, u), asin(a))
}

#[cold]
#[inline(never)]
fn exp_out_of_range(x: f64) -> f64 {
    x.exp()
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // these tests check exact values on purpose
mod tests {
    use super::*;

    fn ulps(a: f64, b: f64) -> f64 {
        if a == b {
            return 0.0;
        }
        (a - b).abs() / (f64::EPSILON * b.abs().max(f64::MIN_POSITIVE))
    }

    #[test]
    fn atan2_matches_std_in_every_quadrant() {
        let mut worst: f64 = 0.0;
        for i in 0..20_001 {
            let angle = -PI + 2.0 * PI * i as f64 / 20_000.0;
            for &r in &[1e-3, 1.0, 293.0] {
                let (y, x) = (r * angle.sin(), r * angle.cos());
                worst = worst.max(ulps(atan2(y, x), y.atan2(x)));
            }
        }
        for &(y, x) in &[
            (1e-300, 1.0),
            (-3.0, 1e-300),
            (0.0, -1.0),
            (5.0, 0.0),
            (-5.0, 0.0),
        ] {
            worst = worst.max(ulps(atan2(y, x), f64::atan2(y, x)));
        }
        assert!(worst <= 4.0, "worst {worst} ulp");
        assert_eq!(atan2(0.0, 0.0), 0.0);
        assert!(atan2(f64::NAN, 1.0).is_nan());
    }

    #[test]
    fn asin_matches_std() {
        let mut worst: f64 = 0.0;
        for i in 0..200_001 {
            let x = -1.0 + 2.0 * i as f64 / 200_000.0;
            worst = worst.max(ulps(asin(x), x.asin()));
        }
        for &x in &[1e-300, -1e-10, 0.625, -0.625, 0.62500001, 1.0, -1.0] {
            worst = worst.max(ulps(asin(x), f64::asin(x)));
        }
        assert!(worst <= 4.0, "worst {worst} ulp");
        assert!(asin(1.5).is_nan() && asin(f64::NAN).is_nan());
    }

    #[test]
    fn atan2_asin_matches_std_inside_and_outside_the_packed_range() {
        let (mut worst_atan, mut worst_asin): (f64, f64) = (0.0, 0.0);
        for i in 0..20_001 {
            // Flow angles up to +-90 deg (the packed range ends at 33.4 deg of incidence and
            // 38.7 deg of sideslip); a sideslip component v of a speed 293 m/s.
            let angle = -FRAC_PI_2 + PI * i as f64 / 20_000.0;
            let (w, u) = (293.0 * angle.sin(), 293.0 * angle.cos());
            let v = 293.0 * (0.999_999 * angle).sin();
            let a = v / 293.0;
            let (alpha, beta) = atan2_asin(w, u, a, v * v, 293.0 * 293.0);
            worst_atan = worst_atan.max(ulps(alpha, w.atan2(u)));
            worst_asin = worst_asin.max(ulps(beta, a.asin()));
        }
        assert!(worst_atan <= 4.0, "atan2: worst {worst_atan} ulp");
        assert!(worst_asin <= 4.0, "asin: worst {worst_asin} ulp");
        let (alpha, beta) = atan2_asin(-0.0, 1.0, -0.0, 0.0, 1.0);
        assert!(alpha == 0.0 && alpha.is_sign_negative() && beta.is_sign_negative());
        let (alpha, beta) = atan2_asin(1.0, -1.0, 0.5, 0.25, 1.0);
        assert_eq!((alpha, beta), (atan2(1.0, -1.0), asin(0.5)));
    }

    #[test]
    fn exp_matches_std() {
        let mut worst: f64 = 0.0;
        for i in 0..200_001 {
            let x = -700.0 + 1400.0 * i as f64 / 200_000.0;
            worst = worst.max(ulps(exp(x), x.exp()));
        }
        for i in 0..100_001 {
            let x = -16.0 + 16.0 * i as f64 / 100_000.0;
            worst = worst.max(ulps(exp(x), x.exp()));
        }
        assert!(worst <= 4.0, "worst {worst} ulp");
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(-1000.0), 0.0);
        assert!(exp(1000.0).is_infinite());
    }
}
