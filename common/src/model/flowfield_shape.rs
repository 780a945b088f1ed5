//! The flowfield's shape g(z) as a table over depth (docs/model.md section 3b, "The shape as a
//! table"): section 1's piecewise-linear interpolation (`correction::interpolate`), held at the
//! ends, for one run and for the lanes of a batch.

use crate::correction::{FieldChangeError, corrected_shape, interpolate};
use crate::lanes::Real;
use crate::scenario::MAX_SHAPE_POINTS;

/// The field's shape g(z) as a table over depth (docs/model.md section 3b, "The shape as a
/// table"): linear between the depths, held at the last value below the last.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeRun {
    points: usize,
    depth_m: [f64; MAX_SHAPE_POINTS],
    g: [f64; MAX_SHAPE_POINTS],
}

impl ShapeRun {
    /// The table of `depth_m` and `g` (checked with the scenario: from 0, increasing).
    pub fn new(depth_m: &[f64], g: &[f64]) -> Self {
        let mut t = ShapeRun {
            points: depth_m.len().min(MAX_SHAPE_POINTS),
            depth_m: [0.0; MAX_SHAPE_POINTS],
            g: [0.0; MAX_SHAPE_POINTS],
        };
        t.depth_m[..t.points].copy_from_slice(&depth_m[..t.points]);
        t.g[..t.points].copy_from_slice(&g[..t.points]);
        t
    }

    /// Its depths scaled by `k` (the effect `interference_decay`: g(z / k)).
    pub fn scale_depth(&mut self, k: f64) {
        for z in &mut self.depth_m[..self.points] {
            *z *= k;
        }
    }

    /// g at the depth `z_m` \[m\]: section 1's piecewise-linear interpolation held at the
    /// ends, so g(0) = 1 above carriage as z+ = max(z, 0) asks (NaN gives NaN).
    #[inline(always)]
    pub fn at(&self, z_m: f64) -> f64 {
        let n = self.points;
        interpolate(&self.depth_m[..n], &self.g[..n], z_m)
    }

    /// g at each lane's depth (held at g(0) above carriage, as z+ = max(z, 0) asks).
    #[inline(always)]
    pub(super) fn lanes<R: Real>(&self, z_m: R) -> R {
        let mut a = z_m.to_array();
        for z in a.as_mut() {
            *z = self.at(*z);
        }
        R::from_array(a)
    }

    /// The table with the correction (`knots_m`, `change`) added ([`corrected_shape`]).
    pub fn corrected(&self, knots_m: &[f64], change: &[f64]) -> Result<ShapeRun, FieldChangeError> {
        let n = self.points;
        let (depth_m, g) = corrected_shape(&self.depth_m[..n], &self.g[..n], knots_m, change)?;
        Ok(ShapeRun::new(&depth_m, &g))
    }
}
