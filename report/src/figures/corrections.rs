//! Corrections: what an update of a store's aerodynamic data changed, one panel per corrected
//! field, each correction against its variable with its ±2σ band, the range the releases
//! explored shaded, and the evidence it was chosen from.

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::kit::{
    Chart2d, DrawResult, FLOOR_GREY, LegendMark, Root, band_polygon, colour, draw_dashed,
    draw_legend_strip, draw_mesh, draw_polyline, fmt_tick, padded_range, plottable,
    plottable_point, render, text, tint,
};
use super::{FigureError, FigureInput};

/// One correction: its value and standard deviation along its variable, what the releases
/// explored, its breakpoints, and (optionally) the evidence it was chosen from.
#[derive(Debug, Clone, Default)]
pub struct CorrectionPanel<'a> {
    /// The caption, for example "Cm over local alpha".
    pub caption: &'a str,
    /// The variable with its unit, for example "local alpha \[deg\]".
    pub x_label: &'a str,
    /// The variable at the curve's points.
    pub x: &'a [f64],
    /// The correction there.
    pub value: &'a [f64],
    /// Its standard deviation there.
    pub std: &'a [f64],
    /// The range the releases explored (the curve is dashed outside it).
    pub explored: (f64, f64),
    /// The breakpoints and their values (dots).
    pub knots: (&'a [f64], &'a [f64]),
    /// Evidence: (variable, value, standard deviation) per point, drawn as grey error bars;
    /// empty when there is none to show.
    pub evidence: Vec<(f64, f64, f64)>,
}

/// Columns of the panel grid.
const COLUMNS: usize = 2;
/// How much white there is in the band.
const BAND_WHITE: f64 = 0.72;

/// One panel per correction in a grid of two columns, 1400 px wide and 460 px per row of
/// panels: the correction as a line (solid where the releases explored its variable, dashed
/// beyond), its ±2σ band, the explored range shaded, its breakpoints as dots and the evidence
/// as grey points with ±2σ bars; `title` on top and a legend below it. Vectors of one panel
/// that must have one length and do not are refused with [`FigureError::Input`].
pub fn correction_figure(
    path: &Path,
    panels: &[CorrectionPanel],
    title: &str,
) -> Result<(), FigureError> {
    for p in panels {
        if p.value.len() != p.x.len()
            || p.std.len() != p.x.len()
            || p.knots.0.len() != p.knots.1.len()
        {
            return Err(FigureError::Input {
                path: path.to_path_buf(),
                reason: FigureInput::CorrectionPanel {
                    caption: p.caption.to_string(),
                    points: p.x.len(),
                    values: p.value.len(),
                    stds: p.std.len(),
                    breakpoints: p.knots.0.len(),
                    knot_values: p.knots.1.len(),
                },
            });
        }
    }
    let rows = panels.len().div_ceil(COLUMNS).max(1);
    let height = 120 + 460 * rows as u32;
    render(path, (1400, height), |root| {
        let (_, body) = root.split_vertically(8);
        let body = body.titled(title, text(26.0))?;
        let (legend, grid) = body.split_vertically(44);
        draw_legend_strip(
            &legend,
            &[
                ("correction".to_string(), LegendMark::Line(colour(0))),
                (
                    "±2σ band".to_string(),
                    LegendMark::Band(tint(colour(0), BAND_WHITE)),
                ),
                (
                    "range the releases explored".to_string(),
                    LegendMark::Band(tint(FLOOR_GREY, 0.9)),
                ),
                (
                    "evidence (reconstruction, ±2σ)".to_string(),
                    LegendMark::Ring(FLOOR_GREY),
                ),
            ],
        )?;
        for (panel, area) in panels.iter().zip(grid.split_evenly((rows, COLUMNS)).iter()) {
            draw_panel(area, panel)?;
        }
        Ok(())
    })
}

