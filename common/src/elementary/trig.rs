//! sin and cos: reduction by pi/2 (four-part Cody-Waite in double-double for |x| <= 2^20,
//! Payne and Hanek's reduction with 1280 bits of 2/pi above) and fdlibm's kernels on
//! [-pi/4, pi/4] (the sources and accuracy are in the parent module's documentation).

use super::*;

/// pi/2 in four parts, the first three of 33 bits (fdlibm's `pio2_1`, `pio2_2`, `pio2_3`), so
/// that n times each is exact for |n| < 2^20.
const PIO2_1: f64 = 1.570_796_326_734_125_6;
const PIO2_2: f64 = 6.077_100_506_303_966e-11;
const PIO2_3: f64 = 2.022_266_248_711_166_5e-21;
const PIO2_4: f64 = 8.478_427_660_368_9e-32;
/// Above this |x| the reduction is Payne and Hanek's.
pub const MEDIUM_MAX: f64 = 1_048_576.0; // 2^20

/// fdlibm `k_sin.c`: sin(x) ~ x + S1 x^3 + ... + S6 x^13 on [-pi/4, pi/4].
const SIN: [f64; 6] = [
    -1.666_666_666_666_663_2e-1,
    8.333_333_333_322_49e-3,
    -1.984_126_982_985_795e-4,
    2.755_731_370_707_006_8e-6,
    -2.505_076_025_340_686_3e-8,
    1.589_690_995_211_55e-10,
];
/// fdlibm `k_cos.c`: cos(x) ~ 1 - x^2/2 + C1 x^4 + ... + C6 x^14 on [-pi/4, pi/4].
const COS: [f64; 6] = [
    4.166_666_666_666_66e-2,
    -1.388_888_888_887_411e-3,
    2.480_158_728_947_673e-5,
    -2.755_731_435_139_066_3e-7,
    2.087_572_321_298_175e-9,
    -1.135_964_755_778_819_5e-11,
];

/// (sin x, cos x) (each with an error below 1 ulp; NaN for infinite or NaN x).
///
/// x = n pi/2 + r with |r| <= pi/4 (r as a double-double), then fdlibm's kernels for sin r and
/// cos r, swapped and negated by n mod 4.
#[inline(always)]
pub fn sin_cos<R: Real>(x: R) -> (R, R) {
    let (n_shifted, r, r_lo) = reduce_pio2(x);
    let sin_r = kernel_sin(r, r_lo);
    let cos_r = kernel_cos(r, r_lo);
    let quadrant = n_shifted.to_bits().and(Bits::splat(3));
    let swap = R::nonzero(quadrant.and(Bits::splat(1)));
    let sin_v = R::select(swap, cos_r, sin_r);
    let cos_v = R::select(swap, sin_r, cos_r);
    // Quadrants 2, 3 negate sin; quadrants 1, 2 negate cos.
    let sin_sign = quadrant.and(Bits::splat(2)).shl(62);
    let cos_sign = quadrant
        .wrapping_add(Bits::splat(1))
        .and(Bits::splat(2))
        .shl(62);
    let sin = R::from_bits(sin_v.to_bits().xor(sin_sign));
    let cos = R::from_bits(cos_v.to_bits().xor(cos_sign));
    // sin(-0) = -0.
    (R::select(x.eq(c(0.0)), x, sin), cos)
}

/// Sine (see [`sin_cos`]).
#[inline(always)]
pub fn sin<R: Real>(x: R) -> R {
    sin_cos(x).0
}

/// Cosine (see [`sin_cos`]).
#[inline(always)]
pub fn cos<R: Real>(x: R) -> R {
    sin_cos(x).1
}

