//! Figure 7 of Anderson's study: the factors each method found beside the true ones.

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::FontTransform;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::kit::{
    Chart2d, DrawResult, Root, box_mark, colour, draw_dashed, draw_legend, estimate_width,
    fmt_tick, line_mark, plottable, render, text,
};
use super::{FigureError, FigureInput};

/// `value` normalised to `range` ((value − min) / (max − min)), if that can be drawn.
fn normalise(value: f64, (min, max): (f64, f64)) -> Option<f64> {
    let span = max - min;
    let v = (value - min) / span;
    (plottable(value) && plottable(min) && plottable(max) && span.abs() > 1e-300 && plottable(v))
        .then_some(v)
}

/// Figure 7: the factors found by each method beside the truth, as grouped bars per factor,
/// each factor normalised to its range ((value − min) / (max − min), so 0 and 1 are the ends
/// of the search range), the truth drawn as a black marker across the group when given.
///
/// `names` and `ranges` give one entry per factor; each method, and the truth, gives one value
/// per factor in the factor's own unit. A factor whose range is empty or not finite, or a value
/// that is not finite, is left out. The figure is 1000 × 700 px, wider for many factors; names
/// that do not fit under their group are written vertically.
pub fn factor_figure(
    path: &Path,
    names: &[&str],
    ranges: &[(f64, f64)],
    methods: &[(&str, &[f64])],
    truth: Option<&[f64]>,
) -> Result<(), FigureError> {
    check_lengths(names.len(), ranges.len(), methods, truth).map_err(|reason| {
        FigureError::Input {
            path: path.to_path_buf(),
            reason,
        }
    })?;
    let bars = Bars::of(ranges, methods, truth);
    let layout = Layout::of(names, methods.len() + usize::from(truth.is_some()), &bars);
    let n = names.len();
    render(path, (layout.width, layout.height), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                "Figure 7. Factors found by each method, normalised to their ranges",
                text(26.0),
            )
            .margin(18)
            .x_label_area_size(layout.label_area)
            .y_label_area_size(85)
            .build_cartesian_2d(-0.5..(n.max(1) as f64 - 0.5), layout.y.0..layout.y.1)?;
        draw_axes(&mut chart, n)?;
        draw_bars(&mut chart, methods, &bars)?;
        draw_names(root, &chart, names, &layout)?;
        if layout.entries > 0 {
            draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        }
        Ok(())
    })
}

/// Checks that every method, the ranges and the truth give one value per factor (`n`).
fn check_lengths(
    n: usize,
    ranges: usize,
    methods: &[(&str, &[f64])],
    truth: Option<&[f64]>,
) -> Result<(), FigureInput> {
    if ranges != n {
        return Err(FigureInput::FactorRanges { names: n, ranges });
    }
    for (label, values) in methods {
        if values.len() != n {
            return Err(FigureInput::MethodValues {
                label: label.to_string(),
                values: values.len(),
                factors: n,
            });
        }
    }
    if let Some(given) = truth.map(<[f64]>::len).filter(|&len| len != n) {
        return Err(FigureInput::TruthValues {
            values: given,
            factors: n,
        });
    }
    Ok(())
}

/// The values drawn: each method's and the truth's, normalised to the factors' ranges (`None`
/// where a value cannot be drawn).
struct Bars {
    methods: Vec<Vec<Option<f64>>>,
    truth: Option<Vec<Option<f64>>>,
}

impl Bars {
    fn of(ranges: &[(f64, f64)], methods: &[(&str, &[f64])], truth: Option<&[f64]>) -> Self {
        let normalised = |values: &[f64]| -> Vec<Option<f64>> {
            values
                .iter()
                .zip(ranges)
                .map(|(&v, &r)| normalise(v, r))
                .collect()
        };
        Bars {
            methods: methods
                .iter()
                .map(|(_, values)| normalised(values))
                .collect(),
            truth: truth.map(normalised),
        }
    }

    /// The smallest and largest value drawn, with 0 and 1 (the range ends) always included.
    fn span(&self) -> (f64, f64) {
        self.methods
            .iter()
            .flatten()
            .chain(self.truth.iter().flatten())
            .flatten()
            .copied()
            .fold((0.0f64, 1.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)))
    }
}

/// Font size of the factor names \[px\].
const LABEL_SIZE: f64 = 15.0;

