//! The unit tests of `sepval_common::elementary`:
//! The kernels against the standard library (dense sweeps, error reported), their special
//! values, and the rule of [`sepval_common::lanes`]: each lane of [`F64x4`] gives the scalar bits, in
//! the portable build and in the AVX2/FMA build the propagator dispatches to. The accuracy
//! against a high-precision reference is `common/tests/model/elementary.rs`.

#![allow(clippy::float_cmp)] // these tests check exact values on purpose

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

use sepval_common::elementary::*;
use sepval_common::internals::{ASIN_A_MAX, ATAN_T_MAX, MEDIUM_MAX, exp_dd};
use sepval_common::lanes::F64x4;

/// Distance from `b` in units in the last place of `b`.
pub(super) fn ulps(a: f64, b: f64) -> f64 {
    if a == b || (a.is_nan() && b.is_nan()) {
        return 0.0;
    }
    if !a.is_finite() || !b.is_finite() {
        return f64::INFINITY;
    }
    let exponent_bits = b.abs().to_bits() & 0x7ff0_0000_0000_0000;
    let ulp = if exponent_bits == 0 {
        f64::from_bits(1)
    } else {
        (f64::from_bits(exponent_bits) * f64::EPSILON).max(f64::from_bits(1))
    };
    (a - b).abs() / ulp
}

/// splitmix64.
struct Random(u64);

impl Random {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next() >> 11) as f64 / (1u64 << 53) as f64)
    }
    /// Any double: random bit patterns (NaN, infinities, subnormals included).
    fn any(&mut self) -> f64 {
        f64::from_bits(self.next())
    }
    /// A random magnitude, uniform in its exponent, between 2^lo and 2^hi, random sign.
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let m = 2f64.powf(self.uniform(lo, hi));
        if self.next() & 1 == 0 { m } else { -m }
    }
}

/// Special and boundary values every kernel sees.
fn specials() -> Vec<f64> {
    let mut v = vec![
        0.0,
        f64::from_bits(1),
        f64::from_bits(0x000f_ffff_ffff_ffff),
        f64::MIN_POSITIVE,
        1e-300,
        1e-20,
        2f64.powi(-27),
        0.5,
        ASIN_A_MAX,
        ATAN_T_MAX,
        FRAC_PI_4,
        1.0,
        FRAC_PI_2,
        2.0,
        700.0,
        709.782_712_893_384,
        709.8,
        745.133_219_101_941_1,
        745.2,
        746.0,
        MEDIUM_MAX,
        1e22,
        f64::MAX,
        f64::INFINITY,
        f64::NAN,
    ];
    for x in v.clone() {
        if x.is_finite() && x > 0.0 {
            v.push(f64::from_bits(x.to_bits() + 1));
            v.push(f64::from_bits(x.to_bits() - 1));
        }
    }
    let negatives: Vec<f64> = v.iter().map(|x| -x).collect();
    v.extend(negatives);
    v
}

/// Inputs for a unary kernel: specials, random patterns, log-uniform magnitudes, and uniform
/// values in [lo, hi).
fn inputs(seed: u64, lo: f64, hi: f64) -> Vec<f64> {
    let mut r = Random(seed);
    let mut v = specials();
    for _ in 0..20_000 {
        v.push(r.any());
        v.push(r.log_uniform(-1074.0, 1024.0));
        v.push(r.log_uniform(-30.0, 12.0));
        v.push(r.uniform(lo, hi));
    }
    v
}

