//! Elementary functions of the simulation, written once over lanes of doubles
//! ([`crate::lanes::Real`]): `exp`, `ln`, `pow`, `sin`, `cos`, `atan2`, `asin`, and the force
//! evaluation's packed flow angles (`atan2_asin`).
//!
//! **No result of a simulation depends on the host's C library.** Everything computed for a
//! candidate, from the setup (atmosphere, flight angles, effects) through every force
//! evaluation to the observed Euler angles, is a function of IEEE basic operations
//! (`+ - * /`, `sqrt`, fused multiply-add, each correctly rounded) and exact operations on the
//! representation (comparisons, sign, bit patterns, table look-ups), so two hosts give the same
//! bits. The system math libraries differ between versions and CPU features; these kernels do
//! not. (`f64::mul_add` calls the C library's `fma` on x86-64 hosts without FMA units, and
//! `floor`/`round` may be C library calls on x86-64 without SSE4.1: all three are exact
//! operations, correctly rounded by definition, so they give the same bits everywhere.) The
//! noise of synthetic flight tests (`noise.rs`, through `rand_distr`) and the coordinator's
//! statistics still use the standard library: they run on one host.
//!
//! **Lanes.** Each kernel is generic over [`Real`], implemented for `f64` and for four lanes
//! ([`crate::lanes::F64x4`]), and branch-free: the reduced ranges are part of one computation
//! (both arguments formed, one selected), special values (zeros, infinities, NaN, subnormals)
//! follow from the same arithmetic or are selected at the end. The four lanes of an `F64x4`
//! give bit for bit the scalar results (the rule of [`crate::lanes`]; tested with random and
//! special inputs). Three kernels keep their common case short and branch on "any lane" for a
//! rare one, where every lane takes the general form (which gives the common form's bits where
//! both apply): `exp` outside [-700, 700] (clamped argument, scale in two steps), `sin`/`cos`
//! for |x| > 2^20 (Payne and Hanek's reduction, lane by lane with the scalar code) and
//! `atan2_asin` outside the store's range (the general `atan2` and `asin`).
//!
//! **Methods and accuracy**: the largest error found against a 300-bit reference (`mpmath`),
//! over 8 000 values per function (12 000 for `atan2`) spread across its whole domain, boundaries
//! and hard cases included (`common/tests/model/elementary.rs` checks the tenth of them in
//! `elementary_reference.txt` to 1 ulp; both sets from `scripts/elementary_reference.py`):
//!
//! | function | method | max error |
//! |---|---|---|
//! | `exp` | P. T. P. Tang's table (ACM TOMS 15, 1989): 2^(j/64) rounded and its rounding error, a degree-6 polynomial, no division; results near the ends of the range scaled in two steps | 0.62 ulp |
//! | `ln` | x = 2^e m, m in [sqrt(1/2), sqrt(2)), ln m = 2 atanh(f / (2 + f)) as a series, evaluated in double-double | 0.50 ulp |
//! | `pow` (x >= 0) | exp(y ln x) with ln x and the product in double-double, exp of a double-double | 0.51 ulp |
//! | `sin`, `cos` | reduction by pi/2 (four-part Cody-Waite in double-double for \|x\| <= 2^20, Payne-Hanek with 1280 bits of 2/pi above), fdlibm's kernels on [-pi/4, pi/4] | 0.64 ulp (sin), 0.73 ulp (cos) |
//! | `atan2` | to t in [0, 1] by swapping y and x, above t = 0.66 to (t - 1) / (t + 1); S. L. Moshier's Cephes rational (`atan.c`); quadrant as a multiple of pi/4 | 0.78 ulp |
//! | `asin` | Cephes rational (`asin.c`) for \|x\| <= 0.625, pi/2 - 2 asin(sqrt((1 - \|x\|) / 2)) above, with the same rational | 0.74 ulp |
//!
//! Polynomials are evaluated by Horner's rule with fused multiply-adds (one rounding per
//! step). Sources: S. L. Moshier, Cephes Math Library (public domain); Sun Microsystems'
//! fdlibm (`k_sin.c`, `k_cos.c`, `e_rem_pio2.c`: freely distributable); P. T. P. Tang (above);
//! M. H. Payne and R. N. Hanek, "Radian reduction for trigonometric functions", SIGNUM
//! Newsletter 18 (1983).

use std::f64::consts::{FRAC_2_PI, FRAC_PI_2, FRAC_PI_4};

