//! A score over a grid of conditions as a map (for example the separation of rival models over
//! two axes of the flight condition), with the best cell marked.

use std::path::Path;

use plotters::prelude::*;

use super::kit::{DrawResult, Root, draw_mesh, fmt_tick, plottable, render, text};
use super::{FigureError, FigureInput};

/// One axis of a condition map: its label and its values (increasing).
#[derive(Debug, Clone, Copy)]
pub struct MapAxis<'a> {
    /// The label, with the unit.
    pub label: &'a str,
    /// The values.
    pub values: &'a [f64],
}

/// The colour of a cell without a value.
pub(super) const NO_VALUE_GREY: RGBColor = RGBColor(170, 170, 170);

/// The sequential colour of `f` in \[0, 1\] (viridis at five stops); grey when not finite.
fn sequential(f: f64) -> RGBColor {
    const STOPS: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    if !f.is_finite() {
        return NO_VALUE_GREY;
    }
    let s = f.clamp(0.0, 1.0) * 4.0;
    let k = (s.floor() as usize).min(3);
    let g = s - k as f64;
    let mix = |i: usize| (STOPS[k][i] + g * (STOPS[k + 1][i] - STOPS[k][i])).round() as u8;
    RGBColor(mix(0), mix(1), mix(2))
}

/// The cell edges around `values`: midway between neighbours, half a step beyond the ends (a
/// single value gets a cell of width 1, or 10 % of the value).
pub(super) fn edges(values: &[f64]) -> Vec<f64> {
    match values {
        [] => vec![0.0, 1.0],
        [v] => {
            let h = 0.05 * v.abs().max(10.0);
            vec![v - h, v + h]
        }
        _ => {
            let n = values.len();
            let mut e = vec![values[0] - 0.5 * (values[1] - values[0])];
            e.extend(values.windows(2).map(|w| 0.5 * (w[0] + w[1])));
            e.push(values[n - 1] + 0.5 * (values[n - 1] - values[n - 2]));
            e
        }
    }
}

/// Refuses `cells` (`cells[iy][ix]`) that are not one row per value of `y` (one row without
/// it) of one cell per value of `x`.
pub(super) fn check_cells<T>(
    path: &Path,
    x: MapAxis<'_>,
    y: Option<MapAxis<'_>>,
    cells: &[Vec<T>],
) -> Result<(), FigureError> {
    let rows = y.map_or(1, |y| y.values.len());
    if cells.len() != rows || cells.iter().any(|r| r.len() != x.values.len()) {
        return Err(FigureError::Input {
            path: path.to_path_buf(),
            reason: FigureInput::Map {
                rows,
                columns: x.values.len(),
                found: cells.len(),
            },
        });
    }
    Ok(())
}

