//! The clearance between a store and the aircraft against time (`figures/clearance.png` of
//! `sepval fit --aircraft` and `sepval diagnose --aircraft`): one line per release, the
//! criterion, each release's smallest clearance counted, and the time the ejector holds the
//! store.
//!
//! Choices made here:
//! - The y axis is in millimetres from zero (lower only when a clearance is negative) to the
//!   largest clearance or the criterion, whichever is higher, so the criterion is always in
//!   view.
//! - A clearance rises from millimetres to metres within a second, which squeezes the
//!   criterion and the minima against the axis. When the whole range is more than
//!   `ZOOM_RATIO` times the range that matters (up to the larger of 2.5 times the criterion
//!   and 1.3 times the largest minimum), a second panel below shows that range alone, with
//!   each minimum's value written beside its dot; the lines that leave it are cut at its edge.
//!   A linear zoom rather than a log axis, because a log axis cannot show a clearance of zero
//!   (touching), the one value that matters most.
//! - The time before the latest `free_from_s` of all releases is shaded grey: there the
//!   ejector holds the store and its clearance does not count.
//! - Colours follow release order as in every figure (Tableau 10); the criterion is a darker
//!   red, dashed, and named on the line as well as in the legend.

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::kit::{
    Chart2d, DrawResult, Root, box_mark, colour, draw_dashed, draw_legend, draw_mesh,
    estimate_width, fmt_tick, legend_corner, line_mark, padded_range, padded_range_from_zero,
    plottable, plottable_point, render, segments, text,
};
use super::{FigureError, FigureInput};

/// One release's clearance along time.
#[derive(Debug, Clone, Copy)]
pub struct ClearanceSeries<'a> {
    /// The release's name (the legend label).
    pub label: &'a str,
    /// The sample times \[s\].
    pub t_s: &'a [f64],
    /// The clearance at each time \[m\] (0: touching); a value that is not finite breaks the
    /// line.
    pub clearance_m: &'a [f64],
    /// The time from which the smallest clearance counts \[s\] (before it the ejector holds
    /// the store).
    pub free_from_s: f64,
    /// The time of the smallest clearance counted \[s\].
    pub min_t_s: f64,
    /// The smallest clearance counted \[m\]; not marked when it or its time is not finite.
    pub min_m: f64,
}

/// The figure's size in pixels.
const SIZE_PX: (u32, u32) = (1200, 900);
/// The shade of the time the ejector holds the store.
const HELD_GREY: RGBColor = RGBColor(222, 222, 222);
/// The criterion's colour (darker than the palette's red, so that it is not taken for a
/// release).
const CRITERION_RED: RGBColor = RGBColor(190, 0, 0);
/// The range that matters reaches at least this many times the criterion (which so lies in
/// its lower part)...
const CRITERION_HEADROOM: f64 = 2.5;
/// ... and this many times the largest minimum (so that no dot sits on the top edge).
const MINIMUM_HEADROOM: f64 = 1.3;
/// A panel near the criterion is added when the whole range is more than this many times the
/// range that matters (which would then fill less than a fifth of the one panel).
pub(super) const ZOOM_RATIO: f64 = 5.0;
/// The radius of a minimum's dot, in pixels.
const DOT_RADIUS_PX: i32 = 6;
/// The size of the values written beside the dots and the criterion.
const NOTE_SIZE: f64 = 16.0;

