//! The envelope map (`sepval envelope`): a per-condition value over a grid of flight
//! conditions (for example the probability that the clearance falls below its criterion, or a
//! low percentile of the clearance), coloured so that the safe side shows at a glance, with the
//! criterion's contour over it and the releases flown marked.
//!
//! Choices made here:
//! - The colour scale is anchored at the criterion (`envelope_scale`): the safe side runs from
//!   light green to yellow, the unsafe side from orange to dark red, each side linear in the
//!   value, so the colour changes where the criterion is crossed whatever the range of values.
//! - The contour joins cell centres (marching squares, `contour`); on a one-axis map (one row)
//!   it is a vertical line across the row at each crossing.
//! - A release flown outside the map (or with a coordinate that is not finite) is omitted, not
//!   moved to the edge, and the legend says how many were; on a one-axis map only its x counts
//!   and it is drawn at the row's middle.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::condition_map::{MapAxis, NO_VALUE_GREY, edges};
use super::contour::{
    GridError, Segment, check_axis, check_shape, contour_segments, row_crossings,
};
use super::envelope_scale::{Safety, Scale, criterion_styles, draw_scale_bar};
use super::kit::{
    Chart2d, DrawResult, LegendMark, RING_RADIUS_PX, draw_mesh, fmt_tick, plottable,
    plottable_point, render, ring_style, text, titled_with_legend,
};
use super::{FigureError, FigureInput};
use plotters::coord::types::RangedCoordf64;

/// The colour of the marks of releases flown (blue: on no colour of the scale).
const FLOWN_BLUE: RGBColor = RGBColor(31, 119, 180);

/// The most cells along an axis for the values to be written in them.
const MAX_LABELLED_CELLS: usize = 12;

/// What an envelope map shows.
#[derive(Debug, Clone, Copy)]
pub struct EnvelopeMap<'a> {
    /// The figure's title.
    pub title: &'a str,
    /// The horizontal axis: its label with the unit, its values (finite, increasing).
    pub x: MapAxis<'a>,
    /// The vertical axis, or `None` for a one-axis map (one row).
    pub y: Option<MapAxis<'a>>,
    /// The value at each condition, `cells[iy][ix]`: one row per y value (one row without y),
    /// one value per x value. A value that is not finite is a grey cell.
    pub cells: &'a [Vec<f64>],
    /// The label of the value, with its unit (the colour bar's).
    pub value_label: &'a str,
    /// Which side of the criterion is safe.
    pub safety: Safety,
    /// The level whose contour is drawn: the allowed probability for a probability, the
    /// clearance criterion for a clearance (in the values' unit).
    pub criterion: f64,
    /// The contour's legend entry (for example "allowed probability 0.05").
    pub criterion_label: &'a str,
    /// The conditions of the releases flown, (x, y) in the axes' units.
    pub flown: &'a [(f64, f64)],
}

/// Draws `map` to `path` as a 1200 × 900 px PNG: the cells coloured by `map.safety` (the
/// criterion the boundary between the safe side's greens and the unsafe side's reds, and a
/// colour bar naming both ends), the value written in each cell when the grid is at most
/// 12 × 12, the criterion's contour as a black line, the releases flown as blue rings (those
/// outside the map omitted and counted in the legend), and a legend. Axes that are empty, not
/// finite or not strictly increasing, cells whose shape is not one row per y value (one
/// without) of one value per x value, and a criterion that is not finite are refused with
/// [`FigureError::Input`] before anything is written.
pub fn envelope_map(path: &Path, map: &EnvelopeMap<'_>) -> Result<(), FigureError> {
    let input = |reason: FigureInput| FigureError::Input {
        path: path.to_path_buf(),
        reason,
    };
    let checked = check(map).map_err(|e| input(FigureInput::EnvelopeGrid(e)))?;
    if !plottable(map.criterion) {
        return Err(input(FigureInput::EnvelopeCriterion {
            criterion: map.criterion,
        }));
    }
    let scale = Scale::new(
        checked.cells.iter().flatten().copied(),
        map.criterion,
        map.safety,
    );
    let xe = edges(map.x.values);
    let ye = map.y.map_or(vec![0.0, 1.0], |y| edges(y.values));
    let extent = Extent {
        x: (xe[0], xe[xe.len() - 1]),
        y: (ye[0], ye[ye.len() - 1]),
    };
    let flown = Flown::within(map.flown, &extent, map.y.is_some());
    let contour =
        contour(map, &checked, &extent).map_err(|e| input(FigureInput::EnvelopeGrid(e)))?;
    let entries = legend(map, &checked, &contour, &flown);
    render(path, (1200, 900), |root| {
        let rest = titled_with_legend(root, map.title, &entries)?;
        let (main, bar) = rest.split_horizontally(1040);
        let mut chart = ChartBuilder::on(&main)
            .margin(18)
            .x_label_area_size(55)
            .y_label_area_size(85)
            .build_cartesian_2d(extent.x.0..extent.x.1, extent.y.0..extent.y.1)?;
        match map.y {
            Some(y) => draw_mesh(&mut chart, map.x.label, y.label, fmt_tick, fmt_tick)?,
            None => {
                chart
                    .configure_mesh()
                    .x_desc(map.x.label)
                    .axis_desc_style(text(19.0))
                    .label_style(text(15.0))
                    .x_label_formatter(&|v| fmt_tick(*v))
                    .y_labels(0)
                    .disable_y_mesh()
                    .bold_line_style(RGBColor(210, 210, 210))
                    .axis_style(RGBColor(60, 60, 60))
                    .draw()?;
            }
        }
        draw_cells(&mut chart, &checked.cells, (&xe, &ye), &scale)?;
        for style in criterion_styles() {
            chart.draw_series(
                contour
                    .iter()
                    .map(|&[p, q]| PathElement::new(vec![p, q], style)),
            )?;
        }
        draw_flown(&mut chart, &flown.points)?;
        // The values last, over the contour and the rings, so that each stays readable.
        draw_values(&mut chart, &checked.cells, (&xe, &ye), &scale)?;
        draw_scale_bar(&bar, &scale, map.value_label)
    })
}

