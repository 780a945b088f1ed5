//! Increments: what force and moment a fitted model lacks, reconstructed per axis as time
//! histories with their uncertainty, beside what the found model terms give.

use std::path::Path;

use plotters::prelude::*;

use super::kit::{
    DrawResult, FLOOR_GREY, LegendMark, Root, colour, draw_dashed, draw_legend_strip, draw_mesh,
    draw_polyline, fmt_tick, padded_range, plottable, plottable_point, render, segments, text,
    tint,
};
use super::{FigureError, FigureInput};

/// One event's reconstructed increment on one axis: per window, its mid-time, the increment
/// and the increment's standard deviation (three vectors of one length).
#[derive(Debug, Clone, Copy)]
pub struct IncrementSeries<'a> {
    /// The legend label, for example the event's name. An event keeps its position in
    /// [`IncrementPanel::series`] across panels, and with it its colour and label.
    pub label: &'a str,
    /// The windows' mid-times \[s\].
    pub t_s: &'a [f64],
    /// The increment per window (a coefficient increment, or a fraction of the ejector force).
    pub value: &'a [f64],
    /// The increment's standard deviation per window, in the unit of `value`.
    pub std: &'a [f64],
}

/// One panel of [`increment_figure`]: the increments of one axis.
#[derive(Debug, Clone, Default)]
pub struct IncrementPanel<'a> {
    /// The panel's caption, for example "dCY (side force)".
    pub axis: &'a str,
    /// The reconstructed increments, one per event, in the same event order in every panel.
    pub series: Vec<IncrementSeries<'a>>,
    /// What the found model terms give on this axis, per event: (times \[s\], increment), two
    /// vectors of one length. May be empty (no found terms, or none shown).
    pub model: Vec<(&'a [f64], &'a [f64])>,
}

/// How much white there is in a ±2σ band on white: a band is its series' colour at opacity
/// `1 - BAND_WHITE`, a light tint where it lies alone and darker where bands overlap.
const BAND_WHITE: f64 = 0.75;

/// Columns of the panel grid.
const COLUMNS: usize = 3;

/// Reconstructed increments against time, one panel per axis in a grid of three columns (as many
/// rows as the panels need; cells left over stay empty). In each panel every event's increment
/// is a line in the event's colour over its band of ±2 standard deviations in a light
/// translucent tint of that colour (where the bands of several events overlap, both stay
/// visible; a lone window gets an error bar), and the found terms' increments are black dashed
/// lines on top. The y axis is symmetric about a grey zero line and covers the bands and the
/// found terms; the time axis covers the times of the panel's series and found-term curves.
/// 1600 × 1200 px, `title` on top and a one-row legend below it: the events (labelled as in the
/// first panel that has them), the band, and "found terms" when any panel has a curve of them.
///
/// Points that cannot be drawn (not finite) are skipped, a line or band broken there; a
/// negative standard deviation gives no band at its window; a panel without drawable points
/// shows empty axes. Vectors that must have one length and do not are refused with
/// [`FigureError::Input`] naming the panel and the series.
pub fn increment_figure(
    path: &Path,
    panels: &[IncrementPanel],
    title: &str,
) -> Result<(), FigureError> {
    check_lengths(path, panels)?;
    render(path, (1600, 1200), |root| {
        let (_, body) = root.split_vertically(8);
        let body = body.titled(title, text(28.0))?;
        let (legend, grid) = body.split_vertically(44);
        draw_legend_strip(&legend, &legend_entries(panels))?;
        let rows = panels.len().div_ceil(COLUMNS).max(1);
        for (panel, area) in panels.iter().zip(grid.split_evenly((rows, COLUMNS)).iter()) {
            draw_panel(area, panel)?;
        }
        Ok(())
    })
}

