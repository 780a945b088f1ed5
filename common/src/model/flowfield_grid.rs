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
//! are found once for all of them.

use crate::scenario::FlowfieldSpec;
use crate::table::{Table, Variable};

/// The most axes of a field's grid (x, y and z).
const MAX_AXES: usize = 3;

/// The field's tables over position on their one grid, values as the scenario gives them
/// (angles in degrees).
#[derive(Debug, Clone, PartialEq)]
pub struct FieldGrid {
    /// The component of the point (0: x, 1: y, 2: z) each axis reads, in nesting order.
    components: Vec<usize>,
    /// Each axis's breakpoints \[m\].
    breakpoints: Vec<Vec<f64>>,
    /// Each axis's stride in the row-major values.
    strides: Vec<usize>,
    /// Upwash and sidewash \[deg\], dynamic pressure ratio minus 1, rolling-moment coefficient,
    /// at each grid point (row-major); none where the scenario has no table of it.
    values: [Option<Vec<f64>>; 4],
}

/// A point's cell in the grid: the index of its lower corner and each axis's weight of the upper
/// one.
#[derive(Debug, Clone, Copy)]
struct Cell {
    base: usize,
    t: [f64; MAX_AXES],
}

impl FieldGrid {
    /// The grid of `spec`'s tables over position, when its field is given as tables (the
    /// scenario's checks have made them share one grid).
    pub fn of(spec: &FlowfieldSpec) -> Option<FieldGrid> {
        let tables = spec.position_tables();
        let first = tables.iter().flatten().next()?;
        let axes = first.axes();
        let mut strides = vec![1usize; axes.len()];
        for k in (0..axes.len().saturating_sub(1)).rev() {
            strides[k] = strides[k + 1] * axes[k + 1].breakpoints.len();
        }
        let component = |v: Variable| match v {
            Variable::X => 0,
            Variable::Y => 1,
            _ => 2,
        };
        let values = std::array::from_fn(|j| {
            tables[j].map(|t: &Table| {
                let v = t.values();
                // The dynamic pressure ratio is kept as its change, eta - 1.
                if j == 2 {
                    v.iter().map(|eta| eta - 1.0).collect()
                } else {
                    v.to_vec()
                }
            })
        });
        Some(FieldGrid {
            components: axes.iter().map(|a| component(a.variable)).collect(),
            breakpoints: axes.iter().map(|a| a.breakpoints.clone()).collect(),
            strides,
            values,
        })
    }

    /// The cell of the point `p_m` (held at the edges; NaN gives NaN weights).
    #[inline(always)]
    fn cell(&self, p_m: [f64; 3]) -> Cell {
        let mut cell = Cell {
            base: 0,
            t: [0.0; MAX_AXES],
        };
        for (j, (b, &c)) in self.breakpoints.iter().zip(&self.components).enumerate() {
            let v = p_m[c];
            let i = b.partition_point(|&x| x <= v).clamp(1, b.len() - 1) - 1;
            cell.t[j] = ((v - b[i]) / (b[i + 1] - b[i])).clamp(0.0, 1.0);
            cell.base += i * self.strides[j];
        }
        cell
    }

    /// `values` at `cell`, interpolated along the axes from `axis` on (the last axis first).
    fn interpolate(&self, values: &[f64], cell: &Cell, axis: usize, at: usize) -> f64 {
        if axis == self.components.len() {
            return values[at];
        }
        let lo = self.interpolate(values, cell, axis + 1, at);
        let hi = self.interpolate(values, cell, axis + 1, at + self.strides[axis]);
        lo + cell.t[axis] * (hi - lo)
    }

    /// The tables at the point `p_m` of L: upwash \[deg\], sidewash \[deg\], eta - 1 and the
    /// rolling-moment coefficient (0 where a table is absent).
    #[inline(always)]
    pub fn at(&self, p_m: [f64; 3]) -> [f64; 4] {
        let cell = self.cell(p_m);
        self.values.each_ref().map(|v| {
            v.as_deref()
                .map_or(0.0, |v| self.interpolate(v, &cell, 0, cell.base))
        })
    }

    /// The upwash, sidewash and eta - 1 at the point `p_m` (the rolling moment, read at the CG
    /// only, is not interpolated).
    #[inline(always)]
    pub fn angles_at(&self, p_m: [f64; 3]) -> [f64; 3] {
        let cell = self.cell(p_m);
        std::array::from_fn(|j| {
            self.values[j]
                .as_deref()
                .map_or(0.0, |v| self.interpolate(v, &cell, 0, cell.base))
        })
    }
}