/// The figure's size, the room for the names under the groups and the value axis.
struct Layout {
    width: u32,
    height: u32,
    /// Height of the area under the plot that holds the names \[px\].
    label_area: u32,
    /// Width of one factor's group \[px\].
    group_px: u32,
    /// Whether the names are written vertically (when one does not fit its group).
    vertical: bool,
    /// The value axis, with headroom above the bars for the legend.
    y: (f64, f64),
    /// Legend entries: the methods and the truth.
    entries: usize,
}

impl Layout {
    fn of(names: &[&str], entries: usize, bars: &Bars) -> Self {
        let n = names.len();
        let (vmin, vmax) = bars.span();
        let width = (200 + 60 * n).clamp(1000, 2000) as u32;
        // Room for the names: horizontal when each fits its group, vertical otherwise.
        let widest = names
            .iter()
            .map(|name| estimate_width(name, LABEL_SIZE))
            .max()
            .unwrap_or(0);
        let group_px = (width.saturating_sub(140)) / (n.max(1) as u32);
        let vertical = widest + 8 > group_px;
        let label_area = if vertical {
            (widest + 24).clamp(40, 260)
        } else {
            40
        };
        let height = 660 + label_area;
        // Headroom above the bars for the legend (upper right), about 24 px an entry.
        let plot_px = f64::from(height - label_area - 110);
        let free = if entries > 0 {
            ((24.0 * entries as f64 + 34.0) / plot_px).min(0.6)
        } else {
            0.0
        };
        let lo = vmin - 0.05 * (vmax - vmin);
        let top = vmax + 0.03 * (vmax - vmin);
        Layout {
            width,
            height,
            label_area,
            group_px,
            vertical,
            y: (lo, lo + (top - lo) / (1.0 - free)),
            entries,
        }
    }
}

/// A chart with a factor axis and a value axis.
type FactorChart<'a, 'b> = Chart2d<'a, 'b, RangedCoordf64, RangedCoordf64>;

/// The value axis with its grid, and the ends of the search ranges (0 and 1) dashed across.
fn draw_axes(chart: &mut FactorChart, n: usize) -> DrawResult {
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(0)
        .y_desc("Normalised value (v − min) / (max − min)")
        .axis_desc_style(text(19.0))
        .label_style(text(15.0))
        .y_label_formatter(&|v| fmt_tick(*v))
        .bold_line_style(RGBColor(210, 210, 210))
        .light_line_style(RGBColor(238, 238, 238))
        .axis_style(RGBColor(60, 60, 60))
        .draw()?;
    let x_ends = (-0.5, n.max(1) as f64 - 0.5);
    for level in [0.0, 1.0] {
        draw_dashed(
            chart,
            vec![(x_ends.0, level), (x_ends.1, level)],
            RGBColor(150, 150, 150).stroke_width(1),
            None,
        )?;
    }
    Ok(())
}

/// Each method's bars side by side in each factor's group, and the truth's marker across it.
fn draw_bars(chart: &mut FactorChart, methods: &[(&str, &[f64])], bars: &Bars) -> DrawResult {
    let m = methods.len().max(1) as f64;
    let bar = 0.8 / m;
    for (j, ((label, _), values)) in methods.iter().zip(&bars.methods).enumerate() {
        let style = colour(j).filled();
        let rectangles: Vec<Rectangle<(f64, f64)>> = values
            .iter()
            .enumerate()
            .filter_map(|(i, v)| {
                let v = (*v)?;
                let x0 = i as f64 - 0.4 + j as f64 * bar;
                Some(Rectangle::new([(x0, 0.0), (x0 + bar * 0.92, v)], style))
            })
            .collect();
        chart
            .draw_series(rectangles)?
            .label(*label)
            .legend(box_mark(style));
    }
    if let Some(truth) = &bars.truth {
        let style = BLACK.stroke_width(4);
        let marks: Vec<PathElement<(f64, f64)>> = truth
            .iter()
            .enumerate()
            .filter_map(|(i, v)| {
                let v = (*v)?;
                Some(PathElement::new(
                    vec![(i as f64 - 0.45, v), (i as f64 + 0.45, v)],
                    style,
                ))
            })
            .collect();
        chart
            .draw_series(marks)?
            .label("Truth")
            .legend(line_mark(style));
    }
    Ok(())
}

