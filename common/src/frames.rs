//! Frames, attitude and angle conventions.
//!
//! Source: `docs/model.md` section 2.
//! - Launch frame L: x forward, y right, z down, inertial; body frame B: x along the store axis.
//! - Attitude: unit quaternion `q = (q0, q1, q2, q3)`, scalar first, rotating vectors from B to
//!   L (`v_L = q v_B q*`), so `C_LB` below is the Hamilton rotation matrix of `q`.
//! - Euler angles: 3-2-1 sequence, `C_LB = Rz(psi) Ry(theta) Rx(phi)`; phi and psi wrapped to
//!   (-180, 180] deg, theta in [-90, 90] deg.
//!
//! Choice left open by docs/model.md and made here: inside an RK4 stage the quaternion is not unit
//! (it is renormalised only after a full step, section 2). [`dcm_from_quaternion`] returns the
//! rotation of the *normalised* stage quaternion (every entry divided by `|q|^2`), so each
//! stage sees a proper rotation. The difference from the unnormalised formula is O(h^2 |omega|^2)
//! per stage and far below the 1e-6 conformance.

use nalgebra::Matrix3;

use crate::elementary::{asin, atan2, sin_cos};

/// Direction-cosine matrix `C_LB` (body to launch frame) of the rotation described by the
/// quaternion `(q0, q1, q2, q3)`, scalar first. The quaternion need not be of unit length: the
/// matrix is that of `q / |q|`.
#[inline]
pub fn dcm_from_quaternion(q: [f64; 4]) -> Matrix3<f64> {
    let [q0, q1, q2, q3] = q;
    let (s00, s11, s22, s33) = (q0 * q0, q1 * q1, q2 * q2, q3 * q3);
    let inv_n2 = 1.0 / (s00 + s11 + s22 + s33);
    let two = 2.0 * inv_n2;
    let (q0q1, q0q2, q0q3) = (q0 * q1, q0 * q2, q0 * q3);
    let (q1q2, q1q3, q2q3) = (q1 * q2, q1 * q3, q2 * q3);
    Matrix3::new(
        (s00 + s11 - s22 - s33) * inv_n2,
        two * (q1q2 - q0q3),
        two * (q1q3 + q0q2),
        two * (q1q2 + q0q3),
        (s00 - s11 + s22 - s33) * inv_n2,
        two * (q2q3 - q0q1),
        two * (q1q3 - q0q2),
        two * (q2q3 + q0q1),
        (s00 - s11 - s22 + s33) * inv_n2,
    )
}

/// Quaternion kinematics `dq/dt = 0.5 q (x) (0, omega)` (docs/model.md section 2), with
/// `omega = (p, q, r)` in body axes [rad/s].
#[inline]
pub fn quaternion_rate(q: [f64; 4], p: f64, qq: f64, r: f64) -> [f64; 4] {
    let [q0, q1, q2, q3] = q;
    [
        0.5 * (-q1 * p - q2 * qq - q3 * r),
        0.5 * (q0 * p + q2 * r - q3 * qq),
        0.5 * (q0 * qq + q3 * p - q1 * r),
        0.5 * (q0 * r + q1 * qq - q2 * p),
    ]
}

/// 3-2-1 Euler angles `(roll, pitch, yaw)` in degrees of the rotation `C_LB`, roll and yaw in
/// (-180, 180], pitch in [-90, 90] (with sepval's `asin` and `atan2`, docs/model.md section 9).
///
/// Called at every sample from code compiled for any x86-64, where each fused multiply-add of
/// those kernels would be a call to the C library's `fma`; on x86-64 hosts with AVX2 and FMA it
/// runs a copy compiled for them, as `propagator::propagate` does (the same bits).
#[inline]
pub fn euler_321_deg(c_lb: &Matrix3<f64>) -> [f64; 3] {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("fma") && std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports the features `euler_321_deg_fma` is compiled for.
        return unsafe { euler_321_deg_fma(c_lb) };
    }
    euler_321_deg_inline(c_lb)
}

/// [`euler_321_deg`] compiled for x86-64 hosts with AVX2 and FMA.
///
/// # Safety
/// The CPU must support AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn euler_321_deg_fma(c_lb: &Matrix3<f64>) -> [f64; 3] {
    euler_321_deg_inline(c_lb)
}

/// The body of [`euler_321_deg`].
#[inline(always)]
fn euler_321_deg_inline(c_lb: &Matrix3<f64>) -> [f64; 3] {
    let sin_theta = (-c_lb[(2, 0)]).clamp(-1.0, 1.0);
    let theta = asin(sin_theta);
    let phi = atan2(c_lb[(2, 1)], c_lb[(2, 2)]);
    let psi = atan2(c_lb[(1, 0)], c_lb[(0, 0)]);
    [
        wrap_deg(phi.to_degrees()),
        theta.to_degrees(),
        wrap_deg(psi.to_degrees()),
    ]
}

/// Wraps an angle in degrees to (-180, 180].
#[inline]
pub fn wrap_deg(angle_deg: f64) -> f64 {
    if angle_deg > -180.0 && angle_deg <= 180.0 {
        return angle_deg;
    }
    let wrapped = angle_deg - 360.0 * ((angle_deg + 180.0) / 360.0).floor();
    // `wrapped` is in [-180, 180); move the open end to -180 and the closed end to +180.
    if wrapped <= -180.0 {
        wrapped + 360.0
    } else {
        wrapped
    }
}

/// Quaternion `(q0, q1, q2, q3)` of the 3-2-1 Euler angles (radians).
pub fn quaternion_from_euler_321(roll_rad: f64, pitch_rad: f64, yaw_rad: f64) -> [f64; 4] {
    let (sr, cr) = sin_cos(0.5 * roll_rad);
    let (sp, cp) = sin_cos(0.5 * pitch_rad);
    let (sy, cy) = sin_cos(0.5 * yaw_rad);
    [
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    ]
}
