//! The contour of a level over a grid of values: marching squares on the cell centres, with
//! linear interpolation along the edges between them (W. E. Lorensen and H. E. Cline, "Marching
//! cubes: a high resolution 3D surface construction algorithm", SIGGRAPH 1987, in its
//! two-dimensional form; the case table and the saddle rule as in P. Bourke, "Polygonising a
//! scalar field", 1994).
//!
//! Choices made here:
//! - A value counts as above the level when it is at least the level, below otherwise; a square
//!   (four neighbouring centres) with a value that is not finite gives no segment, so the
//!   contour stops short of a cell without a value rather than guessing through it.
//! - The ambiguous (saddle) square, whose diagonal corners are on the same side and its
//!   neighbouring ones on the other, is resolved by the average of its four corners taken as the
//!   value at its centre: the diagonal pair on the centre's side is joined through the centre,
//!   and the segments cut off the other two corners.
//! - The contour joins cell centres, so it spans the grid of centres, not the half cells beyond
//!   the outer ones.

/// A straight piece of a contour: its two ends, (x, y).
pub type Segment = [(f64, f64); 2];

/// A grid whose values do not fit its axes.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GridError {
    /// An axis without values.
    #[error("the {axis} axis has no values")]
    EmptyAxis {
        /// Which axis ("x" or "y").
        axis: &'static str,
    },
    /// An axis whose values are not finite and strictly increasing.
    #[error(
        "the {axis} axis must be finite and strictly increasing: value {index} is {value} after {previous}"
    )]
    NotIncreasing {
        /// Which axis ("x" or "y").
        axis: &'static str,
        /// The index of the value out of order.
        index: usize,
        /// The value out of order.
        value: f64,
        /// The value before it.
        previous: f64,
    },
    /// An axis value that is not finite (the first one; later ones are `NotIncreasing`).
    #[error("the {axis} axis must be finite: value 0 is {value}")]
    NotFinite {
        /// Which axis ("x" or "y").
        axis: &'static str,
        /// The value.
        value: f64,
    },
    /// Not as many rows as y values, or a row not as long as the x axis.
    #[error("the grid must be {rows} rows of {columns} cells: {found}")]
    Shape {
        /// The rows expected (one per y value).
        rows: usize,
        /// The cells expected in each row (one per x value).
        columns: usize,
        /// What was found instead.
        found: String,
    },
}

/// Checks that `values` are finite and strictly increasing, and that there is at least one.
pub(super) fn check_axis(axis: &'static str, values: &[f64]) -> Result<(), GridError> {
    let Some(&first) = values.first() else {
        return Err(GridError::EmptyAxis { axis });
    };
    if !first.is_finite() {
        return Err(GridError::NotFinite { axis, value: first });
    }
    for (i, w) in values.windows(2).enumerate() {
        // `!(a < b)` also catches a NaN.
        if !(w[1].is_finite() && w[0] < w[1]) {
            return Err(GridError::NotIncreasing {
                axis,
                index: i + 1,
                value: w[1],
                previous: w[0],
            });
        }
    }
    Ok(())
}

/// Checks that `cells` has one row per value of `y` and one cell per value of `x` in each row.
pub(super) fn check_shape(x: &[f64], rows: usize, cells: &[Vec<f64>]) -> Result<(), GridError> {
    let columns = x.len();
    let found = if cells.len() != rows {
        Some(format!("found {} rows", cells.len()))
    } else {
        cells
            .iter()
            .position(|r| r.len() != columns)
            .map(|i| format!("row {i} has {} cells", cells[i].len()))
    };
    match found {
        Some(found) => Err(GridError::Shape {
            rows,
            columns,
            found,
        }),
        None => Ok(()),
    }
}

/// The segments of the contour at `level` of `cells` (`cells[iy][ix]` the value at
/// (`x[ix]`, `y[iy]`)), by marching squares on the cell centres (see the module's choices).
/// Axes that are empty, not finite or not strictly increasing, and a grid whose shape is not
/// `y.len()` rows of `x.len()` cells, are refused. A grid of one row or one column has no
/// square and gives no segment (see [`row_crossings`] for one row).
pub fn contour_segments(
    x: &[f64],
    y: &[f64],
    cells: &[Vec<f64>],
    level: f64,
) -> Result<Vec<Segment>, GridError> {
    check_axis("x", x)?;
    check_axis("y", y)?;
    check_shape(x, y.len(), cells)?;
    let mut out = Vec::new();
    for iy in 0..y.len().saturating_sub(1) {
        for ix in 0..x.len().saturating_sub(1) {
            // Corners counter-clockwise from the lower left: (x, y, value).
            let corners = [
                (x[ix], y[iy], cells[iy][ix]),
                (x[ix + 1], y[iy], cells[iy][ix + 1]),
                (x[ix + 1], y[iy + 1], cells[iy + 1][ix + 1]),
                (x[ix], y[iy + 1], cells[iy + 1][ix]),
            ];
            square_segments(&corners, level, &mut out);
        }
    }
    Ok(out)
}