/// The factor names under their groups: every name while they fit side by side, else every
/// `step`-th; vertical when one does not fit its group.
fn draw_names(root: &Root, chart: &FactorChart, names: &[&str], layout: &Layout) -> DrawResult {
    let style = text(LABEL_SIZE);
    let step = (16 / layout.group_px.max(1) + 1) as usize;
    for (i, name) in names.iter().enumerate().step_by(step) {
        let (px, py) = chart.backend_coord(&(i as f64, layout.y.0));
        if layout.vertical {
            let style = style
                .transform(FontTransform::Rotate270)
                .pos(Pos::new(HPos::Right, VPos::Center));
            root.draw(&Text::new(*name, (px, py + 8), style))?;
        } else {
            let style = style.pos(Pos::new(HPos::Center, VPos::Top));
            root.draw(&Text::new(*name, (px, py + 10), style))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::testing::{check_png, decode_size};

    #[test]
    fn factor_figure_draws_grouped_bars() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fig7_factors.png");
        let names = ["C_m_alpha", "C_n_beta", "C_l_p", "ejector_force", "cg_x"];
        let ranges = [(-2.0, 0.0), (0.0, 1.0), (-1.0, 1.0), (5e3, 2e4), (0.1, 0.3)];
        let ga = [-1.1, 0.42, 0.1, 1.2e4, 0.21];
        let nm = [-0.9, 0.5, -0.2, 1.5e4, 0.19];
        let truth = [-1.0, 0.45, 0.0, 1.3e4, 0.2];
        let methods: [(&str, &[f64]); 2] = [("GA", &ga), ("Nelder-Mead", &nm)];
        factor_figure(&path, &names, &ranges, &methods, Some(&truth)).unwrap();
        check_png(&path, (1000, 700));
    }

    #[test]
    fn factor_figure_survives_odd_data_and_refuses_mismatches() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("odd.png");
        let names = ["a", "a factor with a rather long name", "c"];
        let ranges = [(0.0, 0.0), (f64::NAN, 1.0), (0.0, 1.0)];
        let values = [f64::NAN, 0.5, f64::INFINITY];
        let methods: [(&str, &[f64]); 1] = [("m", &values)];
        factor_figure(&path, &names, &ranges, &methods, None).unwrap();
        check_png(&path, decode_size(&path));
        // No factors and no methods: empty axes.
        let empty = dir.path().join("empty.png");
        factor_figure(&empty, &[], &[], &[], Some(&[])).unwrap();
        check_png(&empty, (1000, 700));
        // Many factors with long names are written vertically under a wider figure.
        let many: Vec<String> = (0..30).map(|i| format!("factor_number_{i}")).collect();
        let many: Vec<&str> = many.iter().map(String::as_str).collect();
        let ranges = vec![(0.0, 1.0); 30];
        let values: Vec<f64> = (0..30).map(|i| f64::from(i) / 30.0).collect();
        let wide = dir.path().join("wide.png");
        factor_figure(&wide, &many, &ranges, &[("m", &values)], Some(&values)).unwrap();
        let (w, h) = decode_size(&wide);
        assert!(w > 1000 && h > 700, "{w} x {h}");
        check_png(&wide, (w, h));
        // Hundreds of factors: a bounded figure, names thinned out.
        let names = vec!["a_factor"; 500];
        let ranges = vec![(0.0, 1.0); 500];
        let values = vec![0.5; 500];
        factor_figure(&wide, &names, &ranges, &[("m", &values)], None).unwrap();
        let (w, h) = decode_size(&wide);
        assert!(w <= 2000 && h <= 1000, "{w} x {h}");
        check_png(&wide, (w, h));

        let bad = dir.path().join("bad.png");
        let err = factor_figure(&bad, &["a", "b"], &[(0.0, 1.0)], &[], None).unwrap_err();
        assert!(matches!(err, FigureError::Input { .. }), "{err:?}");
        assert!(err.to_string().contains("bad.png"), "{err}");
        let err =
            factor_figure(&bad, &["a"], &[(0.0, 1.0)], &[("m", &[1.0, 2.0])], None).unwrap_err();
        assert!(matches!(err, FigureError::Input { .. }), "{err:?}");
        let err = factor_figure(&bad, &["a"], &[(0.0, 1.0)], &[], Some(&[1.0, 2.0])).unwrap_err();
        assert!(matches!(err, FigureError::Input { .. }), "{err:?}");
        assert!(!bad.exists());
    }
}
