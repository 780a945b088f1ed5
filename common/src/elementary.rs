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
//! `asin.c`, `exp.c`; public domain): atan on the argument reduced to [0, 0.66] (with the pi/4 shift
//! above that and 1/x above tan(3 pi/8)), a 4/5 rational in x^2, peak relative error
//! 1.9e-16 in IEEE double; asin as a + a^3 P(a^2)/Q(a^2) for |a| <= 0.625 and through
//! sqrt((1 - a)/2) above, peak relative error 2.5e-16; exp as 2^n exp(r), |r| <= ln 2 / 2,
//! exp(r) = 1 + 2 r P(r^2) / (Q(r^2) - r P(r^2)), peak relative error 2.2e-16. The tests
//! check both against the standard library to a few units in the last place.
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

/// e^x, as `f64::exp` (to within a few ulp).
#[inline(always)]
pub fn exp(x: f64) -> f64 {
    const LOG2E: f64 = std::f64::consts::LOG2_E;
    const C1: f64 = 6.931_457_519_531_25e-1; // ln 2, high part (exact in few bits)
    const C2: f64 = 1.428_606_820_309_417_3e-6; // ln 2 - C1
    if !(-708.0..=709.0).contains(&x) {
        return exp_out_of_range(x);
    }
    // n = round(x / ln 2), by the 1.5 * 2^52 trick (exact for |x / ln 2| < 2^51).
    const ROUND: f64 = 6_755_399_441_055_744.0;
    let shifted = LOG2E.mul_add(x, ROUND);
    let n = shifted - ROUND;
    let r = (-n).mul_add(C2, (-n).mul_add(C1, x));
    let rr = r * r;
    let p = r * horner(
        rr,
        1.261_771_930_748_105_9e-4,
        &[3.029_944_077_074_419_6e-2, 1.0],
    );
    let q = horner(
        rr,
        3.001_985_051_386_644_5e-6,
        &[2.524_483_403_496_841e-3, 2.272_655_482_081_550_3e-1, 2.0],
    );
    let e = 2.0f64.mul_add(p / (q - p), 1.0);
    // Scale by 2^n through the exponent bits (n is within the normal range here).
    // n sits in the low bits of `shifted` (two's complement, |n| < 2^51), so the exponent
    // field (n + 1023) << 52 is formed without a float-to-integer conversion.
    e * f64::from_bits(shifted.to_bits().wrapping_add(1023) << 52)
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