use crate::lanes::{Bits, Mask, Real};

/// `v` in every lane.
#[inline(always)]
fn c<R: Real>(v: f64) -> R {
    R::splat(v)
}

/// `c0 x^n + c[0] x^(n-1) + ... + c[n-1]` by Horner's rule with fused multiply-adds.
#[inline(always)]
fn horner<R: Real, const N: usize>(x: R, c0: f64, coefficients: &[f64; N]) -> R {
    coefficients
        .iter()
        .fold(c(c0), |acc: R, &ci| acc.mul_add(x, c(ci)))
}

/// a + b = s + e exactly (Knuth's two-sum, any order of magnitude).
#[inline(always)]
fn two_sum<R: Real>(a: R, b: R) -> (R, R) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// a + b = s + e exactly, for |a| >= |b| (or a = 0).
#[inline(always)]
fn fast_two_sum<R: Real>(a: R, b: R) -> (R, R) {
    let s = a + b;
    (s, b - (s - a))
}

/// 1.5 * 2^52: adding it rounds a double of magnitude below 2^51 to an integer, which then sits
/// in the low bits of the sum's pattern (two's complement).
const SHIFT: f64 = 6_755_399_441_055_744.0;
/// Extra bits of pi/2 beyond its double (pi/2 - `FRAC_PI_2`; Cephes `MOREBITS`).
const PIO2_LO: f64 = 6.123_233_995_736_766e-17;
/// pi/4 - `FRAC_PI_4` (`FRAC_PI_4` has 50 significant bits, so q pi/4 is exact for q <= 4).
const PIO4_LO: f64 = 3.061_616_997_868_383e-17;

// ---------------------------------------------------------------------------------------------
// exp

/// 64 / ln 2.
const N_OVER_LN2: f64 = 92.332_482_616_893_66;
/// ln 2 / 64, rounded.
const LN2_OVER_N_HI: f64 = 0.010_830_424_696_249_145;
/// ln 2 / 64 - `LN2_OVER_N_HI`.
const LN2_OVER_N_LO: f64 = 3.623_510_646_634_843e-19;
/// Arguments beyond these give 0 and +inf (e^-746 rounds to 0, e^710 overflows); clamping to
/// them keeps the reduction's integer small.
const EXP_MIN_ARG: f64 = -746.0;
const EXP_MAX_ARG: f64 = 710.0;
/// Beyond +-700 the result is scaled in two steps (2^(e -+ 128), then 2^(+-128)), so that each
/// factor is a normal double: the ends of the range (overflow, gradual underflow).
const EXP_SPLIT_ARG: f64 = 700.0;

/// e^x (error below 1 ulp; 0 below -745.2, +inf above 709.8, NaN for NaN).
///
/// Tang's table method, without a division: x = (64 e + j) ln 2 / 64 + r with |r| <= ln 2 / 128,
/// e^x = 2^e 2^(j/64) e^r, 2^(j/64) from a table of its rounded values and their relative
/// errors, and e^r - 1 by its Taylor polynomial of degree 6 (truncation error below 6e-20
/// relative).
///
/// Within [-700, 700] (the force evaluation's range) 2^e is a normal double and the result is
/// one scaling of the table entry. When any lane is outside (or NaN), all lanes take the
/// general form (clamped argument, the scale in two steps near the ends of the range), which
/// gives the same bits inside: a lane's result depends only on its own argument.
#[inline(always)]
pub fn exp<R: Real>(x: R) -> R {
    if !x.abs().le(c(EXP_SPLIT_ARG)).all() {
        return exp_general(x, c(0.0));
    }
    // k = 64 e + j = round(64 x / ln 2), in the low bits of `shifted`.
    let shifted = x.mul_add(c(N_OVER_LN2), c(SHIFT));
    let k = shifted - c(SHIFT);
    let r = (-k).mul_add(c(LN2_OVER_N_LO), (-k).mul_add(c(LN2_OVER_N_HI), x));
    exp_table(shifted, r)
}

/// e^(hi + lo) for a double-double argument (|lo| <= ulp(hi)), as [`exp`].
#[inline(always)]
pub fn exp_dd<R: Real>(hi: R, lo: R) -> R {
    exp_general(hi, lo)
}

