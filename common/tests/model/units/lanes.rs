//! The unit tests of `sepval_common::lanes`.

#![allow(clippy::float_cmp)]

use sepval_common::lanes::*;

#[test]
fn each_lane_is_the_scalar_operation() {
    let a = F64x4([1.5, -0.0, f64::INFINITY, 3.0e-310]);
    let b = F64x4([0.1, 2.0, -1.0, 7.0]);
    let c = F64x4([-0.0, 1e300, f64::NAN, 1.0]);
    let same = |v: F64x4, f: &dyn Fn(usize) -> f64| {
        for i in 0..4 {
            let s = f(i);
            assert!(
                v.0[i].to_bits() == s.to_bits() || (v.0[i].is_nan() && s.is_nan()),
                "lane {i}: {} vs {s}",
                v.0[i]
            );
        }
    };
    same(a + b, &|i| a.0[i] + b.0[i]);
    same(a - b, &|i| a.0[i] - b.0[i]);
    same(a * b, &|i| a.0[i] * b.0[i]);
    same(a / b, &|i| a.0[i] / b.0[i]);
    same(-a, &|i| -a.0[i]);
    same(a.mul_add(b, c), &|i| a.0[i].mul_add(b.0[i], c.0[i]));
    same(b.sqrt(), &|i| b.0[i].sqrt());
    same(b.copysign(a), &|i| b.0[i].copysign(a.0[i]));
    same(F64x4::select(a.lt(b), a, c), &|i| {
        if a.0[i] < b.0[i] { a.0[i] } else { c.0[i] }
    });
    assert_eq!(a.sign_bit().0, [0, u64::MAX, 0, 0]);
    assert_eq!(c.is_nan().0, [0, 0, u64::MAX, 0]);
    assert!(a.eq(a).any() && !a.eq(c).all());
    assert_eq!(
        a.to_bits().and(U64x4::splat(0xff)).0,
        a.0.map(|v| v.to_bits() & 0xff)
    );
}