/// Refuses series and found-term curves whose vectors differ in length.
fn check_lengths(path: &Path, panels: &[IncrementPanel]) -> Result<(), FigureError> {
    let refuse = |reason: FigureInput| FigureError::Input {
        path: path.to_path_buf(),
        reason,
    };
    for panel in panels {
        for s in &panel.series {
            if s.value.len() != s.t_s.len() || s.std.len() != s.t_s.len() {
                return Err(refuse(FigureInput::IncrementSeries {
                    axis: panel.axis.to_string(),
                    label: s.label.to_string(),
                    times: s.t_s.len(),
                    values: s.value.len(),
                    stds: s.std.len(),
                }));
            }
        }
        for (j, (times, values)) in panel.model.iter().enumerate() {
            if values.len() != times.len() {
                return Err(refuse(FigureInput::IncrementModel {
                    axis: panel.axis.to_string(),
                    event: j,
                    label: panel.series.get(j).map(|s| s.label.to_string()),
                    times: times.len(),
                    values: values.len(),
                }));
            }
        }
    }
    Ok(())
}

/// The legend: each event (labelled as in the first panel that has it), the band, and the
/// found terms when any panel has a curve of them.
fn legend_entries(panels: &[IncrementPanel]) -> Vec<(String, LegendMark)> {
    let events = panels.iter().map(|p| p.series.len()).max().unwrap_or(0);
    let mut entries: Vec<(String, LegendMark)> = (0..events)
        .map(|i| {
            let label = panels
                .iter()
                .find_map(|p| p.series.get(i))
                .map_or("", |s| s.label);
            (label.to_string(), LegendMark::Line(colour(i)))
        })
        .collect();
    entries.push((
        "±2σ band".to_string(),
        LegendMark::Band(tint(FLOOR_GREY, BAND_WHITE)),
    ));
    if panels.iter().any(|p| !p.model.is_empty()) {
        entries.push(("found terms".to_string(), LegendMark::Dashed(BLACK)));
    }
    entries
}

/// The points (time, increment) of one series.
fn series_points<'s>(s: &'s IncrementSeries<'_>) -> impl Iterator<Item = (f64, f64)> + 's {
    s.t_s.iter().copied().zip(s.value.iter().copied())
}

/// The points (time, increment) of one found-terms curve.
fn model_points<'s>(
    &(times, values): &'s (&[f64], &[f64]),
) -> impl Iterator<Item = (f64, f64)> + 's {
    times.iter().copied().zip(values.iter().copied())
}

/// The ±2σ band of one series: per window its time and (lower, upper) edge, `None` where it
/// cannot be drawn (the time, increment or standard deviation not finite, or σ negative).
fn band_edges<'s>(
    s: &'s IncrementSeries<'_>,
) -> impl Iterator<Item = Option<(f64, f64, f64)>> + 's {
    s.t_s.iter().zip(s.value).zip(s.std).map(|((&t, &v), &sd)| {
        let (lo, hi) = (v - 2.0 * sd, v + 2.0 * sd);
        let drawable = plottable(t) && plottable(sd) && sd >= 0.0;
        (drawable && plottable(lo) && plottable(hi)).then_some((t, lo, hi))
    })
}

