//! The direction-cosine matrix of an RK4 stage's quaternion, for the force evaluation
//! (docs/model.md sections 2 and 9: the stage's attitude is the quaternion scaled to unit
//! length, kept as |q|^2 C_LB and 1/|q|^2).

use super::dot;
use crate::lanes::Real;

/// The direction-cosine matrix C_LB of one stage's quaternion q scaled to unit length (see
/// [`crate::frames`]), kept as `m` = |q|^2 C_LB (row-major, `m[i][j]` = |q|^2 C_LB(i, j)),
/// the products of q without a division, and the scale 1 / |q|^2.
#[derive(Debug, Clone, Copy)]
pub struct Dcm<R = f64> {
    /// |q|^2 C_LB.
    pub m: [[R; 3]; 3],
    /// |q|^2.
    pub n2: R,
    /// 1 / |q|^2.
    pub inv_n2: R,
}

impl<R: Real> Dcm<R> {
    /// |q|^2 C_LB of the quaternion (q0, q1, q2, q3): the diagonal as q0^2 + qi^2 - qj^2 - qk^2,
    /// the rest as 2 (qi qj -+ q0 qk).
    #[inline(always)]
    pub fn from_quaternion(q0: R, q1: R, q2: R, q3: R) -> Dcm<R> {
        let (s00, s11, s22, s33) = (q0 * q0, q1 * q1, q2 * q2, q3 * q3);
        let (a, b) = (s00 + s11, s22 + s33);
        let (c, d) = (s00 - s11, s22 - s33);
        let n2 = a + b;
        // 2 qi qj -+ 2 q0 qk with one rounding after the shared product (doubling is exact).
        let (p12, p13, p23) = ((q1 + q1) * q2, (q1 + q1) * q3, (q2 + q2) * q3);
        let (t01, t02, t03) = (q0 + q0, q0 + q0, q0 + q0);
        Dcm {
            m: [
                [a - b, (-t03).mul_add(q3, p12), t02.mul_add(q2, p13)],
                [t03.mul_add(q3, p12), c + d, (-t01).mul_add(q1, p23)],
                [(-t02).mul_add(q2, p13), t01.mul_add(q1, p23), c - d],
            ],
            n2,
            inv_n2: R::splat(1.0) / n2,
        }
    }

    /// |q|^2 C_BL a: a launch-frame vector in body axes, times |q|^2.
    #[inline(always)]
    pub fn to_body_scaled(&self, a: [R; 3]) -> [R; 3] {
        let m = &self.m;
        [
            dot([m[0][0], m[1][0], m[2][0]], a),
            dot([m[0][1], m[1][1], m[2][1]], a),
            dot([m[0][2], m[1][2], m[2][2]], a),
        ]
    }

    /// base + |q|^2 C_LB b: a body vector in launch-frame axes, times |q|^2, added to base.
    /// The sum runs from b\[0\] to b\[2\], so that b\[2\] (in the force evaluation the normal force,
    /// the last to be known) waits for one multiply-add only.
    #[inline(always)]
    pub fn to_launch_scaled(&self, b: [R; 3], base: [R; 3]) -> [R; 3] {
        let m = &self.m;
        let row =
            |i: usize| m[i][2].mul_add(b[2], m[i][1].mul_add(b[1], m[i][0].mul_add(b[0], base[i])));
        [row(0), row(1), row(2)]
    }
}