/// The map's cells, checked against its axes, with every value that cannot be drawn as NaN.
struct Checked {
    /// `cells[iy][ix]`.
    cells: Vec<Vec<f64>>,
    /// Whether some cell has no value.
    any_missing: bool,
}

/// Checks the axes and the shape of the cells of `map`.
fn check(map: &EnvelopeMap<'_>) -> Result<Checked, GridError> {
    check_axis("x", map.x.values)?;
    if let Some(y) = map.y {
        check_axis("y", y.values)?;
    }
    let rows = map.y.map_or(1, |y| y.values.len());
    check_shape(map.x.values, rows, map.cells)?;
    let cells: Vec<Vec<f64>> = map
        .cells
        .iter()
        .map(|row| {
            row.iter()
                .map(|&v| if plottable(v) { v } else { f64::NAN })
                .collect()
        })
        .collect();
    let any_missing = cells.iter().flatten().any(|v| v.is_nan());
    Ok(Checked { cells, any_missing })
}

/// The criterion's contour on the map: marching squares over a grid of at least 2 × 2; a
/// vertical line across the map at each crossing along a single row, a horizontal one at each
/// crossing along a single column.
fn contour(
    map: &EnvelopeMap<'_>,
    checked: &Checked,
    extent: &Extent,
) -> Result<Vec<Segment>, GridError> {
    let (x, cells, level) = (map.x.values, &checked.cells, map.criterion);
    let y = map.y.map_or(&[0.5][..], |y| y.values);
    Ok(if x.len() >= 2 && y.len() >= 2 {
        contour_segments(x, y, cells, level)?
    } else if y.len() == 1 {
        row_crossings(x, &cells[0], level)
            .into_iter()
            .map(|xc| [(xc, extent.y.0), (xc, extent.y.1)])
            .collect()
    } else {
        let column: Vec<f64> = cells.iter().map(|row| row[0]).collect();
        row_crossings(y, &column, level)
            .into_iter()
            .map(|yc| [(extent.x.0, yc), (extent.x.1, yc)])
            .collect()
    })
}

/// The area the map covers, in the axes' units: (from, to) along x and along y.
struct Extent {
    x: (f64, f64),
    y: (f64, f64),
}

/// The releases flown that are drawn, and how many are not.
struct Flown {
    /// The points drawn, in the chart's coordinates.
    points: Vec<(f64, f64)>,
    /// How many were given in all.
    given: usize,
}

impl Flown {
    /// The points of `flown` inside `extent` (on a one-axis map, when `two_axes` is false, the
    /// x alone decides and the point is drawn at the row's middle).
    fn within(flown: &[(f64, f64)], extent: &Extent, two_axes: bool) -> Self {
        let inside = |v: f64, (a, b): (f64, f64)| (a..=b).contains(&v);
        let points = flown
            .iter()
            .filter_map(|&(x, y)| {
                if two_axes {
                    (plottable_point((x, y)) && inside(x, extent.x) && inside(y, extent.y))
                        .then_some((x, y))
                } else {
                    (plottable(x) && inside(x, extent.x))
                        .then_some((x, 0.5 * (extent.y.0 + extent.y.1)))
                }
            })
            .collect();
        Self {
            points,
            given: flown.len(),
        }
    }
}