/// The contour's segments through one square, its `corners` (x, y, value) counter-clockwise
/// from the lower left, pushed onto `out`.
fn square_segments(corners: &[(f64, f64, f64); 4], level: f64, out: &mut Vec<Segment>) {
    if corners.iter().any(|c| !c.2.is_finite()) || !level.is_finite() {
        return;
    }
    let above = corners.map(|c| c.2 >= level);
    // Edge k joins corner k to corner k + 1 (bottom, right, top, left); where it crosses.
    let crossing = |k: usize| -> Option<(f64, f64)> {
        let (a, b) = (corners[k], corners[(k + 1) % 4]);
        if above[k] == above[(k + 1) % 4] {
            return None;
        }
        let t = (level - a.2) / (b.2 - a.2);
        Some((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)))
    };
    let cuts: Vec<(usize, (f64, f64))> =
        (0..4).filter_map(|k| crossing(k).map(|p| (k, p))).collect();
    match cuts.as_slice() {
        [(_, p), (_, q)] => out.push([*p, *q]),
        [e0, e1, e2, e3] => {
            // A saddle: corners 0 and 2 on one side, 1 and 3 on the other.
            let centre = corners.iter().map(|c| c.2).sum::<f64>() / 4.0;
            if (centre >= level) == above[0] {
                // 0 and 2 joined through the centre: cut off corner 1 (edges 0, 1) and corner 3
                // (edges 2, 3).
                out.push([e0.1, e1.1]);
                out.push([e2.1, e3.1]);
            } else {
                // 1 and 3 joined: cut off corner 0 (edges 3, 0) and corner 2 (edges 1, 2).
                out.push([e3.1, e0.1]);
                out.push([e1.1, e2.1]);
            }
        }
        _ => {}
    }
}