/// A map of `cells` (`cells[iy][ix]`, one row when `y` is `None`; a value that is not finite is
/// a grey cell) over the values of `x` and `y`, coloured from the smallest value (dark) to the
/// largest (yellow), the value written in each cell when the grid is at most 12 × 12, the cell
/// `best` (ix, iy) outlined, a colour bar labelled `value_label` on the right. 1200 × 900 px.
pub fn condition_map(
    path: &Path,
    title: &str,
    x: MapAxis<'_>,
    y: Option<MapAxis<'_>>,
    cells: &[Vec<f64>],
    value_label: &str,
    best: Option<(usize, usize)>,
) -> Result<(), FigureError> {
    check_cells(path, x, y, cells)?;
    let rows = cells.len();
    let finite: Vec<f64> = cells
        .iter()
        .flatten()
        .copied()
        .filter(|v| plottable(*v))
        .collect();
    let lo = finite.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    // No finite cell: an empty map over a unit scale.
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 1.0) };
    let span = if hi > lo { hi - lo } else { 1.0 };
    let fraction = |v: f64| {
        if plottable(v) {
            (v - lo) / span
        } else {
            f64::NAN
        }
    };
    let (xe, ye) = (
        edges(x.values),
        y.map_or(vec![0.0, 1.0], |y| edges(y.values)),
    );
    let label_cells = x.values.len() <= 12 && rows <= 12;
    render(path, (1200, 900), |root| {
        let (main, bar) = root.split_horizontally(1040);
        let mut chart = ChartBuilder::on(&main)
            .caption(title, text(26.0))
            .margin(18)
            .x_label_area_size(55)
            .y_label_area_size(85)
            .build_cartesian_2d(xe[0]..xe[xe.len() - 1], ye[0]..ye[ye.len() - 1])?;
        draw_mesh(
            &mut chart,
            x.label,
            y.map_or("", |y| y.label),
            fmt_tick,
            fmt_tick,
        )?;
        for (iy, row) in cells.iter().enumerate() {
            for (ix, &v) in row.iter().enumerate() {
                let rect = [(xe[ix], ye[iy]), (xe[ix + 1], ye[iy + 1])];
                chart.draw_series(std::iter::once(Rectangle::new(
                    rect,
                    sequential(fraction(v)).filled(),
                )))?;
                if label_cells && plottable(v) {
                    let centre = (0.5 * (xe[ix] + xe[ix + 1]), 0.5 * (ye[iy] + ye[iy + 1]));
                    let ink = if fraction(v) > 0.6 { BLACK } else { WHITE };
                    let style = text(15.0)
                        .color(&ink)
                        .pos(plotters::style::text_anchor::Pos::new(
                            plotters::style::text_anchor::HPos::Center,
                            plotters::style::text_anchor::VPos::Center,
                        ));
                    chart.draw_series(std::iter::once(Text::new(fmt_tick(v), centre, style)))?;
                }
            }
        }
        if let Some((ix, iy)) = best.filter(|&(ix, iy)| ix < x.values.len() && iy < rows) {
            let rect = [(xe[ix], ye[iy]), (xe[ix + 1], ye[iy + 1])];
            chart.draw_series(std::iter::once(Rectangle::new(rect, RED.stroke_width(4))))?;
        }
        draw_colour_bar(&bar, lo, hi, value_label)
    })
}

/// The colour bar of a map from `lo` to `hi`, labelled `value_label`.
fn draw_colour_bar(bar: &Root<'_>, lo: f64, hi: f64, value_label: &str) -> DrawResult {
    let span = if hi > lo { hi - lo } else { 1.0 };
    let mut scale = ChartBuilder::on(bar)
        .margin_top(80)
        .margin_bottom(75)
        .margin_right(10)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..1.0, lo.min(hi)..if hi > lo { hi } else { lo + 1.0 })?;
    scale
        .configure_mesh()
        .disable_x_mesh()
        .disable_x_axis()
        .y_desc(value_label)
        .axis_desc_style(text(17.0))
        .label_style(text(14.0))
        .y_label_formatter(&|v| fmt_tick(*v))
        .draw()?;
    let steps = 64;
    for i in 0..steps {
        let (a, b) = (i as f64 / steps as f64, (i + 1) as f64 / steps as f64);
        let rect = [(0.0, lo + a * span), (1.0, lo + b * span)];
        scale.draw_series(std::iter::once(Rectangle::new(
            rect,
            sequential(a).filled(),
        )))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::testing::{check_png, dark_pixels};

    #[test]
    fn a_map_and_a_single_row_are_drawn_and_a_bad_shape_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let (xs, ys) = ([0.5, 0.7, 0.9], [0.0, 2.0]);
        let cells = vec![vec![1.0, 2.0, f64::NAN], vec![3.0, 9.5, 4.0]];
        let x = MapAxis {
            label: "Mach [-]",
            values: &xs,
        };
        let y = MapAxis {
            label: "Beta [deg]",
            values: &ys,
        };
        let path = dir.path().join("map.png");
        condition_map(
            &path,
            "Separation",
            x,
            Some(y),
            &cells,
            "margin",
            Some((1, 1)),
        )
        .unwrap();
        check_png(&path, (1200, 900));
        assert!(dark_pixels(&path, 100..800) > 10_000);
        condition_map(&path, "One axis", x, None, &cells[1..], "margin", None).unwrap();
        let e = condition_map(&path, "bad", x, Some(y), &cells[1..], "m", None).unwrap_err();
        assert!(e.to_string().contains("2 rows of 3 cells"), "{e}");
    }
}
