//! Poses between the plain arrays of the public API and parry's types: a 3-2-1 Euler attitude
//! C_LB = Rz(psi) Ry(theta) Rx(phi) (docs/model.md section 2), with active right-handed
//! rotations, so that a body point p_B lies at r + C_LB p_B in the launch frame.

use parry3d_f64::math::{Pose as PPose, Rotation, Vector};

/// C_LB of 3-2-1 Euler angles `[phi, theta, psi]` in degrees.
pub(crate) fn rotation_321_deg(euler_deg: [f64; 3]) -> Rotation {
    let [phi, theta, psi] = euler_deg.map(f64::to_radians);
    Rotation::from_rotation_z(psi)
        * Rotation::from_rotation_y(theta)
        * Rotation::from_rotation_x(phi)
}

/// The pose of the body frame in L: translation `position_m`, rotation C_LB.
pub(crate) fn body_pose(position_m: [f64; 3], euler_deg: [f64; 3]) -> PPose {
    PPose::from_parts(vector(position_m), rotation_321_deg(euler_deg))
}

/// A parry vector of an array.
pub(crate) fn vector(a: [f64; 3]) -> Vector {
    Vector::new(a[0], a[1], a[2])
}

/// An array of a parry vector.
pub(crate) fn array(v: Vector) -> [f64; 3] {
    [v.x, v.y, v.z]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pitch_up_lifts_the_nose_and_yaw_right_turns_it_right() {
        // z is down: a positive pitch puts the nose (body +x) at negative z.
        let nose = rotation_321_deg([0.0, 30.0, 0.0]) * Vector::X;
        assert!((nose.z + 0.5).abs() < 1e-12 && (nose.x - 0.75f64.sqrt()).abs() < 1e-12);
        let nose = rotation_321_deg([0.0, 0.0, 90.0]) * Vector::X;
        assert!((nose.y - 1.0).abs() < 1e-12);
        // Roll right puts the right wing (body +y) down (+z).
        let right = rotation_321_deg([90.0, 0.0, 0.0]) * Vector::Y;
        assert!((right.z - 1.0).abs() < 1e-12);
    }

    #[test]
    fn the_order_is_yaw_then_pitch_then_roll() {
        // C_LB[2][0] = -sin(theta) whatever phi and psi (docs/model.md section 2).
        let c = rotation_321_deg([20.0, 35.0, -50.0]);
        let x_body_in_l = c * Vector::X;
        assert!((x_body_in_l.z + 35f64.to_radians().sin()).abs() < 1e-12);
        // C_LB[1][0] / C_LB[0][0] = tan(psi).
        assert!((x_body_in_l.y.atan2(x_body_in_l.x) + 50f64.to_radians()).abs() < 1e-12);
    }
}