/// Draws the clearance of each release in `series` against time to `path` as a 1200 × 900 px
/// PNG, `title` on top: one coloured line per release with a legend, the criterion
/// `criterion_m` as a dashed red line, each release's counted minimum as a dot, the time
/// before the latest `free_from_s` shaded grey ("held by the ejector"). Clearances are shown
/// in millimetres; when they span far more than the criterion, a second panel shows the range
/// near it, where the minima's values are written (otherwise they are written in the one
/// panel).
///
/// No series, a series whose times and clearances differ in number, a `free_from_s` that is
/// not finite, and a criterion that is negative or not finite are refused with
/// [`FigureError::Input`] before anything is written.
pub fn clearance_figure(
    path: &Path,
    title: &str,
    series: &[ClearanceSeries<'_>],
    criterion_m: f64,
) -> Result<(), FigureError> {
    let layout = Layout::of(series, criterion_m).map_err(|e| FigureError::Input {
        path: path.to_path_buf(),
        reason: FigureInput::Clearance(e),
    })?;
    render(path, SIZE_PX, |root| {
        let (_, body) = root.split_vertically(8);
        let body = body.titled(title, text(26.0))?;
        match layout.near_mm {
            None => {
                let panel = Panel {
                    caption: None,
                    y_mm: layout.whole_mm,
                    legend: true,
                    notes: true,
                };
                draw_panel(&body, &layout, series, &panel)
            }
            Some(near_mm) => {
                let height = body.dim_in_pixel().1;
                let (top, bottom) = body.split_vertically(height / 2);
                let whole = Panel {
                    caption: Some("whole range".to_string()),
                    y_mm: layout.whole_mm,
                    legend: true,
                    notes: false,
                };
                draw_panel(&top, &layout, series, &whole)?;
                let near = Panel {
                    caption: Some("near the criterion".to_string()),
                    y_mm: near_mm,
                    legend: false,
                    notes: true,
                };
                draw_panel(&bottom, &layout, series, &near)
            }
        }
    })
}

/// The ranges of the figure, decided once from the checked input.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Layout {
    /// The time axis \[s\].
    pub(super) x_s: (f64, f64),
    /// The y range showing every clearance and the criterion \[mm\].
    pub(super) whole_mm: (f64, f64),
    /// The y range near the criterion \[mm\], when a second panel is needed.
    pub(super) near_mm: Option<(f64, f64)>,
    /// The criterion \[mm\].
    pub(super) criterion_mm: f64,
    /// The latest time the ejector holds a store \[s\].
    pub(super) held_until_s: f64,
}

/// A clearance figure's series or criterion that cannot be drawn.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ClearanceInput {
    /// No series.
    #[error("no release to draw")]
    NoRelease,
    /// A criterion that is not finite or is negative.
    #[error("the criterion must be finite and not negative, found {criterion_m} m")]
    Criterion {
        /// The criterion \[m\].
        criterion_m: f64,
    },
    /// A release whose clearances are not one per time.
    #[error("release {label:?} has {clearances} clearances for {times} times")]
    Lengths {
        /// The release.
        label: String,
        /// Its clearances.
        clearances: usize,
        /// Its times.
        times: usize,
    },
    /// A release whose free-from time is not finite.
    #[error(
        "release {label:?}: the time from which the clearance counts must be finite, found {free_from_s} s"
    )]
    FreeFrom {
        /// The release.
        label: String,
        /// The time from which its clearance counts \[s\].
        free_from_s: f64,
    },
}