/// e^(x + lo) over the whole range ([`exp`] outside [-700, 700]; `lo` is a tail of x, or 0).
#[cold]
#[inline(never)]
fn exp_general<R: Real>(x: R, lo: R) -> R {
    // Beyond these the result is 0 or +inf; clamping keeps the reduction's integer small. NaN
    // stays NaN.
    let clamped = R::select(x.gt(c(EXP_MAX_ARG)), c(EXP_MAX_ARG), x);
    let clamped = R::select(clamped.lt(c(EXP_MIN_ARG)), c(EXP_MIN_ARG), clamped);
    // A clamped (or NaN) argument drops its tail.
    let lo = R::select(clamped.eq(x), lo, c(0.0));
    let x = clamped;
    let shifted = x.mul_add(c(N_OVER_LN2), c(SHIFT));
    let k = shifted - c(SHIFT);
    let r = (-k).mul_add(c(LN2_OVER_N_LO), (-k).mul_add(c(LN2_OVER_N_HI), x)) + lo;
    // Near the ends of the range 2^e is not a normal double: take 2^(e -+ 128) in the table
    // scaling and 2^(+-128) after. Elsewhere the shift is 0 and the last factor 1 (exact), as
    // in `exp`.
    let high = x.gt(c(EXP_SPLIT_ARG));
    let low = x.lt(c(-EXP_SPLIT_ARG));
    let k_shift = R::select(
        high,
        c(64.0 * 128.0),
        R::select(low, c(-64.0 * 128.0), c(0.0)),
    );
    let last = R::select(
        high,
        c(f64::from_bits(0x47f0_0000_0000_0000)), // 2^128
        R::select(low, c(f64::from_bits(0x37f0_0000_0000_0000)), c(1.0)), // 2^-128
    );
    // k_shift is a multiple of 64 and `shifted` an integer below 2^53: exact.
    exp_table(shifted - k_shift, r) * last
}