fn draw_panel(area: &Root<'_>, p: &CorrectionPanel) -> DrawResult {
    let x = padded_range(p.x.iter().copied().chain(p.knots.0.iter().copied()), 0.02);
    let band = p
        .value
        .iter()
        .zip(p.std)
        .flat_map(|(v, s)| [v - 2.0 * s, v + 2.0 * s]);
    let evidence = p
        .evidence
        .iter()
        .flat_map(|(_, v, s)| [v - 2.0 * s, v + 2.0 * s]);
    let y = padded_range(
        band.chain(evidence)
            .chain(p.value.iter().copied())
            .chain([0.0]),
        0.06,
    );
    let mut chart = ChartBuilder::on(area)
        .caption(p.caption, text(20.0))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)?;
    draw_mesh(&mut chart, p.x_label, "Correction", fmt_tick, fmt_tick)?;
    let (lo, hi) = (p.explored.0.max(x.0), p.explored.1.min(x.1));
    if plottable(lo) && plottable(hi) && hi > lo {
        chart.draw_series(std::iter::once(Rectangle::new(
            [(lo, y.0), (hi, y.1)],
            tint(FLOOR_GREY, 0.9).filled(),
        )))?;
    }
    let edges: Vec<(f64, f64, f64)> =
        p.x.iter()
            .zip(p.value)
            .zip(p.std)
            .map(|((&x, &v), &s)| (x, v - 2.0 * s, v + 2.0 * s))
            .filter(|&(x, a, b)| plottable(x) && plottable(a) && plottable(b))
            .collect();
    draw_band(&mut chart, &edges)?;
    chart.draw_series(std::iter::once(PathElement::new(
        vec![(x.0, 0.0), (x.1, 0.0)],
        FLOOR_GREY.stroke_width(1),
    )))?;
    for &(ex, v, s) in &p.evidence {
        if plottable_point((ex, v)) && plottable(s) {
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(ex, v - 2.0 * s), (ex, v + 2.0 * s)],
                tint(FLOOR_GREY, 0.5).stroke_width(1),
            )))?;
            chart.draw_series(std::iter::once(Circle::new(
                (ex, v),
                3,
                FLOOR_GREY.filled(),
            )))?;
        }
    }
    let inside = |x: f64| x >= p.explored.0 - 1e-12 && x <= p.explored.1 + 1e-12;
    let points: Vec<(f64, f64)> = p.x.iter().copied().zip(p.value.iter().copied()).collect();
    draw_polyline(
        &mut chart,
        points
            .iter()
            .map(|&(x, v)| if inside(x) { (x, v) } else { (x, f64::NAN) }),
        colour(0).stroke_width(3),
        None,
    )?;
    let beyond: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|&(x, v)| x >= p.explored.1 - 1e-12 && plottable_point((x, v)))
        .collect();
    if beyond.len() > 1 {
        draw_dashed(&mut chart, beyond, colour(0).stroke_width(2), None)?;
    }
    chart.draw_series(
        p.knots
            .0
            .iter()
            .zip(p.knots.1)
            .filter(|(x, v)| plottable_point((**x, **v)))
            .map(|(&x, &v)| Circle::new((x, v), 5, colour(0).filled())),
    )?;
    Ok(())
}

/// The ±2σ band through `edges` (x, lower, upper): a filled area, or a bar where every edge
/// has the same x (a correction at one Mach, whose area would have no width).
fn draw_band(
    chart: &mut Chart2d<'_, '_, RangedCoordf64, RangedCoordf64>,
    edges: &[(f64, f64, f64)],
) -> DrawResult {
    let (x_lo, x_hi) = edges
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), e| {
            (a.min(e.0), b.max(e.0))
        });
    if edges.len() > 1 && x_hi > x_lo {
        chart.draw_series(std::iter::once(band_polygon(
            edges,
            tint(colour(0), BAND_WHITE).filled(),
        )))?;
    } else if let Some(&(ex, _, _)) = edges.first() {
        // All at one x (a correction at one Mach): the band as a bar.
        let lo = edges.iter().map(|e| e.1).fold(f64::INFINITY, f64::min);
        let hi = edges.iter().map(|e| e.2).fold(f64::NEG_INFINITY, f64::max);
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(ex, lo), (ex, hi)],
            tint(colour(0), BAND_WHITE).stroke_width(10),
        )))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::testing::{check_png, dark_pixels};

    #[test]
    fn correction_figure_draws_each_panel_and_refuses_ragged_input() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("corrections.png");
        let x: Vec<f64> = (0..=90).map(|i| i as f64 * 0.1).collect();
        let v: Vec<f64> = x.iter().map(|x| 0.2 * (-x).exp()).collect();
        let s: Vec<f64> = x.iter().map(|x| 0.01 + 0.002 * x).collect();
        let knots = [0.0, 0.5, 1.0, 2.0, 9.0];
        let kv = [0.2, 0.12, 0.07, 0.03, 0.0];
        let panels = vec![
            CorrectionPanel {
                caption: "interference dCZ over distance",
                x_label: "distance from carriage [m]",
                x: &x,
                value: &v,
                std: &s,
                explored: (0.0, 2.0),
                knots: (&knots, &kv),
                evidence: vec![(0.3, 0.15, 0.02), (1.0, 0.08, 0.02)],
            },
            CorrectionPanel {
                caption: "Cm over alpha",
                x_label: "local alpha [deg]",
                x: &x,
                value: &v,
                std: &s,
                explored: (1.0, 5.0),
                knots: (&knots, &kv),
                evidence: Vec::new(),
            },
            CorrectionPanel {
                caption: "Cn over beta",
                x_label: "local beta [deg]",
                x: &x,
                value: &v,
                std: &s,
                explored: (0.0, 9.0),
                knots: (&knots, &kv),
                evidence: Vec::new(),
            },
        ];
        correction_figure(&path, &panels, "What the update changed").unwrap();
        check_png(&path, (1400, 120 + 460 * 2));
        assert!(dark_pixels(&path, 600..1000) > 2000);
        let bad = vec![CorrectionPanel {
            caption: "ragged",
            x: &x,
            value: &v[..3],
            std: &s,
            ..CorrectionPanel::default()
        }];
        let e = correction_figure(&dir.path().join("bad.png"), &bad, "x").unwrap_err();
        assert!(e.to_string().contains("ragged"), "{e}");
        assert!(!dir.path().join("bad.png").exists());
    }
}