impl Layout {
    /// Checks `series` and `criterion_m` and decides the ranges; what does not fit, in words.
    pub(super) fn of(
        series: &[ClearanceSeries<'_>],
        criterion_m: f64,
    ) -> Result<Self, ClearanceInput> {
        if series.is_empty() {
            return Err(ClearanceInput::NoRelease);
        }
        if !(plottable(criterion_m) && criterion_m >= 0.0) {
            return Err(ClearanceInput::Criterion { criterion_m });
        }
        for s in series {
            if s.t_s.len() != s.clearance_m.len() {
                return Err(ClearanceInput::Lengths {
                    label: s.label.to_string(),
                    clearances: s.clearance_m.len(),
                    times: s.t_s.len(),
                });
            }
            if !plottable(s.free_from_s) {
                return Err(ClearanceInput::FreeFrom {
                    label: s.label.to_string(),
                    free_from_s: s.free_from_s,
                });
            }
        }
        let criterion_mm = 1e3 * criterion_m;
        let x_s = padded_range(series.iter().flat_map(|s| s.t_s.iter().copied()), 0.01);
        let clearances_mm = series.iter().flat_map(|s| {
            s.t_s
                .iter()
                .zip(s.clearance_m)
                .filter(|(t, _)| plottable(**t))
                .map(|(_, c)| 1e3 * c)
        });
        // Zero is among the values so that the axis starts there (or below a negative one).
        let whole_mm = padded_range_from_zero(clearances_mm.chain([criterion_mm, 0.0]), 0.05);
        let largest_min_mm = series
            .iter()
            .filter(|s| plottable_point((s.min_t_s, s.min_m)))
            .map(|s| 1e3 * s.min_m)
            .fold(f64::NEG_INFINITY, f64::max);
        let near_top_mm =
            (CRITERION_HEADROOM * criterion_mm).max(MINIMUM_HEADROOM * largest_min_mm);
        let near_mm = (near_top_mm > 0.0 && whole_mm.1 > ZOOM_RATIO * near_top_mm)
            .then_some((whole_mm.0.min(0.0), near_top_mm));
        let held_until_s = series
            .iter()
            .map(|s| s.free_from_s)
            .fold(f64::NEG_INFINITY, f64::max);
        Ok(Self {
            x_s,
            whole_mm,
            near_mm,
            criterion_mm,
            held_until_s,
        })
    }
}

/// One panel of the figure: its caption, its y range, and what it carries.
struct Panel {
    /// Written above the panel when there are two.
    caption: Option<String>,
    /// The y range \[mm\].
    y_mm: (f64, f64),
    /// Whether the legend is drawn in it.
    legend: bool,
    /// Whether the minima's values are written in it.
    notes: bool,
}

/// Draws one panel on `area`: the shaded time held, the lines, the criterion, the minima.
fn draw_panel(
    area: &Root<'_>,
    layout: &Layout,
    series: &[ClearanceSeries<'_>],
    panel: &Panel,
) -> DrawResult {
    let (x, y) = (layout.x_s, panel.y_mm);
    let mut builder = ChartBuilder::on(area);
    if let Some(caption) = &panel.caption {
        builder.caption(caption, text(19.0));
    }
    let mut chart = builder
        .margin(16)
        .x_label_area_size(50)
        .y_label_area_size(85)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)?;
    draw_mesh(&mut chart, "t [s]", "clearance [mm]", fmt_tick, fmt_tick)?;
    if layout.held_until_s > x.0 {
        let until = layout.held_until_s.min(x.1);
        let anno = chart.draw_series(std::iter::once(Rectangle::new(
            [(x.0, y.0), (until, y.1)],
            HELD_GREY.filled(),
        )))?;
        anno.label("held by the ejector")
            .legend(box_mark(HELD_GREY.filled()));
    }
    for (i, s) in series.iter().enumerate() {
        let points = s.t_s.iter().zip(s.clearance_m).map(|(&t, &c)| (t, 1e3 * c));
        let style = colour(i).stroke_width(2);
        let segs = clipped_segments(points, y);
        let singles: Vec<(f64, f64)> = segs.iter().filter(|s| s.len() == 1).map(|s| s[0]).collect();
        chart
            .draw_series(
                segs.into_iter()
                    .filter(|s| s.len() > 1)
                    .map(|s| PathElement::new(s, style)),
            )?
            .label(s.label)
            .legend(line_mark(style));
        chart.draw_series(
            singles
                .into_iter()
                .map(|p| Circle::new(p, 2, style.filled())),
        )?;
    }
    let criterion_name = draw_criterion(&mut chart, layout)?;
    let minima = minima_mm(series, x, y);
    draw_minima(&mut chart, &minima, panel.notes, &[criterion_name])?;
    if panel.legend {
        let crowd = series
            .iter()
            .flat_map(|s| s.t_s.iter().zip(s.clearance_m).map(|(&t, &c)| (t, 1e3 * c)))
            .chain(minima.iter().map(|m| m.at))
            // The criterion's name at the right end of its line.
            .chain((0..8).map(|_| (x.1, layout.criterion_mm)));
        let corner = legend_corner(crowd, x, y);
        draw_legend(&mut chart, corner)?;
    }
    Ok(())
}

/// The plottable points of a line, split where a value cannot be drawn and where the line
/// leaves `(lo, hi)` in y, cut at the edge it crosses.
pub(super) fn clipped_segments(
    points: impl IntoIterator<Item = (f64, f64)>,
    (lo, hi): (f64, f64),
) -> Vec<Vec<(f64, f64)>> {
    let inside = |y: f64| (lo..=hi).contains(&y);
    let mut out = Vec::new();
    for seg in segments(points) {
        let mut current: Vec<(f64, f64)> = Vec::new();
        let mut prev: Option<(f64, f64)> = None;
        for p in seg {
            if let Some(q) = prev {
                // The part of the step from q to p inside the range, as fractions along it.
                let (a, b) = step_inside(q.1, p.1, (lo, hi));
                if a <= b {
                    let at = |f: f64| (q.0 + f * (p.0 - q.0), q.1 + f * (p.1 - q.1));
                    if current.is_empty() || a > 0.0 {
                        if current.len() > 1 {
                            out.push(std::mem::take(&mut current));
                        }
                        current.clear();
                        current.push(at(a));
                    }
                    current.push(at(b));
                    if b < 1.0 {
                        out.push(std::mem::take(&mut current));
                    }
                }
            } else if inside(p.1) {
                current.push(p);
            }
            prev = Some(p);
        }
        if !current.is_empty() {
            out.push(current);
        }
    }
    out
}

/// The fractions (from, to) of the step from `y0` to `y1` that lie within `(lo, hi)`; from
/// after to when none does.
fn step_inside(y0: f64, y1: f64, (lo, hi): (f64, f64)) -> (f64, f64) {
    let dy = y1 - y0;
    if dy.abs() < f64::MIN_POSITIVE {
        return if (lo..=hi).contains(&y0) {
            (0.0, 1.0)
        } else {
            (1.0, 0.0)
        };
    }
    let (f_lo, f_hi) = ((lo - y0) / dy, (hi - y0) / dy);
    let (enter, leave) = (f_lo.min(f_hi), f_lo.max(f_hi));
    (enter.max(0.0), leave.min(1.0))
}

/// Draws the criterion as a dashed red line across the chart, named at its right end; the
/// pixels its name covers (left, top, right, bottom).
fn draw_criterion(
    chart: &mut Chart2d<'_, '_, RangedCoordf64, RangedCoordf64>,
    layout: &Layout,
) -> Result<[i32; 4], Box<dyn std::error::Error>> {
    let (x, c) = (layout.x_s, layout.criterion_mm);
    let name = format!("criterion {}", fmt_mm(c));
    draw_dashed(
        chart,
        vec![(x.0, c), (x.1, c)],
        CRITERION_RED.stroke_width(2),
        Some(&name),
    )?;
    let style = text(NOTE_SIZE)
        .color(&CRITERION_RED)
        .pos(Pos::new(HPos::Right, VPos::Bottom));
    let (px, py) = chart.backend_coord(&(x.1, c));
    let (w, h) = note_size(&name);
    chart.draw_series(std::iter::once(
        EmptyElement::at((x.1, c)) + Text::new(name, (-8, -5), style),
    ))?;
    Ok([px - 8 - w, py - 5 - h, px - 8, py - 5])
}

/// A minimum to mark: where, in the chart's units, and its series' colour.
struct Minimum {
    /// (t \[s\], clearance \[mm\]).
    at: (f64, f64),
    /// The series' colour.
    colour: RGBColor,
}

/// The counted minima of `series` that lie within the chart (`x` \[s\], `y` \[mm\]).
fn minima_mm(series: &[ClearanceSeries<'_>], x: (f64, f64), y: (f64, f64)) -> Vec<Minimum> {
    series
        .iter()
        .enumerate()
        .map(|(i, s)| Minimum {
            at: (s.min_t_s, 1e3 * s.min_m),
            colour: colour(i),
        })
        .filter(|m| {
            plottable_point(m.at) && (x.0..=x.1).contains(&m.at.0) && (y.0..=y.1).contains(&m.at.1)
        })
        .collect()
}

/// Draws each minimum as a dot in its series' colour ringed in black, and, when `notes`, its
/// value beside it (placed by [`place_note`], clear of the pixels `taken`).
fn draw_minima(
    chart: &mut Chart2d<'_, '_, RangedCoordf64, RangedCoordf64>,
    minima: &[Minimum],
    notes: bool,
    taken: &[[i32; 4]],
) -> DrawResult {
    chart
        .draw_series(minima.iter().map(|m| {
            EmptyElement::at(m.at)
                + Circle::new((0, 0), DOT_RADIUS_PX, m.colour.filled())
                + Circle::new((0, 0), DOT_RADIUS_PX, BLACK)
        }))?
        .label("smallest clearance counted")
        .legend(|(px, py)| Circle::new((px + 11, py), DOT_RADIUS_PX, BLACK.filled()));
    if !notes {
        return Ok(());
    }
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let area = [xs.start, ys.start, xs.end, ys.end];
    let mut placed = taken.to_vec();
    for m in minima {
        let note = fmt_mm(m.at.1);
        let dot = chart.backend_coord(&m.at);
        let spot = place_note(dot, note_size(&note), area, &placed);
        placed.push(spot);
        let style = text(NOTE_SIZE).pos(Pos::new(HPos::Left, VPos::Top));
        chart.draw_series(std::iter::once(
            EmptyElement::at(m.at) + Text::new(note, (spot[0] - dot.0, spot[1] - dot.1), style),
        ))?;
    }
    Ok(())
}

/// The (width, height) in pixels of a note.
fn note_size(note: &str) -> (i32, i32) {
    let height = text(NOTE_SIZE)
        .font
        .box_size("0")
        .map_or(16, |(_, h)| h as i32);
    (estimate_width(note, NOTE_SIZE) as i32, height)
}

/// Where a note of `(w, h)` pixels beside the dot at `dot` goes (left, top, right, bottom):
/// right of the dot (left of it when `area` ends before), below it, where no line of its
/// release passes (after its minimum a clearance is at least the minimum), moved down past the
/// notes `placed` in the way; above it, moved up past them, when that leaves `area`.
pub(super) fn place_note(
    dot: (i32, i32),
    (w, h): (i32, i32),
    area: [i32; 4],
    placed: &[[i32; 4]],
) -> [i32; 4] {
    let gap = DOT_RADIUS_PX + 6;
    let left = if dot.0 + gap + w > area[2] {
        dot.0 - gap - w
    } else {
        dot.0 + gap
    };
    let in_the_way = |top: i32| {
        placed
            .iter()
            .find(|o| left < o[2] && o[0] < left + w && top < o[3] && o[1] < top + h)
            .copied()
    };
    let mut top = dot.1 + 4;
    while let Some(o) = in_the_way(top) {
        top = o[3] + 2;
    }
    if top + h > area[3] {
        top = dot.1 - 4 - h;
        while let Some(o) = in_the_way(top) {
            top = o[1] - 2 - h;
        }
    }
    [left, top, left + w, top + h]
}

/// A clearance in millimetres with a precision that suits it: 0.25 mm, 10.0 mm, 2000 mm.
pub(super) fn fmt_mm(v_mm: f64) -> String {
    let a = v_mm.abs();
    let decimals = if a < 1.0 {
        2
    } else if a < 100.0 {
        1
    } else {
        0
    };
    format!("{v_mm:.decimals$} mm")
}

#[cfg(test)]
mod tests;