/// Draws one panel: its axes, the bands, the zero line, the increments and the found terms.
fn draw_panel(area: &Root<'_>, panel: &IncrementPanel) -> DrawResult {
    let x = padded_range(
        panel
            .series
            .iter()
            .flat_map(|s| s.t_s.iter().copied())
            .chain(panel.model.iter().flat_map(|(t, _)| t.iter().copied())),
        0.01,
    );
    let extent = panel
        .series
        .iter()
        .flat_map(|s| {
            let values = series_points(s)
                .filter(|p| plottable_point(*p))
                .map(|p| p.1);
            let bands = band_edges(s).flatten().flat_map(|(_, lo, hi)| [lo, hi]);
            values.chain(bands)
        })
        .chain(
            panel
                .model
                .iter()
                .flat_map(|m| model_points(m).filter(|p| plottable_point(*p)).map(|p| p.1)),
        )
        .map(f64::abs)
        .filter(|v| plottable(*v))
        .fold(0.0f64, f64::max);
    let half = if extent > 1e-200 { 1.08 * extent } else { 1.0 };
    let mut chart = ChartBuilder::on(area)
        .caption(panel.axis, text(20.0))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(x.0..x.1, -half..half)?;
    draw_mesh(&mut chart, "Time [s]", "Increment", fmt_tick, fmt_tick)?;
    for (i, s) in panel.series.iter().enumerate() {
        let fill = colour(i).mix(1.0 - BAND_WHITE);
        for run in band_runs(band_edges(s)) {
            if let [(t, lo, hi)] = run[..] {
                // A lone window: its band as an error bar.
                chart.draw_series(std::iter::once(PathElement::new(
                    vec![(t, lo), (t, hi)],
                    fill.stroke_width(4),
                )))?;
            } else {
                let upper = run.iter().map(|&(t, _, hi)| (t, hi));
                let lower = run.iter().rev().map(|&(t, lo, _)| (t, lo));
                chart.draw_series(std::iter::once(Polygon::new(
                    upper.chain(lower).collect::<Vec<_>>(),
                    fill.filled(),
                )))?;
            }
        }
    }
    chart.draw_series(std::iter::once(PathElement::new(
        vec![(x.0, 0.0), (x.1, 0.0)],
        FLOOR_GREY.stroke_width(1),
    )))?;
    for (i, s) in panel.series.iter().enumerate() {
        draw_polyline(
            &mut chart,
            series_points(s),
            colour(i).stroke_width(2),
            None,
        )?;
    }
    let style = BLACK.stroke_width(2);
    for curve in &panel.model {
        for run in segments(model_points(curve)) {
            if let [p] = run[..] {
                chart.draw_series(std::iter::once(Circle::new(p, 2, BLACK.filled())))?;
            } else {
                draw_dashed(&mut chart, run, style, None)?;
            }
        }
    }
    Ok(())
}

