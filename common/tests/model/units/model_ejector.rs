//! The unit tests of `sepval_common::model::ejector`.

#![allow(clippy::float_cmp)]

use sepval_common::model::ejector::*;

#[test]
fn linear_between_points() {
    let c = EjectorCurve::new(&[[0.0, 100.0], [0.1, 50.0], [0.2, 50.0]]);
    assert_eq!(c.force_n(0.0), 100.0);
    assert!((c.force_n(0.05) - 75.0).abs() < 1e-12);
    assert_eq!(c.force_n(0.1), 50.0);
    assert_eq!(c.force_n(0.15), 50.0);
    assert_eq!(c.force_n(0.3), 50.0);
    assert_eq!(c.force_n(-1.0), 100.0);
}