/// x = n pi/2 + (r + r_lo), |r| <= pi/4 (a little more when x n is rounded across a half),
/// returned as (1.5 * 2^52 + n, r, r_lo): n mod 4 in the low bits of the first.
#[inline(always)]
fn reduce_pio2<R: Real>(x: R) -> (R, R, R) {
    let n_shifted = x.mul_add(c(FRAC_2_PI), c(SHIFT));
    let n = n_shifted - c(SHIFT);
    // Cody and Waite: x - n P1 is exact (P1 has 33 bits, |n| < 2^20, and the difference is a
    // multiple of x's last bit no larger than x); n P2 and n P3 are exact and subtracted in
    // double-double; n P4 is below 2^-80 |r| where |r| is smallest.
    let r1 = (-n).mul_add(c(PIO2_1), x);
    let (h, l) = two_sum(r1, -(n * c(PIO2_2)));
    let (h, l2) = two_sum(h, -(n * c(PIO2_3)));
    let l = (-n).mul_add(c(PIO2_4), l + l2);
    let (r, r_lo) = fast_two_sum(h, l);
    let large = x.abs().gt(c(MEDIUM_MAX));
    if !large.any() {
        return (n_shifted, r, r_lo);
    }
    reduce_pio2_large_lanes(x, large, (n_shifted, r, r_lo))
}

/// The lanes of `x` in `large` reduced by [`reduce_pio2_large`], the others as given.
#[cold]
#[inline(never)]
fn reduce_pio2_large_lanes<R: Real>(x: R, large: R::Mask, medium: (R, R, R)) -> (R, R, R) {
    let mut r = x.to_array();
    let mut r_lo = x.to_array();
    let mut lane = 0;
    let n_shifted = x.map(|v| {
        let (n_shifted, hi, lo) = reduce_pio2_large(v);
        r.as_mut()[lane] = hi;
        r_lo.as_mut()[lane] = lo;
        lane += 1;
        n_shifted
    });
    (
        R::select(large, n_shifted, medium.0),
        R::select(large, R::from_array(r), medium.1),
        R::select(large, R::from_array(r_lo), medium.2),
    )
}

/// 2/pi: its bits after the binary point, 1 to 1280 (most significant first).
const TWO_OVER_PI_BITS: [u64; 20] = [
    0xa2f9_836e_4e44_1529,
    0xfc27_57d1_f534_ddc0,
    0xdb62_9599_3c43_9041,
    0xfe51_63ab_debb_c561,
    0xb724_6e3a_424d_d2e0,
    0x0649_2eea_09d1_921c,
    0xfe1d_eb1c_b129_a73e,
    0xe882_35f5_2ebb_4484,
    0xe99c_7026_b45f_7e41,
    0x3991_d639_8353_39f4,
    0x9c84_5f8b_bdf9_283b,
    0x1ff8_97ff_de05_980f,
    0xef2f_118b_5a0a_6d1f,
    0x6d36_7ecf_27cb_09b7,
    0x4f46_3f66_9e5f_ea2d,
    0x7527_bac7_ebe5_f17b,
    0x3d07_39f7_8a52_92ea,
    0x6bfb_5fb1_1f8d_5d08,
    0x5603_3046_fc7b_6bab,
    0xf0cf_bc20_9af4_361d,
];