/// Splits a band where it cannot be drawn.
fn band_runs(
    edges: impl IntoIterator<Item = Option<(f64, f64, f64)>>,
) -> Vec<Vec<(f64, f64, f64)>> {
    let mut out = Vec::new();
    let mut current = Vec::new();
    for e in edges {
        match e {
            Some(e) => current.push(e),
            None if !current.is_empty() => out.push(std::mem::take(&mut current)),
            None => {}
        }
    }
    if !current.is_empty() {
        out.push(current);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::testing::{check_png, dark_pixels};

    /// The seven axes of a diagnosis.
    const AXES: [&str; 7] = [
        "dCA (axial force)",
        "dCY (side force)",
        "dCZ (normal force)",
        "dCl (rolling moment)",
        "dCm (pitching moment)",
        "dCn (yawing moment)",
        "dF_ej / F_ej (ejector force)",
    ];

    /// One event's windows on one axis: (times, increments, standard deviations).
    type Windows = (Vec<f64>, Vec<f64>, Vec<f64>);

    /// One event's windows on axis `k`.
    fn event(k: usize, phase: f64, n: usize) -> Windows {
        let t: Vec<f64> = (0..n).map(|i| 0.025 + i as f64 * 0.05).collect();
        let scale = 0.01 * (k + 1) as f64;
        let v = t
            .iter()
            .map(|&t| scale * ((4.0 + k as f64) * t + phase).sin() + 0.5 * scale * t)
            .collect();
        let s = t.iter().map(|&t| 0.15 * scale * (1.0 + t)).collect();
        (t, v, s)
    }

    #[test]
    fn increment_figure_draws_seven_panels_with_found_terms() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("increments.png");
        let data: Vec<[Windows; 2]> = (0..7)
            .map(|k| [event(k, 0.0, 24), event(k, 0.8, 20)])
            .collect();
        let models: Vec<(Vec<f64>, Vec<f64>)> = (0..7)
            .map(|k| {
                let t: Vec<f64> = (0..121).map(|i| i as f64 * 0.01).collect();
                let scale = 0.01 * (k + 1) as f64;
                let v = t
                    .iter()
                    .map(|&t| 0.8 * scale * ((4.0 + k as f64) * t).sin())
                    .collect();
                (t, v)
            })
            .collect();
        let panels: Vec<IncrementPanel> = AXES
            .iter()
            .zip(&data)
            .zip(&models)
            .map(|((axis, events), (mt, mv))| IncrementPanel {
                axis,
                series: events
                    .iter()
                    .zip(["release 1", "release 2"])
                    .map(|((t, v, s), label)| IncrementSeries {
                        label,
                        t_s: t,
                        value: v,
                        std: s,
                    })
                    .collect(),
                model: vec![(mt.as_slice(), mv.as_slice())],
            })
            .collect();
        increment_figure(&path, &panels, "Missing increments, two releases").unwrap();
        check_png(&path, (1600, 1200));
        assert!(dark_pixels(&path, 0..40) > 200);
        if let Some(example) = std::env::var_os("SEPVAL_INCREMENTS_EXAMPLE") {
            std::fs::copy(&path, example).unwrap();
        }
    }

    #[test]
    fn increment_figure_survives_odd_data() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("increments.png");
        let (t, mut v, mut s) = event(1, 0.0, 12);
        v[3] = f64::NAN;
        v[4] = f64::INFINITY;
        s[6] = f64::NAN;
        s[7] = -1.0;
        s[9] = f64::INFINITY;
        let zero = vec![0.0; t.len()];
        let nan = vec![f64::NAN; t.len()];
        let mut odd_t = t.clone();
        odd_t[10] = f64::NEG_INFINITY;
        let model_t = [0.0, f64::NAN, 0.2, 0.3];
        let model_v = [0.01, 0.0, f64::INFINITY, -0.01];
        let series = |label, t_s, value, std| IncrementSeries {
            label,
            t_s,
            value,
            std,
        };
        let panels = vec![
            IncrementPanel {
                axis: "odd",
                series: vec![
                    series("nan and inf", &t, &v, &s),
                    series("zero std", &odd_t, &v, &zero),
                ],
                model: vec![(&model_t[..], &model_v[..])],
            },
            IncrementPanel {
                axis: "all NaN",
                series: vec![series("nan", &t, &nan, &nan)],
                model: vec![],
            },
            IncrementPanel {
                axis: "empty",
                series: vec![series("empty", &[], &[], &[])],
                model: vec![(&[], &[])],
            },
            IncrementPanel {
                axis: "one window",
                series: vec![series("one", &[0.5], &[0.02], &[0.01])],
                model: vec![(&[0.5], &[0.0])],
            },
            IncrementPanel {
                axis: "zero everywhere",
                series: vec![series("zero", &t, &zero, &zero)],
                model: vec![],
            },
            IncrementPanel::default(),
        ];
        increment_figure(&path, &panels, "odd").unwrap();
        check_png(&path, (1600, 1200));
        increment_figure(&path, &[], "").unwrap();
        check_png(&path, (1600, 1200));
        let many: Vec<IncrementPanel> = (0..10).map(|_| panels[0].clone()).collect();
        increment_figure(&path, &many, "ten panels").unwrap();
        check_png(&path, (1600, 1200));
    }

    #[test]
    fn increment_figure_refuses_mismatched_lengths() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("increments.png");
        let (t, v, s) = event(0, 0.0, 10);
        let good = IncrementSeries {
            label: "release 1",
            t_s: &t,
            value: &v,
            std: &s,
        };
        let short_std = IncrementPanel {
            axis: "dCY (side force)",
            series: vec![
                good,
                IncrementSeries {
                    std: &s[..9],
                    ..good
                },
            ],
            model: vec![],
        };
        let err = increment_figure(&path, &[short_std], "x").unwrap_err();
        assert!(matches!(err, FigureError::Input { .. }), "{err:?}");
        let message = err.to_string();
        assert!(message.contains("increments.png"), "{message}");
        assert!(message.contains("dCY (side force)"), "{message}");
        assert!(message.contains("release 1"), "{message}");

        let short_model = IncrementPanel {
            axis: "dCn (yawing moment)",
            series: vec![good],
            model: vec![(&t[..], &v[..4])],
        };
        let err = increment_figure(&path, &[short_model], "x").unwrap_err();
        assert!(matches!(err, FigureError::Input { .. }), "{err:?}");
        let message = err.to_string();
        assert!(message.contains("increments.png"), "{message}");
        assert!(message.contains("dCn (yawing moment)"), "{message}");
        assert!(!path.exists());
    }
}
