//! The unit tests of `sepval_common::frames`.

#![allow(clippy::float_cmp)]

use nalgebra::Matrix3;
use sepval_common::frames::*;

#[test]
fn wrap_maps_into_the_half_open_interval() {
    assert_eq!(wrap_deg(180.0), 180.0);
    assert_eq!(wrap_deg(-180.0), 180.0);
    assert_eq!(wrap_deg(190.0), -170.0);
    assert_eq!(wrap_deg(-190.0), 170.0);
    assert_eq!(wrap_deg(540.0), 180.0);
    assert_eq!(wrap_deg(-540.0), 180.0);
    assert_eq!(wrap_deg(12.5), 12.5);
}

#[test]
fn euler_round_trip_through_the_quaternion() {
    for &(r, p, y) in &[
        (10.0, 20.0, 30.0),
        (-170.0, -80.0, 179.0),
        (0.0, 45.0, -120.0),
    ] {
        let q =
            quaternion_from_euler_321(f64::to_radians(r), f64::to_radians(p), f64::to_radians(y));
        let e = euler_321_deg(&dcm_from_quaternion(q));
        assert!((e[0] - r).abs() < 1e-9 && (e[1] - p).abs() < 1e-9 && (e[2] - y).abs() < 1e-9);
    }
}

#[test]
fn dcm_of_a_scaled_quaternion_is_the_same_rotation() {
    let q = quaternion_from_euler_321(0.3, -0.2, 1.1);
    let c1 = dcm_from_quaternion(q);
    let c2 = dcm_from_quaternion(q.map(|x| 1.7 * x));
    assert!((c1 - c2).abs().max() < 1e-15);
    assert!((c1 * c1.transpose() - Matrix3::identity()).abs().max() < 1e-15);
}