/// Payne and Hanek's reduction of a finite x with |x| > 2^20, in integer arithmetic (exact up
/// to the 192 bits of 2/pi taken): (1.5 * 2^52 + (n mod 4), r, r_lo) as [`reduce_pio2`];
/// NaN for an infinite or NaN x, and a zero r for |x| <= 2^20 (not used there).
fn reduce_pio2_large(x: f64) -> (f64, f64, f64) {
    if !x.is_finite() {
        return (SHIFT, f64::NAN, f64::NAN);
    }
    if x.abs() <= MEDIUM_MAX {
        return (SHIFT, 0.0, 0.0);
    }
    let bits = x.to_bits();
    // x = m 2^e, m an integer below 2^53 (x is normal here).
    let m = (bits & ((1 << 52) - 1)) | (1 << 52);
    let e = ((bits >> 52) & 0x7ff) as i64 - 1075;
    // x 2/pi = sum over the bits b_k of 2/pi of m b_k 2^(e - k): those with k <= e - 2 are
    // multiples of 4 and are dropped. The 192 bits from k0 = max(1, e - 1) on form the integer
    // w, and x 2/pi mod 4 = m w 2^-shift (mod 4), shift = k0 + 191 - e, in [190, 224].
    let k0 = (e - 1).max(1);
    let start = (k0 - 1) as usize; // bit index from the most significant bit of the table
    let (word, offset) = (start / 64, (start % 64) as u32);
    let table_word = |i: usize| -> u64 {
        let hi = TWO_OVER_PI_BITS[word + i] << offset;
        let lo = if offset == 0 {
            0
        } else {
            TWO_OVER_PI_BITS[word + i + 1] >> (64 - offset)
        };
        hi | lo
    };
    let w = [table_word(2), table_word(1), table_word(0)]; // least significant first
    // p = m w, 256 bits, least significant word first.
    let mut p = [0u64; 4];
    let mut carry: u128 = 0;
    for i in 0..3 {
        let t = m as u128 * w[i] as u128 + carry;
        p[i] = t as u64;
        carry = t >> 64;
    }
    p[3] = carry as u64;
    let shift = (k0 + 191 - e) as usize;
    // Bits [pos, pos + 128) of p.
    let bits_at = |pos: usize| -> u128 {
        let (i, o) = (pos / 64, (pos % 64) as u32);
        let word_at = |j: usize| -> u64 {
            let lo = p.get(j).copied().unwrap_or(0) >> o;
            let hi = if o == 0 {
                0
            } else {
                p.get(j + 1).copied().unwrap_or(0) << (64 - o)
            };
            lo | hi
        };
        (word_at(i + 1) as u128) << 64 | word_at(i) as u128
    };
    let quarter_turns = (bits_at(shift) & 3) as u64;
    // The fraction in [0, 1) as a 128-bit fixed-point number; rounded to the nearest quarter
    // turn, it becomes the signed fraction f in [-1/2, 1/2).
    let fraction = bits_at(shift - 128);
    let n = (quarter_turns + (fraction >> 127) as u64) & 3;
    let f = fraction as i128;
    // f 2^-128 as a double-double, times pi/2.
    let f_hi = f as f64;
    let f_lo = f.wrapping_sub(f_hi as i128) as f64;
    let scale = f64::from_bits(0x37f0_0000_0000_0000); // 2^-128
    let (f_hi, f_lo) = (f_hi * scale, f_lo * scale);
    let r = f_hi * FRAC_PI_2;
    let r_lo = f_hi.mul_add(FRAC_PI_2, -r) + f_hi.mul_add(PIO2_LO, f_lo * FRAC_PI_2);
    let (r, r_lo) = fast_two_sum(r, r_lo);
    if x < 0.0 {
        (SHIFT + ((4 - n) & 3) as f64, -r, -r_lo)
    } else {
        (SHIFT + n as f64, r, r_lo)
    }
}

/// sin(x + y) for |x| <= pi/4, |y| <= ulp(x) (fdlibm `k_sin.c`).
#[inline(always)]
fn kernel_sin<R: Real>(x: R, y: R) -> R {
    let z = x * x;
    let w = z * z;
    let r = z.mul_add(z.mul_add(c(SIN[3]), c(SIN[2])), c(SIN[1]))
        + z * w * z.mul_add(c(SIN[5]), c(SIN[4]));
    let v = z * x;
    x - ((z * (c::<R>(0.5) * y - v * r) - y) - v * c(SIN[0]))
}

/// cos(x + y) for |x| <= pi/4, |y| <= ulp(x) (fdlibm `k_cos.c`, as revised in FreeBSD).
#[inline(always)]
fn kernel_cos<R: Real>(x: R, y: R) -> R {
    let z = x * x;
    let w = z * z;
    let r = z * z.mul_add(z.mul_add(c(COS[2]), c(COS[1])), c(COS[0]))
        + w * w * z.mul_add(z.mul_add(c(COS[5]), c(COS[4])), c(COS[3]));
    let hz = c::<R>(0.5) * z;
    let w = c::<R>(1.0) - hz;
    w + (((c::<R>(1.0) - w) - hz) + (z * r - x * y))
}
