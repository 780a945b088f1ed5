//! The aircraft's flowfield given as tables over position (docs/model.md section 3b, "The field
//! as a table over position"): the upwash, sidewash, dynamic pressure ratio and rolling moment
//! at the grid points of a survey beneath the aircraft (captive-trajectory or grid data, or
//! CFD), interpolated multilinearly at each station.
//!
//! The interpolation is section 1's (Press et al., *Numerical Recipes*, 3rd ed., section 3.6,
//! one axis at a time, the last axis first), held at the grid's edges:
//!
//! ```text
//! t_j  = clamp((p_j - b_j,i) / (b_j,i+1 - b_j,i), 0, 1),   b_j,i <= p_j < b_j,i+1
//! v    = v_lo + t_j (v_hi - v_lo)   along axis j, from the last axis to the first
//! ```
//!
//! The four tables share one grid (checked with the scenario), so a point's cell and weights
//! are found once for all of them, and their four values are kept together at each grid point
//! and interpolated together. An axis the tables do not span is kept as one breakpoint whose
//! weight is 0, so that every grid has three axes (x, y, z) and one code path.

use crate::scenario::FlowfieldSpec;
use crate::table::Variable;

/// The field's tables over position on their one grid.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldGrid {
    /// The breakpoints along x, y and z \[m\] (one, 0, for an axis not spanned).
    breakpoints: [Vec<f64>; 3],
    /// 1 / (b_i+1 - b_i) of each interval of each axis \[1/m\].
    inv_widths: [Vec<f64>; 3],
    /// Each axis's stride in `values` (0 for an axis not spanned: its upper corner is its
    /// lower one).
    strides: [usize; 3],
    /// At each grid point (row-major, z fastest): upwash and sidewash \[deg\], the dynamic
    /// pressure ratio minus 1 and the rolling-moment coefficient (0 where the scenario has no
    /// table of it).
    values: Vec<[f64; 4]>,
}

impl FieldGrid {
    /// The grid of `spec`'s tables over position, when its field is given as tables (the
    /// scenario's checks have made them share one grid).
    pub fn of(spec: &FlowfieldSpec) -> Option<FieldGrid> {
        let tables = spec.position_tables();
        let first = tables.iter().flatten().next()?;
        let mut breakpoints: [Vec<f64>; 3] = [vec![0.0], vec![0.0], vec![0.0]];
        for a in first.axes() {
            let j = match a.variable {
                Variable::X => 0,
                Variable::Y => 1,
                _ => 2,
            };
            breakpoints[j] = a.breakpoints.clone();
        }
        let sizes = breakpoints.each_ref().map(Vec::len);
        let row_major = [sizes[1] * sizes[2], sizes[2], 1];
        let strides = std::array::from_fn(|j| if sizes[j] > 1 { row_major[j] } else { 0 });
        let points = first.values().len();
        let neutral = [0.0, 0.0, 1.0, 0.0];
        let values = (0..points)
            .map(|k| {
                let mut v: [f64; 4] =
                    std::array::from_fn(|j| tables[j].map_or(neutral[j], |t| t.values()[k]));
                // The dynamic pressure ratio is kept as its change, eta - 1.
                v[2] -= 1.0;
                v
            })
            .collect();
        let inv_widths = breakpoints
            .each_ref()
            .map(|b| b.windows(2).map(|w| 1.0 / (w[1] - w[0])).collect());
        Some(FieldGrid {
            breakpoints,
            inv_widths,
            strides,
            values,
        })
    }

    /// The tables at the point `p_m` of L: upwash \[deg\], sidewash \[deg\], eta - 1 and the
    /// rolling-moment coefficient (0 where a table is absent).
    #[inline(always)]
    pub fn at(&self, p_m: [f64; 3]) -> [f64; 4] {
        let mut base = 0;
        let mut t = [0.0; 3];
        for j in 0..3 {
            let b = &self.breakpoints[j];
            if b.len() > 1 {
                let v = p_m[j];
                let i = upper_index(b, v).clamp(1, b.len() - 1) - 1;
                t[j] = ((v - b[i]) * self.inv_widths[j][i]).clamp(0.0, 1.0);
                base += i * self.strides[j];
            }
        }
        let [sx, sy, sz] = self.strides;
        // Along z on the four edges of the cell, then along y, then along x (plain functions,
        // not closures: a closure may be left out of line).
        lerp(
            self.along_y(base, [sy, sz], [t[1], t[2]]),
            self.along_y(base + sx, [sy, sz], [t[1], t[2]]),
            t[0],
        )
    }

    /// How far the point `p_m` (in the tables' coordinates) lies beyond the grid along each
    /// axis \[m\]: 0 inside, and along an axis the tables do not span.
    pub fn beyond(&self, p_m: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|j| match self.range(j) {
            Some([lo, hi]) => (lo - p_m[j]).max(p_m[j] - hi).max(0.0),
            None => 0.0,
        })
    }

    /// The first and last breakpoint along axis `j` (x, y, z), when the tables span it.
    pub fn range(&self, j: usize) -> Option<[f64; 2]> {
        let b = &self.breakpoints[j];
        (b.len() > 1).then(|| [b[0], b[b.len() - 1]])
    }

    /// The values on the cell's face at `at` (strides and fractions along y and z).
    #[inline(always)]
    fn along_y(&self, at: usize, [sy, sz]: [usize; 2], [ty, tz]: [f64; 2]) -> [f64; 4] {
        lerp(self.along_z(at, sz, tz), self.along_z(at + sy, sz, tz), ty)
    }

    /// The values between grid points `at` and `at + sz`, at `t` of the way.
    #[inline(always)]
    fn along_z(&self, at: usize, sz: usize, t: f64) -> [f64; 4] {
        lerp(self.values[at], self.values[at + sz], t)
    }
}

/// The number of breakpoints at or below `v` (`partition_point(|x| x <= v)`, by bisection,
/// without a closure that may be left out of line).
#[inline(always)]
fn upper_index(b: &[f64], v: f64) -> usize {
    let (mut lo, mut hi) = (0, b.len());
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if b[mid] <= v {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    lo
}

/// lo + t (hi - lo), value by value.
#[inline(always)]
fn lerp(lo: [f64; 4], hi: [f64; 4], t: f64) -> [f64; 4] {
    [
        lo[0] + t * (hi[0] - lo[0]),
        lo[1] + t * (hi[1] - lo[1]),
        lo[2] + t * (hi[2] - lo[2]),
        lo[3] + t * (hi[3] - lo[3]),
    ]
}

/// How often a run's samples found the field beyond its grid, and how far (docs/model.md
/// section 3b: the tables are held at the grid's edges, and a run that leaves them is reported
/// as one that leaves a coefficient's table is). Counted at the telemetry samples, from the
/// state: a station, or the CG where the rolling moment is a table, beyond an axis the tables
/// span.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GridExcursions {
    /// Samples looked at.
    pub samples: u64,
    /// Samples with a point beyond the grid.
    pub outside: u64,
    /// The largest distance beyond the grid along x, y and z \[m\] (the tables' coordinates).
    pub worst_m: [f64; 3],
}

impl GridExcursions {
    /// Counts one sample whose points lie `beyond` the grid (from [`FieldGrid::beyond`]).
    pub fn note(&mut self, beyond: [f64; 3]) {
        self.samples += 1;
        if beyond.iter().any(|&b| b > 0.0) {
            self.outside += 1;
        }
        for (w, b) in self.worst_m.iter_mut().zip(beyond) {
            *w = w.max(b);
        }
    }
}
