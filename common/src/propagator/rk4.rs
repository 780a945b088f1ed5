//! One classic RK4 step (docs/model.md section 1) of one run or of one run per SIMD lane, and
//! the derivatives it steps: a run's equations or four runs' with the feet's modes held.
//!
//! Source: `docs/model.md` sections 1 (integrator) and 2 (renormalisation of q after every
//! step, never inside the stages).

use crate::lanes::{F64x4, Real};
use crate::model::{EquationsOfMotion, LaneEquations, STATE_LEN, StateVector};

/// A state derivative with the feet's modes held (one run, or one run per lane of `R`), for
/// [`rk4`]. (A trait with an `#[inline(always)]` method rather than a closure: a closure may be
/// compiled out of line, without the FMA build's target features, and its fused multiply-adds
/// would then be calls to the C library.)
pub(super) trait Derivative<R> {
    /// dx/dt at `x` and time `t`.
    fn at(&self, x: &[R; STATE_LEN], t: R) -> [R; STATE_LEN];
}

/// One run's equations with the feet's modes held (`PLAIN`: the run is
/// [`EquationsOfMotion::plain`], and takes [`EquationsOfMotion::derivative_plain`]).
pub(super) struct Held<'e, 'a, const PLAIN: bool> {
    pub(super) equations: &'e EquationsOfMotion<'a>,
    pub(super) on: [bool; 2],
}

impl<const PLAIN: bool> Derivative<f64> for Held<'_, '_, PLAIN> {
    #[inline(always)]
    fn at(&self, x: &StateVector, t: f64) -> StateVector {
        if PLAIN {
            self.equations.derivative_plain(x, t, self.on)
        } else {
            self.equations.derivative(x, t, self.on)
        }
    }
}

/// Four runs' equations, one per lane, each with its feet's modes held.
pub(super) struct LanesHeld<'e, 'a> {
    pub(super) equations: &'e LaneEquations<'a>,
    pub(super) on: [[bool; 2]; 4],
}

impl Derivative<F64x4> for LanesHeld<'_, '_> {
    #[inline(always)]
    fn at(&self, x: &[F64x4; STATE_LEN], t: F64x4) -> [F64x4; STATE_LEN] {
        self.equations.derivative(x, t, &self.on)
    }
}

/// One classic RK4 step of length `h` from `x` at time `t` of the derivative `f` (one run or
/// one run per lane of `R`), q renormalised (each stage at its own time: t, t + h/2, t + h/2,
/// t + h).
#[inline(always)]
pub(super) fn rk4<R: Real>(
    f: &impl Derivative<R>,
    x: &[R; STATE_LEN],
    t: R,
    h: R,
) -> [R; STATE_LEN] {
    let half = R::splat(0.5) * h;
    let sixth = h / R::splat(6.0);
    let k1 = f.at(x, t);
    let k2 = f.at(&axpy(x, half, &k1), t + half);
    let k3 = f.at(&axpy(x, half, &k2), t + half);
    let k4 = f.at(&axpy(x, h, &k3), t + h);
    let two = R::splat(2.0);
    let mut y = *x;
    for j in 0..STATE_LEN {
        y[j] = sixth.mul_add(two.mul_add(k2[j] + k3[j], k1[j]) + k4[j], x[j]);
    }
    let n2 = y[6].mul_add(y[6], y[7].mul_add(y[7], y[8].mul_add(y[8], y[9] * y[9])));
    let inv_norm = R::splat(1.0) / n2.sqrt();
    for v in &mut y[6..10] {
        *v = *v * inv_norm;
    }
    y
}

/// x + a k, component by component (fused).
#[inline(always)]
fn axpy<R: Real>(x: &[R; STATE_LEN], a: R, k: &[R; STATE_LEN]) -> [R; STATE_LEN] {
    let mut y = *x;
    for j in 0..STATE_LEN {
        y[j] = a.mul_add(k[j], x[j]);
    }
    y
}