/// The legend's entries: the criterion's contour, the releases flown when there are any, grey
/// cells when some cell has no value.
fn legend(
    map: &EnvelopeMap<'_>,
    checked: &Checked,
    contour: &[Segment],
    flown: &Flown,
) -> Vec<(String, LegendMark)> {
    let mut contour_label = map.criterion_label.to_string();
    if contour.is_empty() {
        contour_label.push_str(not_drawn(checked, map.criterion, map.safety));
    }
    let mut entries = vec![(contour_label, LegendMark::Line(BLACK))];
    if flown.given > 0 {
        let omitted = flown.given - flown.points.len();
        let label = if omitted == 0 {
            "releases flown".to_string()
        } else {
            format!("releases flown ({omitted} outside the map, not shown)")
        };
        entries.push((label, LegendMark::Ring(FLOWN_BLUE)));
    }
    if checked.any_missing {
        entries.push(("no value".to_string(), LegendMark::Band(NO_VALUE_GREY)));
    }
    entries
}

/// Why the criterion's contour is not on the map: which side every value is on, or that it is
/// crossed only beside cells without a value.
fn not_drawn(checked: &Checked, criterion: f64, safety: Safety) -> &'static str {
    let values = || checked.cells.iter().flatten().filter(|v| !v.is_nan());
    let (any_below, any_above) = (
        values().any(|&v| v < criterion),
        values().any(|&v| v >= criterion),
    );
    match (any_below, any_above, safety) {
        (false, false, _) => " (no value on the map)",
        (true, true, _) => " (crossed only beside cells without a value)",
        (true, false, Safety::LowIsSafe) | (false, true, Safety::HighIsSafe) => {
            " (not crossed: every value on the safe side)"
        }
        _ => " (not crossed: every value on the unsafe side)",
    }
}

/// Draws the cells coloured by `scale`, their edges `xe` and `ye`.
fn draw_cells(
    chart: &mut Chart2d<'_, '_, RangedCoordf64, RangedCoordf64>,
    cells: &[Vec<f64>],
    (xe, ye): (&[f64], &[f64]),
    scale: &Scale,
) -> DrawResult {
    for (iy, row) in cells.iter().enumerate() {
        chart.draw_series(row.iter().enumerate().map(|(ix, &v)| {
            let rect = [(xe[ix], ye[iy]), (xe[ix + 1], ye[iy + 1])];
            Rectangle::new(rect, scale.colour(v).filled())
        }))?;
    }
    Ok(())
}

/// Writes the value in each cell (edges `xe` and `ye`) when the grid is at most
/// [`MAX_LABELLED_CELLS`] along each axis, black or white as the cell's colour needs.
fn draw_values(
    chart: &mut Chart2d<'_, '_, RangedCoordf64, RangedCoordf64>,
    cells: &[Vec<f64>],
    (xe, ye): (&[f64], &[f64]),
    scale: &Scale,
) -> DrawResult {
    if xe.len() - 1 > MAX_LABELLED_CELLS || cells.len() > MAX_LABELLED_CELLS {
        return Ok(());
    }
    for (iy, row) in cells.iter().enumerate() {
        for (ix, &v) in row.iter().enumerate().filter(|(_, v)| plottable(**v)) {
            let centre = (0.5 * (xe[ix] + xe[ix + 1]), 0.5 * (ye[iy] + ye[iy + 1]));
            let ink = scale.ink(v);
            let style = text(15.0)
                .color(&ink)
                .pos(Pos::new(HPos::Center, VPos::Center));
            chart.draw_series(std::iter::once(Text::new(fmt_cell(v), centre, style)))?;
        }
    }
    Ok(())
}

/// Draws the releases flown as blue rings.
fn draw_flown(
    chart: &mut Chart2d<'_, '_, RangedCoordf64, RangedCoordf64>,
    points: &[(f64, f64)],
) -> DrawResult {
    chart.draw_series(
        points
            .iter()
            .map(|&p| Circle::new(p, RING_RADIUS_PX, ring_style(FLOWN_BLUE))),
    )?;
    Ok(())
}

/// A cell's value with three significant digits (at most six decimals), trailing zeros
/// dropped: 0.0523, 0.05, 25.4, 131.
fn fmt_cell(v: f64) -> String {
    if v.abs() < 1e-12 {
        return "0".to_string();
    }
    if v.abs() >= 1e5 {
        return fmt_tick(v);
    }
    let decimals = (2 - v.abs().log10().floor() as i32).clamp(0, 6) as usize;
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests;