fn same_bits(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

/// Every kernel, scalar and in lanes, as plain functions of slices.
macro_rules! kernels {
    ($($name:ident: |$($arg:ident),+| $body:expr;)+) => {
        mod scalar {
            use sepval_common::elementary::*;
            $(pub fn $name($($arg: f64),+) -> f64 { $body })+
        }
        mod lanes4 {
            use sepval_common::elementary::*;
            use sepval_common::lanes::F64x4;
            $(pub fn $name($($arg: F64x4),+) -> F64x4 { $body })+
        }
        #[cfg(target_arch = "x86_64")]
        mod avx2 {
            use sepval_common::elementary::*;
            use sepval_common::lanes::F64x4;
            $(
                #[target_feature(enable = "avx2,fma")]
                pub fn $name($($arg: F64x4),+) -> F64x4 { $body }
            )+
            pub mod scalar {
                use sepval_common::elementary::*;
                $(
                    #[target_feature(enable = "avx2,fma")]
                    pub fn $name($($arg: f64),+) -> f64 { $body }
                )+
            }
        }
    };
}

kernels! {
    exp: |x| sepval_common::elementary::exp(x);
    ln: |x| sepval_common::elementary::ln(x);
    sin: |x| sepval_common::elementary::sin(x);
    cos: |x| sepval_common::elementary::cos(x);
    asin: |x| sepval_common::elementary::asin(x);
    atan2: |y, x| sepval_common::elementary::atan2(y, x);
    pow: |x, y| sepval_common::elementary::pow(x, y);
    flow_alpha: |w, u, a| atan2_asin(w, u, a, a * a, sepval_common::lanes::Real::splat(1.0)).0;
    flow_beta: |w, u, a| atan2_asin(w, u, a, a * a, sepval_common::lanes::Real::splat(1.0)).1;
}

fn avx2_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// Checks that lane i of the lane kernel is the scalar kernel of lane i, with the inputs in
/// every lane position, in the portable and the AVX2/FMA build.
fn check_lanes(
    name: &str,
    args: &[Vec<f64>],
    scalar: &dyn Fn(&[f64]) -> f64,
    lanes: &dyn Fn(&[F64x4]) -> F64x4,
    #[allow(unused_variables)] avx2: &dyn Fn(&[F64x4]) -> F64x4,
    #[allow(unused_variables)] avx2_scalar: &dyn Fn(&[f64]) -> f64,
) {
    let n = args[0].len();
    let avx = avx2_available();
    for start in 0..n {
        // Lane i holds input (start + i * 7919) mod n: every input visits every lane.
        let index = |i: usize| (start + i * 7919) % n;
        let lane_args: Vec<F64x4> = args
            .iter()
            .map(|a| F64x4(std::array::from_fn(|i| a[index(i)])))
            .collect();
        let got = lanes(&lane_args);
        let got_avx = if avx { Some(avx2(&lane_args)) } else { None };
        for i in 0..4 {
            let one: Vec<f64> = args.iter().map(|a| a[index(i)]).collect();
            let expected = scalar(&one);
            assert!(
                same_bits(got.0[i], expected),
                "{name}{one:?}: lane {i} gives {:e}, scalar {:e}",
                got.0[i],
                expected
            );
            if let Some(got_avx) = got_avx {
                assert!(
                    same_bits(got_avx.0[i], expected),
                    "{name}{one:?}: AVX2 lane {i} gives {:e}, scalar {:e}",
                    got_avx.0[i],
                    expected
                );
                let s = avx2_scalar(&one);
                assert!(
                    same_bits(s, expected),
                    "{name}{one:?}: AVX2 scalar gives {s:e}, portable {expected:e}"
                );
            }
        }
    }
}

macro_rules! lanes_test {
    ($test:ident, $name:ident, $inputs:expr, $($i:literal),+) => {
        #[test]
        fn $test() {
            let args: Vec<Vec<f64>> = $inputs;
            check_lanes(
                stringify!($name),
                &args,
                &|a| scalar::$name($(a[$i]),+),
                &|a| lanes4::$name($(a[$i]),+),
                #[cfg(target_arch = "x86_64")]
                // SAFETY: only called when the CPU has AVX2 and FMA.
                &|a| unsafe { avx2::$name($(a[$i]),+) },
                #[cfg(not(target_arch = "x86_64"))]
                &|_| unreachable!(),
                #[cfg(target_arch = "x86_64")]
                // SAFETY: as above.
                &|a| unsafe { avx2::scalar::$name($(a[$i]),+) },
                #[cfg(not(target_arch = "x86_64"))]
                &|_| unreachable!(),
            );
        }
    };
}

/// Pairs for the binary kernels: every special against every special, then random pairs.
fn pairs(seed: u64, lo: f64, hi: f64) -> Vec<Vec<f64>> {
    let s = specials();
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for &x in &s {
        for &y in &s {
            a.push(x);
            b.push(y);
        }
    }
    let mut r = Random(seed);
    for _ in 0..20_000 {
        a.push(r.any());
        b.push(r.any());
        a.push(r.log_uniform(-40.0, 40.0));
        b.push(r.log_uniform(-40.0, 40.0));
        a.push(r.uniform(lo, hi));
        b.push(r.uniform(lo, hi));
    }
    vec![a, b]
}

lanes_test!(exp_lanes_are_scalar, exp, vec![inputs(1, -750.0, 750.0)], 0);
lanes_test!(ln_lanes_are_scalar, ln, vec![inputs(2, 0.0, 4.0)], 0);
lanes_test!(sin_lanes_are_scalar, sin, vec![inputs(3, -10.0, 10.0)], 0);
lanes_test!(cos_lanes_are_scalar, cos, vec![inputs(4, -10.0, 10.0)], 0);
lanes_test!(asin_lanes_are_scalar, asin, vec![inputs(5, -1.0, 1.0)], 0);
lanes_test!(atan2_lanes_are_scalar, atan2, pairs(6, -3.0, 3.0), 0, 1);
lanes_test!(pow_lanes_are_scalar, pow, pairs(7, 0.0, 3.0), 0, 1);
lanes_test!(
    flow_angles_lanes_are_scalar,
    flow_alpha,
    flow_inputs(8),
    0,
    1,
    2
);
lanes_test!(
    flow_sideslip_lanes_are_scalar,
    flow_beta,
    flow_inputs(9),
    0,
    1,
    2
);

/// (w, u, a) for the packed flow angles: mostly the store's range, some beyond it in each
/// argument, some special.
fn flow_inputs(seed: u64) -> Vec<Vec<f64>> {
    let mut r = Random(seed);
    let (mut w, mut u, mut a) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..40_000 {
        let (wi, ui, ai) = match k % 8 {
            0 => (r.any(), r.any(), r.uniform(-1.0, 1.0)),
            1 => (
                r.uniform(-500.0, 500.0),
                r.uniform(-300.0, 300.0),
                r.uniform(-1.0, 1.0),
            ),
            _ => (
                r.uniform(-150.0, 150.0),
                r.uniform(240.0, 320.0),
                r.uniform(-0.6, 0.6),
            ),
        };
        w.push(wi);
        u.push(ui);
        a.push(ai);
    }
    for &x in &specials() {
        w.push(x);
        u.push(1.0);
        a.push(0.1);
        w.push(0.1);
        u.push(x);
        a.push(0.1);
        w.push(0.1);
        u.push(1.0);
        a.push(x);
    }
    vec![w, u, a]
}

/// The largest distance from the standard library over `xs`, with the input where it is.
fn worst_vs_std(
    xs: impl Iterator<Item = f64>,
    ours: impl Fn(f64) -> f64,
    std: impl Fn(f64) -> f64,
) -> (f64, f64) {
    xs.map(|x| (ulps(ours(x), std(x)), x))
        .fold((0.0, f64::NAN), |a, b| if b.0 > a.0 { b } else { a })
}

#[test]
fn kernels_agree_with_the_standard_library() {
    // glibc's functions are within about 1 ulp of the exact value; the bound is the sum.
    let mut r = Random(11);
    let mut report = Vec::new();
    let mut check = |name: &str, (worst, at): (f64, f64), bound: f64| {
        report.push(format!("{name}: {worst:.2} ulp (at {at:e})"));
        assert!(worst <= bound, "{name}: {worst} ulp from std at {at:e}");
    };
    let n = 400_000;
    let sweep = |lo: f64, hi: f64| (0..=n).map(move |i| lo + (hi - lo) * i as f64 / n as f64);
    check(
        "exp [-745, 710]",
        worst_vs_std(sweep(-745.0, 710.0), exp, f64::exp),
        2.0,
    );
    check(
        "exp [-16, 1]",
        worst_vs_std(sweep(-16.0, 1.0), exp, f64::exp),
        2.0,
    );
    check(
        "ln (0, 4]",
        worst_vs_std(sweep(1e-9, 4.0), ln, f64::ln),
        1.5,
    );
    let any: Vec<f64> = (0..n).map(|_| r.any().abs()).collect();
    check(
        "ln (any)",
        worst_vs_std(any.iter().copied(), ln, f64::ln),
        1.5,
    );
    check(
        "sin [-10, 10]",
        worst_vs_std(sweep(-10.0, 10.0), sin, f64::sin),
        2.0,
    );
    check(
        "cos [-10, 10]",
        worst_vs_std(sweep(-10.0, 10.0), cos, f64::cos),
        2.0,
    );
    let big: Vec<f64> = (0..n).map(|_| r.log_uniform(0.0, 1024.0)).collect();
    check(
        "sin (any)",
        worst_vs_std(big.iter().copied(), sin, f64::sin),
        2.0,
    );
    check(
        "cos (any)",
        worst_vs_std(big.iter().copied(), cos, f64::cos),
        2.0,
    );
    check(
        "asin [-1, 1]",
        worst_vs_std(sweep(-1.0, 1.0), asin, f64::asin),
        2.5,
    );
    let angles = sweep(-std::f64::consts::PI, std::f64::consts::PI);
    check(
        "atan2 (circle)",
        worst_vs_std(
            angles,
            |t| atan2(t.sin(), t.cos()),
            |t| t.sin().atan2(t.cos()),
        ),
        2.0,
    );
    let mut worst = (0.0, f64::NAN);
    for _ in 0..n {
        let (y, x) = (r.log_uniform(-60.0, 60.0), r.log_uniform(-60.0, 60.0));
        let e = ulps(atan2(y, x), y.atan2(x));
        if e > worst.0 {
            worst = (e, y / x);
        }
    }
    check("atan2 (any, at y/x)", worst, 2.0);
    check(
        "pow (x^5.25588, x in (0.7, 1])",
        worst_vs_std(sweep(0.7, 1.0), |x| pow(x, 5.25588), |x| x.powf(5.25588)),
        2.0,
    );
    let mut worst = (0.0, f64::NAN);
    for _ in 0..n {
        let (x, y) = (r.log_uniform(-20.0, 20.0).abs(), r.uniform(-30.0, 30.0));
        let e = ulps(pow(x, y), x.powf(y));
        if e > worst.0 {
            worst = (e, x);
        }
    }
    check("pow (any)", worst, 2.0);
    eprintln!(
        "elementary functions against the standard library:\n  {}",
        report.join("\n  ")
    );
}

#[test]
fn special_values() {
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    let is = |a: f64, b: f64| same_bits(a, b);
    // exp
    assert!(is(exp(0.0), 1.0) && is(exp(-0.0), 1.0));
    assert!(is(exp(-inf), 0.0) && is(exp(inf), inf) && exp(nan).is_nan());
    assert!(is(exp(-746.0), 0.0) && is(exp(710.0), inf) && is(exp(709.0), 709f64.exp()));
    assert!(is(exp(-745.1), f64::from_bits(1)) || is(exp(-745.1), f64::from_bits(2)));
    // ln and pow
    assert!(is(ln(1.0), 0.0) && is(ln(0.0), -inf) && is(ln(-0.0), -inf));
    assert!(ln(-1.0).is_nan() && ln(nan).is_nan() && is(ln(inf), inf));
    assert!(is(ln(f64::from_bits(1)), -744.440_071_921_381_2));
    assert!(is(pow(nan, 0.0), 1.0) && is(pow(1.0, nan), 1.0) && is(pow(0.0, 0.0), 1.0));
    assert!(is(pow(0.0, 2.0), 0.0) && is(pow(0.0, -2.0), inf) && is(pow(inf, 2.0), inf));
    assert!(is(pow(inf, -2.0), 0.0) && is(pow(0.5, inf), 0.0) && is(pow(2.0, inf), inf));
    assert!(is(pow(0.5, -inf), inf) && is(pow(2.0, -inf), 0.0) && pow(-2.0, 2.0).is_nan());
    assert!(
        is(pow(2.0, 10.0), 1024.0)
            && is(pow(4.0, 0.5), 2.0)
            && is(pow(2.0, -1074.0), f64::from_bits(1))
    );
    // sin and cos
    assert!(is(sin(0.0), 0.0) && is(sin(-0.0), -0.0) && is(cos(0.0), 1.0) && is(cos(-0.0), 1.0));
    assert!(sin(inf).is_nan() && cos(-inf).is_nan() && sin(nan).is_nan());
    assert!(is(sin(1e-300), 1e-300) && is(sin(-f64::from_bits(1)), -f64::from_bits(1)));
    // asin
    assert!(is(asin(0.0), 0.0) && is(asin(-0.0), -0.0) && is(asin(1.0), FRAC_PI_2));
    assert!(is(asin(-1.0), -FRAC_PI_2) && asin(1.0000000000000002).is_nan() && asin(inf).is_nan());
    // atan2
    let pi = std::f64::consts::PI;
    for (y, x, expected) in [
        (0.0, 0.0, 0.0),
        (-0.0, 0.0, -0.0),
        (0.0, -0.0, pi),
        (-0.0, -0.0, -pi),
        (0.0, -1.0, pi),
        (-0.0, -1.0, -pi),
        (0.0, 1.0, 0.0),
        (-0.0, 1.0, -0.0),
        (1.0, 0.0, FRAC_PI_2),
        (-1.0, -0.0, -FRAC_PI_2),
        (inf, inf, FRAC_PI_4),
        (-inf, inf, -FRAC_PI_4),
        (inf, -inf, 3.0 * FRAC_PI_4),
        (-inf, -inf, -3.0 * FRAC_PI_4),
        (inf, 1.0, FRAC_PI_2),
        (1.0, inf, 0.0),
        (-1.0, -inf, -pi),
        (1.0, 1.0, FRAC_PI_4),
        (-1.0, -1.0, -3.0 * FRAC_PI_4),
        (f64::MAX, f64::MAX, FRAC_PI_4),
        (f64::MAX, -f64::MAX, 3.0 * FRAC_PI_4),
        (f64::from_bits(1), f64::from_bits(1), FRAC_PI_4),
        (1e-320, 1.0, 1e-320),
    ] {
        assert!(
            is(atan2(y, x), expected),
            "atan2({y}, {x}) = {}, not {expected}",
            atan2(y, x)
        );
    }
    assert!(atan2(nan, 1.0).is_nan() && atan2(1.0, nan).is_nan() && atan2(nan, 0.0).is_nan());
    assert!(atan2(0.0, nan).is_nan() && atan2(inf, nan).is_nan());
    // Huge values of similar size (the reduced argument's sum must not overflow).
    assert!(ulps(atan2(1.5e308, 1.7e308), 1.5f64.atan2(1.7)) <= 2.0);
}

#[test]
fn packed_flow_angles_match_atan2_and_asin() {
    let (mut worst_atan, mut worst_asin): (f64, f64) = (0.0, 0.0);
    for i in 0..20_001 {
        // Flow angles up to +-90 deg (the packed range ends at 33.4 deg of incidence and
        // 38.7 deg of sideslip); a sideslip component v of a speed 293 m/s.
        let angle = -FRAC_PI_2 + std::f64::consts::PI * i as f64 / 20_000.0;
        let (w, u) = (293.0 * angle.sin(), 293.0 * angle.cos());
        let v = 293.0 * (0.999_999 * angle).sin();
        let a = v / 293.0;
        let (alpha, beta) = atan2_asin(w, u, a, v * v, 293.0 * 293.0);
        worst_atan = worst_atan.max(ulps(alpha, atan2(w, u)));
        worst_asin = worst_asin.max(ulps(beta, asin(a)));
    }
    assert!(worst_atan <= 2.0, "atan2: worst {worst_atan} ulp");
    assert!(worst_asin <= 2.0, "asin: worst {worst_asin} ulp");
    let (alpha, beta) = atan2_asin(-0.0, 1.0, -0.0, 0.0, 1.0);
    assert!(alpha == 0.0 && alpha.is_sign_negative() && beta.is_sign_negative());
    let (alpha, beta) = atan2_asin(1.0, -1.0, 0.5, 0.25, 1.0);
    assert_eq!((alpha, beta), (atan2(1.0, -1.0), asin(0.5)));
}

#[test]
fn exp_of_a_double_double_carries_the_tail() {
    // e^(x + d) = e^x (1 + d) for a small d: the tail of the argument is not lost.
    for &x in &[-700.5, -1.0, 0.3, 5.0, 709.0] {
        assert!(ulps(exp_dd(x, 0.0), exp(x)) == 0.0);
        let tail = x.abs() * 1e-15;
        let shifted = exp_dd(x, tail);
        assert!(ulps(shifted, exp(x) * (1.0 + tail)) <= 2.0, "{x}");
    }
}
