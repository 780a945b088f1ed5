//! The unit tests of `sepval_common::model::interference`.

#![allow(clippy::float_cmp)]

use sepval_common::model::interference::*;

#[test]
fn one_at_carriage_zero_at_the_end() {
    let d = InterferenceDecay::new(0.6, 9.144);
    assert!((d.factor(0.0) - 1.0).abs() < 1e-15);
    assert_eq!(d.factor(9.144), 0.0);
    assert_eq!(d.factor(20.0), 0.0);
    let s: f64 = 1.3;
    let e_end = (-9.144f64 / 0.6).exp();
    let expected = ((-s / 0.6).exp() - e_end) / (1.0 - e_end);
    assert!((d.factor(s) - expected).abs() < 1e-15);
}