/// 2^e 2^(j/64) e^r for k = 64 e + j in the low bits of `shifted` (2^e a normal double).
#[inline(always)]
fn exp_table<R: Real>(shifted: R, r: R) -> R {
    // 2^e 2^(j/64): e added to the exponent field of the table entry.
    let bits = shifted.to_bits();
    let j = bits.and(Bits::splat(63));
    let scale = R::from_bits(
        j.lookup(&EXP2_TABLE)
            .wrapping_add(bits.wrapping_sub(j).shl(46)),
    );
    // 2^(j/64) e^r = T_j (1 + c_j) e^r = T_j (1 + c_j + (e^r - 1)) to below 2^-60, with the
    // table's relative error c_j and e^r - 1 = r + r^2 (1/2 + r/6) + r^4 (1/24 + r/120 +
    // r^2/720).
    let correction = R::from_bits(j.lookup(&EXP2_CORRECTION));
    let r2 = r * r;
    let low_terms = r.mul_add(c(1.0 / 6.0), c(0.5));
    let high_terms = r.mul_add(r.mul_add(c(1.0 / 720.0), c(1.0 / 120.0)), c(1.0 / 24.0));
    let expm1 = (r2 * r2).mul_add(high_terms, r2.mul_add(low_terms, r + correction));
    scale.mul_add(expm1, scale)
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

/// (2^(j/64) - T_j) / T_j for the entries T_j of [`EXP2_TABLE`], rounded (bit patterns;
/// computed with 300-bit arithmetic): the table's rounding error, added to the polynomial.
#[rustfmt::skip]
const EXP2_CORRECTION: [u64; 64] = [
    0x0000000000000000, 0xbc7160139cd8dc5d, 0x3c8cd2523567f613, 0x3c60f74e61e6c861,
    0x3c979aa65d837b6d, 0x3c3ebe3d702f9cd1, 0xbc9556522a2fbd0e, 0xbc91c923b9d5f416,
    0xbc801b15eaa59348, 0x3c8b898c3f1353bf, 0x3c9aecf73e3a2f60, 0x3c8a6f4144a6c38d,
    0x3c968efde3a8a894, 0x3c80472b981fe7f2, 0x3c82f7e16d09ab31, 0x3c8b3782720c0ab4,
    0x3c834d754db0abb6, 0x3c8fdd395dd3f84a, 0xbc924aedcc4b5068, 0xbc71d1e83e9436d2,
    0x3c859f48a72a4c6d, 0xbc58a78f4817895b, 0x3c4363ed60c2ac11, 0x3c6ecce1daa10379,
    0x3c7690cebb7aafb0, 0xbc8f94340071a38e, 0xbc78dec6bd0f385f, 0x3c93350518fdd78e,
    0x3c9063e1e21c5409, 0x3c9432e62b64c035, 0xbc8c33c53bef4da8, 0xbc93cedd78565858,
    0xbc93b3efbf5e2228, 0xbc6367efb86da9ee, 0xbc781f647e5a3ecf, 0xbc8619321e55e68a,
    0xbc7b32dcb94da51d, 0x3c65ebe1abd66c55, 0xbc9369b6f13b3734, 0xbc94d450d872576e,
    0x3c8db72fc1f0eab4, 0x3c7bf68359f35f44, 0xbc5da9b88b6c1e29, 0xbc92434322f4f9aa,
    0x3c71affc2b91ce27, 0xbc87c50422622263, 0xbc91bbd1d3bcbb15, 0x3c8469846e735ab3,
    0x3c8c1a7792cb3387, 0xbc55c3d956dcaeba, 0xbc68d6f438ad9334, 0x3c74ffd70a5fddcd,
    0x3c736eae30af0cb3, 0x3c84e08fd10959ac, 0x3c676b2c6c921968, 0xbc8fad5d3ffffa6f,
    0x3c74a385a63d07a7, 0x3c8e5a50d5c192ac, 0xbc82d52107b43e1f, 0x3c74b604603a88d3,
    0xbc8ff7128fd391f0, 0x3c8ec3bc41aa2008, 0x3c8a64a931d185ee, 0x3c77893b4d91cd9d,
];

// ---------------------------------------------------------------------------------------------
// ln and pow

/// ln 2 to 42 bits (so that e ln 2 is exact for |e| < 2^11) and the rest.
const LN2_HI: f64 = 0.693_147_180_559_890_3;
const LN2_LO: f64 = 5.497_923_018_708_371e-14;
/// 2/3 as a double-double.
const TWO_THIRDS_HI: f64 = 0.666_666_666_666_666_6;
const TWO_THIRDS_LO: f64 = 3.700_743_415_417_188e-17;
/// 2 / (2k + 1), k = 13 down to 2: the atanh series beyond its first two terms (highest
/// degree first, for [`horner`]).
const ATANH_TAIL: [f64; 12] = [
    0.074_074_074_074_074_07,
    0.08,
    0.086_956_521_739_130_43,
    0.095_238_095_238_095_23,
    0.105_263_157_894_736_84,
    0.117_647_058_823_529_41,
    0.133_333_333_333_333_33,
    0.153_846_153_846_153_85,
    0.181_818_181_818_181_82,
    0.222_222_222_222_222_2,
    0.285_714_285_714_285_7,
    0.4,
];

/// ln x as a double-double (hi, lo), about 2^-70 relative, for positive finite x; for x = 0,
/// x < 0, +inf and NaN: (-inf, 0), (NaN, 0), (+inf, 0) and (NaN, 0).
///
/// x = 2^e m with m in [sqrt(1/2), sqrt(2)), f = m - 1 (exact), s = f / (2 + f) (|s| <= 0.172)
/// and ln m = 2 atanh s = 2 s + 2 s^3 / 3 + s^5 (2/5 + 2 s^2 / 7 + ...): the first two terms in
/// double-double, the rest (below 2^-12 of the sum) in double, to s^27.
#[inline(always)]
fn ln_dd<R: Real>(x: R) -> (R, R) {
    // Subnormals scaled into the normal range.
    let subnormal = x.lt(c(f64::MIN_POSITIVE));
    let x_scaled = R::select(subnormal, x * c(18_014_398_509_481_984.0), x); // 2^54
    let e_scale = R::select(subnormal, c(-54.0), c(0.0));
    // e = floor(log2(x / sqrt(1/2))): the exponent field of x's pattern minus that of
    // sqrt(1/2), as a signed 12-bit field (flipping its sign bit makes it unsigned).
    let bits = x_scaled.to_bits();
    let offset = bits.wrapping_sub(Bits::splat(0x3fe6_a09e_667f_3bcd));
    let e_biased = offset.xor(Bits::splat(1 << 63)).shr(52); // e + 2048
    let e =
        (R::from_bits(e_biased.or(Bits::splat(SHIFT.to_bits()))) - c(SHIFT)) - c(2048.0) + e_scale;
    let m = R::from_bits(bits.wrapping_sub(offset.and(Bits::splat(0xfff0_0000_0000_0000))));
    let f = m - c(1.0);
    // s = f / (2 + f) as a double-double.
    let u_hi = c::<R>(2.0) + f;
    let u_lo = f - (u_hi - c(2.0));
    let s_hi = f / u_hi;
    let s_lo = (-s_hi).mul_add(u_lo, (-s_hi).mul_add(u_hi, f)) / u_hi;
    // s^3 and 2 s^3 / 3 as double-doubles.
    let z = s_hi * s_hi;
    let z_lo = s_hi.mul_add(s_hi, -z);
    let s3 = z * s_hi;
    let s3_lo = z.mul_add(s_hi, -s3) + z_lo.mul_add(s_hi, c::<R>(3.0) * z * s_lo);
    let t3 = s3 * c(TWO_THIRDS_HI);
    let t3_lo =
        s3.mul_add(c(TWO_THIRDS_HI), -t3) + s3.mul_add(c(TWO_THIRDS_LO), s3_lo * c(TWO_THIRDS_HI));
    let tail = s3 * z * horner(z, ATANH_TAIL[0], &tail_coefficients());
    // e ln 2 + 2 s + 2 s^3 / 3 + tail.
    let (a, a_err) = two_sum(e * c(LN2_HI), s_hi + s_hi);
    let (b, b_err) = two_sum(a, t3);
    let lo = (a_err + b_err) + e.mul_add(c(LN2_LO), (s_lo + s_lo) + (t3_lo + tail));
    let (hi, lo) = fast_two_sum(b, lo);
    // Zero, negative, infinite and NaN arguments.
    let regular = x.gt(c(0.0)) & x.lt(c(f64::INFINITY));
    let special = R::select(
        x.eq(c(0.0)),
        c(f64::NEG_INFINITY),
        R::select(x.eq(c(f64::INFINITY)), x, c(f64::NAN)),
    );
    (
        R::select(regular, hi, special),
        R::select(regular, lo, c(0.0)),
    )
}

/// `ATANH_TAIL[1..]`.
#[inline(always)]
const fn tail_coefficients() -> [f64; 11] {
    let mut t = [0.0; 11];
    let mut i = 0;
    while i < 11 {
        t[i] = ATANH_TAIL[i + 1];
        i += 1;
    }
    t
}

/// Natural logarithm (error about 0.5 ulp): -inf at 0, NaN below 0 and for NaN.
#[inline(always)]
pub fn ln<R: Real>(x: R) -> R {
    ln_dd(x).0
}

/// x^y for x >= 0 (error below 1 ulp), as exp(y ln x) with ln x and the product carried
/// in double-double. x^0 = 1 and 1^y = 1 (also for NaN), 0^y is 0 for y > 0 and +inf for
/// y < 0, NaN for x < 0 (the sign of a zero x is ignored: (-0)^3 is +0).
#[inline(always)]
pub fn pow<R: Real>(x: R, y: R) -> R {
    let (l_hi, l_lo) = ln_dd(x);
    let p = y * l_hi;
    let p_lo = y.mul_add(l_hi, -p) + y * l_lo;
    // An infinite product (x = 0, +inf, or y infinite) has no tail.
    let p_lo = R::select(p.abs().lt(c(f64::INFINITY)), p_lo, c(0.0));
    let result = exp_dd(p, p_lo);
    R::select(y.eq(c(0.0)) | x.eq(c(1.0)), c(1.0), result)
}

// ---------------------------------------------------------------------------------------------
// atan2 and asin

/// Cephes atan.c: atan(t) = t + t z P(z) / Q(z), z = t^2, |t| <= 0.66 (Q's leading
/// coefficient is 1).
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
/// Cephes's range of atan without reduction: |t| <= 0.66.
pub const ATAN_T_MAX: f64 = 0.66;
/// Cephes's range of asin without reduction: |a| <= 0.625.
pub const ASIN_A_MAX: f64 = 0.625;

/// z P(z) / Q(z) of Cephes atan.c (for z = t^2 <= 0.66^2).
#[inline(always)]
fn atan_ratio<R: Real>(z: R) -> R {
    let p = horner(z, ATAN_P[0], &[ATAN_P[1], ATAN_P[2], ATAN_P[3], ATAN_P[4]]);
    let q = horner(z, 1.0, &ATAN_Q);
    z * p / q
}

/// z P(z) / Q(z) of Cephes asin.c (for z = a^2 <= 0.625^2).
#[inline(always)]
fn asin_ratio<R: Real>(z: R) -> R {
    let p = horner(
        z,
        ASIN_P[0],
        &[ASIN_P[1], ASIN_P[2], ASIN_P[3], ASIN_P[4], ASIN_P[5]],
    );
    let q = horner(z, 1.0, &ASIN_Q);
    z * p / q
}

/// Four-quadrant arc tangent of y / x in [-pi, pi] (error below 1 ulp), with the IEEE
/// special values: atan2(+-0, +0) = +-0, atan2(+-0, -0) = +-pi, +-pi/4 and +-3 pi/4 for two
/// infinities, the sign of y kept, NaN for NaN.
///
/// With a = |y|, b = |x|: t = min(a, b) / max(a, b) in [0, 1]; above t = 0.66 the argument is
/// s = (t - 1) / (t + 1) = (min - max) / (min + max) in (-0.205, 0] and pi/4 is added. The
/// angle is then q pi/4 +- atan(s), q in 0..=4 from the swap, the reduction and the sign of
/// x: one division for s, one for Cephes's rational, one for the rounding error of s.
#[inline(always)]
pub fn atan2<R: Real>(y: R, x: R) -> R {
    let (zero, one) = (c::<R>(0.0), c::<R>(1.0));
    let (a, b) = (y.abs(), x.abs());
    let swap = a.gt(b);
    // Equal magnitudes: t = 1, or 0 for two zeros (also for two infinities, where min / max is
    // NaN).
    let equal = a.eq(b);
    let num = R::select(equal & !a.eq(zero), one, R::select(swap, b, a));
    let den = R::select(equal, one, R::select(swap, a, b));
    let reduced = num.gt(den * c(ATAN_T_MAX));
    let x_negative = x.sign_bit();
    // The sign of atan(s) in the result: minus when exactly one of swap (pi/2 - ...) and a
    // negative x (pi - ...) holds.
    let minus = (swap & !x_negative) | (!swap & x_negative);
    // (num - den) / (num + den): the difference is exact (num >= 0.66 den); both scaled by 1/4
    // when large, so that the sum cannot overflow.
    let scale = R::select(
        den.gt(c(f64::from_bits(0x7fb0_0000_0000_0000))),
        c(0.25),
        one,
    ); // 2^1020
    let s_num = R::select(reduced, (num - den) * scale, num);
    let s_den = R::select(reduced, num.mul_add(scale, den * scale), den);
    let s_num = R::select(minus, -s_num, s_num);
    let s = s_num / s_den;
    let z = s * s;
    // The quotient's rounding error e / s_den (e = s_num - s s_den exactly), carried through
    // atan as e / (s_den (1 + z)); none for an infinite s_den.
    let remainder = (-s).mul_add(s_den, s_num);
    let s_lo = R::select(
        s_den.lt(c(f64::INFINITY)),
        remainder / s_den.mul_add(z, s_den),
        zero,
    );
    // q = base +- (1 if reduced): base 0 (x >= 0), 2 (swapped), 4 (x < 0).
    let quarter = R::select(reduced, one, zero);
    let base = R::select(swap, c(2.0), R::select(x_negative, c(4.0), zero));
    let q = base + R::select(minus, -quarter, quarter);
    let ratio = atan_ratio(z);
    // q pi/4 (exact) + (s + s ratio + s_lo + q (pi/4 - FRAC_PI_4)).
    let angle = q.mul_add(
        c(FRAC_PI_4),
        s + s.mul_add(ratio, q.mul_add(c(PIO4_LO), s_lo)),
    );
    angle.copysign(y)
}

/// Arc sine (error below 1 ulp), for x in [-1, 1]; NaN outside and for NaN; the sign of
/// a zero kept.
///
/// Cephes's rational for |x| <= 0.625; above, asin |x| = pi/2 - 2 asin s with
/// s = sqrt((1 - |x|) / 2) <= 0.433, the same rational at z = s^2 = (1 - |x|) / 2 (exact) and
/// s to twice the precision (one division more).
#[inline(always)]
pub fn asin<R: Real>(x: R) -> R {
    let a = x.abs();
    let reduced = a.gt(c(ASIN_A_MAX));
    let z_reduced = (c::<R>(1.0) - a) * c(0.5);
    let root = z_reduced.sqrt();
    let z = R::select(reduced, z_reduced, a * a);
    let s = R::select(reduced, root, a);
    let ratio = asin_ratio(z);
    let direct = s.mul_add(ratio, s);
    // pi/2 - 2 (s + s ratio) with s = root + root_lo, the square root to twice the precision
    // (z - root^2 is exact), and pi/2 - 2 root as a double-double.
    let two_root = root + root;
    let root_lo = (-root).mul_add(root, z_reduced) / R::select(root.gt(c(0.0)), two_root, c(1.0));
    let (head, head_lo) = fast_two_sum(c(FRAC_PI_2), -two_root);
    let reflected =
        head + (head_lo + (-two_root).mul_add(ratio, c::<R>(PIO2_LO) - (root_lo + root_lo)));
    R::select(reduced, reflected, direct).copysign(x)
}

/// The flow angles of the force evaluation together: `atan2(w, u)` and `asin(a)`, where the
/// caller also passes `a^2` as the quotient `a2_num / a2_den` (so that it need not wait for
/// `a` itself, which takes a square root and a division more).
///
/// In the store's range (u > 0, |w / u| <= 0.66, |a| <= 0.625: no range reduction) the two
/// Cephes rationals of [`atan2`] and [`asin`] are evaluated side by side, lane by lane: one
/// division gives `w / u` and `a^2`, one Horner pass the four polynomials (numerator and
/// denominator of each; atan's shorter numerator has a zero leading coefficient, which is
/// exact), one division both factors `1 + z P(z) / Q(z)`. Outside that range (in any lane)
/// this is [`atan2`] and [`asin`] in those lanes (`a` then must be within [-1, 1]); the two
/// forms differ in the last bits, and a lane's result depends only on that lane's input.
#[inline(always)]
pub fn atan2_asin<R: Real>(w: R, u: R, a: R, a2_num: R, a2_den: R) -> (R, R) {
    let [t, z_asin] = pair(|i| [w, a2_num][i] / [u, a2_den][i]);
    let z_atan = t * t;
    // NaN fails the comparisons too.
    let packed = u.gt(c(0.0))
        & z_atan.le(c(ATAN_T_MAX * ATAN_T_MAX))
        & z_asin.le(c(ASIN_A_MAX * ASIN_A_MAX));
    if !packed.all() {
        cold();
        return atan2_asin_mixed(packed, w, u, a, t, z_asin);
    }
    atan2_asin_packed(t, z_atan, a, z_asin)
}

/// [`atan2_asin`] in the store's range: t = w / u, z_atan = t^2, z_asin = a^2.
#[inline(always)]
fn atan2_asin_packed<R: Real>(t: R, z_atan: R, a: R, z_asin: R) -> (R, R) {
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
    let pq = C[1..].iter().fold(C[0].map(c::<R>), |acc, k| {
        std::array::from_fn(|i| acc[i].mul_add(z[i], c(k[i])))
    });
    // t (1 + z P(z) / Q(z)) = t (Q(z) + z P(z)) / Q(z), and likewise for a: the factor is
    // positive, so a zero t or a keeps its sign (as atan2 and asin).
    let factor: [R; 2] = pair(|i| z[i].mul_add(pq[i], pq[i + 2]) / pq[i + 2]);
    let [alpha, beta] = pair(|i| [t, a][i] * factor[i]);
    (alpha, beta)
}

/// [`atan2_asin`] when some lane is outside the store's range: there [`atan2`] and [`asin`].
/// Inlined (and so compiled with the caller's target features: out of line, in a build without
/// FMA, each `mul_add` would be a library call; a fit's wilder candidates take this path at
/// every stage), its branch marked cold.
#[inline(always)]
fn atan2_asin_mixed<R: Real>(packed: R::Mask, w: R, u: R, a: R, t: R, z_asin: R) -> (R, R) {
    let (alpha, beta) = atan2_asin_packed(t, t * t, a, z_asin);
    (
        R::select(packed, alpha, atan2(w, u)),
        R::select(packed, beta, asin(a)),
    )
}

/// Marks the branch that calls it as rarely taken (code layout only).
#[cold]
#[inline(never)]
fn cold() {}

/// `[f(0), f(1)]`: two lanes of arithmetic written so the compiler may pack them.
#[inline(always)]
fn pair<T>(f: impl FnMut(usize) -> T) -> [T; 2] {
    std::array::from_fn(f)
}

pub(crate) mod trig;

pub use trig::{cos, sin, sin_cos};