/// Where one row of values crosses `level`: the x of each crossing, linearly interpolated
/// between neighbouring values (at least the level counts as above, as in
/// [`contour_segments`]); a pair with a value that is not finite gives none. `x` and `row`
/// are paired up to the shorter.
pub fn row_crossings(x: &[f64], row: &[f64], level: f64) -> Vec<f64> {
    let n = x.len().min(row.len());
    (1..n)
        .filter_map(|i| {
            let (a, b) = (row[i - 1], row[i]);
            let usable = a.is_finite() && b.is_finite() && level.is_finite();
            (usable && (a >= level) != (b >= level)).then(|| {
                let t = (level - a) / (b - a);
                x[i - 1] + t * (x[i] - x[i - 1])
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axis(n: usize, from: f64, step: f64) -> Vec<f64> {
        (0..n).map(|i| from + step * i as f64).collect()
    }

    fn grid(x: &[f64], y: &[f64], f: impl Fn(f64, f64) -> f64) -> Vec<Vec<f64>> {
        y.iter()
            .map(|&yv| x.iter().map(|&xv| f(xv, yv)).collect())
            .collect()
    }

    fn length(segments: &[Segment]) -> f64 {
        segments
            .iter()
            .map(|[p, q]| (q.0 - p.0).hypot(q.1 - p.1))
            .sum()
    }

    #[test]
    fn a_plane_gives_the_straight_line_at_the_level() {
        let (x, y) = (axis(11, 0.0, 1.0), axis(6, 0.0, 1.0));
        let cells = grid(&x, &y, |x, _| x);
        let segs = contour_segments(&x, &y, &cells, 3.3).unwrap();
        assert_eq!(segs.len(), 5);
        for p in segs.iter().flatten() {
            assert!((p.0 - 3.3).abs() < 1e-12, "{p:?}");
        }
        assert!((length(&segs) - 5.0).abs() < 1e-12);
    }

    #[test]
    fn a_cone_gives_a_closed_ring_at_the_radius() {
        let x = axis(41, -2.0, 0.1);
        let cells = grid(&x, &x, f64::hypot);
        // A radius through no node (1.0 would pass through (0.6, 0.8), where a node on the level
        // ends four segments).
        let r = 1.03;
        let segs = contour_segments(&x, &x, &cells, r).unwrap();
        for p in segs.iter().flatten() {
            // Linear interpolation of the cone along an edge of 0.1: within 0.005 of the radius.
            assert!((p.0.hypot(p.1) - r).abs() < 5e-3, "{p:?}");
        }
        // Closed: every end is the end of exactly two segments (ends in units of 1e-9).
        let mut ends = std::collections::HashMap::new();
        for p in segs.iter().flatten() {
            let key = ((p.0 * 1e9).round() as i64, (p.1 * 1e9).round() as i64);
            *ends.entry(key).or_insert(0) += 1;
        }
        assert!(ends.values().all(|&n| n == 2), "{ends:?}");
        let circumference = 2.0 * std::f64::consts::PI * r;
        assert!((length(&segs) - circumference).abs() < 0.01 * circumference);
    }

    #[test]
    fn a_grid_all_above_or_all_below_gives_no_segment() {
        let (x, y) = (axis(5, 0.0, 1.0), axis(4, 0.0, 1.0));
        let cells = grid(&x, &y, |x, y| x + y);
        assert!(contour_segments(&x, &y, &cells, -0.5).unwrap().is_empty());
        assert!(contour_segments(&x, &y, &cells, 7.5).unwrap().is_empty());
        assert!(row_crossings(&x, &cells[0], 9.0).is_empty());
    }

    #[test]
    fn no_segment_passes_through_a_cell_without_a_value() {
        let (x, y) = (axis(8, 0.0, 1.0), axis(6, 0.0, 1.0));
        let mut cells = grid(&x, &y, |x, _| x);
        cells[2][3] = f64::NAN;
        let segs = contour_segments(&x, &y, &cells, 3.5).unwrap();
        // The squares around (3, 2) are skipped: the line misses y in (1, 3).
        assert!((length(&segs) - 3.0).abs() < 1e-12, "{segs:?}");
        assert!(
            segs.iter()
                .all(|[p, q]| p.1.max(q.1) <= 1.0 || p.1.min(q.1) >= 3.0)
        );
        cells[2][3] = f64::INFINITY;
        assert_eq!(contour_segments(&x, &y, &cells, 3.5).unwrap().len(), 3);
    }

    #[test]
    fn a_saddle_is_resolved_by_the_centre_average() {
        let (x, y) = ([0.0, 1.0], [0.0, 1.0]);
        // Corners (0, 0) and (1, 1) high, the others low; centre average 0.5.
        let cells = vec![vec![1.0, 0.0], vec![0.0, 1.0]];
        let near = |segs: &[Segment], corner: (f64, f64)| {
            segs.iter().any(|[p, q]| {
                let mid = (0.5 * (p.0 + q.0), 0.5 * (p.1 + q.1));
                (mid.0 - corner.0).hypot(mid.1 - corner.1) < 0.5
            })
        };
        // Level 0.4: the centre is high, the high corners are joined, the low ones cut off.
        let segs = contour_segments(&x, &y, &cells, 0.4).unwrap();
        assert_eq!(segs.len(), 2);
        assert!(
            near(&segs, (1.0, 0.0)) && near(&segs, (0.0, 1.0)),
            "{segs:?}"
        );
        // Level 0.6: the centre is low, the low corners are joined, the high ones cut off.
        let segs = contour_segments(&x, &y, &cells, 0.6).unwrap();
        assert_eq!(segs.len(), 2);
        assert!(
            near(&segs, (0.0, 0.0)) && near(&segs, (1.0, 1.0)),
            "{segs:?}"
        );
    }

    #[test]
    fn one_row_crosses_where_its_values_pass_the_level() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0];
        let row = [0.0, 2.0, f64::NAN, 4.0, 0.0];
        let c = row_crossings(&x, &row, 1.0);
        assert_eq!(c.len(), 2, "{c:?}");
        assert!(
            (c[0] - 0.5).abs() < 1e-12 && (c[1] - 3.75).abs() < 1e-12,
            "{c:?}"
        );
    }

    #[test]
    fn axes_and_shapes_that_do_not_fit_are_refused() {
        let cells = vec![vec![0.0, 1.0], vec![1.0, 2.0]];
        let e = contour_segments(&[0.0, 0.0], &[0.0, 1.0], &cells, 0.5).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the x axis must be finite and strictly increasing: value 1 is 0 after 0"
        );
        let e = contour_segments(&[0.0, 1.0], &[f64::NAN, 1.0], &cells, 0.5).unwrap_err();
        assert!(matches!(e, GridError::NotFinite { axis: "y", .. }), "{e}");
        let e = contour_segments(&[0.0, 1.0, 2.0], &[0.0, 1.0], &cells, 0.5).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the grid must be 2 rows of 3 cells: row 0 has 2 cells"
        );
        let e = contour_segments(&[0.0, 1.0], &[0.0], &cells, 0.5).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the grid must be 1 rows of 2 cells: found 2 rows"
        );
        let e = contour_segments(&[], &[0.0], &[], 0.5).unwrap_err();
        assert_eq!(e, GridError::EmptyAxis { axis: "x" });
    }
}
