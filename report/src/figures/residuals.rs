//! Residuals: simulated minus measured for the six channels, with the noise bands.

use std::path::Path;

use plotters::prelude::*;

use super::kit::{
    FLOOR_GREY, LegendMark, colour, draw_legend_strip, draw_mesh, draw_polyline, fmt_tick,
    padded_range, plottable, render, text,
};
use super::{FigureError, FigureInput};

/// The six residual channels: caption, unit, whether the channel is a position.
const RESIDUAL_CHANNELS: [(&str, &str, bool); 6] = [
    ("x (downrange)", "m", true),
    ("y (crossrange)", "m", true),
    ("z (down)", "m", true),
    ("Roll φ", "deg", false),
    ("Pitch θ", "deg", false),
    ("Yaw ψ", "deg", false),
];

/// The fill of the ±σ bands.
const BAND: RGBColor = RGBColor(222, 222, 222);

/// Residuals (simulated minus measured) against time for six channels in a 2 × 3 grid (x, y,
/// z \[m\]; roll, pitch, yaw \[deg\]), one line per labelled residual set (e.g. "baseline",
/// "extended"), with grey ±σ bands: `sigma` is (sigma_pos_m, sigma_att_deg), a band left out
/// when its σ is not positive. Each set gives one `[x, y, z, roll, pitch, yaw]` per time in
/// `times_s`. 1600 × 1000 px, `title` on top and one legend below it.
pub fn residual_figure(
    path: &Path,
    times_s: &[f64],
    sets: &[(&str, &[[f64; 6]])],
    sigma: (f64, f64),
    title: &str,
) -> Result<(), FigureError> {
    for (label, values) in sets {
        if values.len() != times_s.len() {
            return Err(FigureError::Input {
                path: path.to_path_buf(),
                reason: FigureInput::Residuals {
                    label: label.to_string(),
                    samples: values.len(),
                    times: times_s.len(),
                },
            });
        }
    }
    let band = |is_pos: bool| {
        let s = if is_pos { sigma.0 } else { sigma.1 };
        (plottable(s) && s > 0.0).then_some(s)
    };
    render(path, (1600, 1000), |root| {
        let (_, body) = root.split_vertically(8);
        let body = body.titled(title, text(28.0))?;
        let (legend, grid) = body.split_vertically(44);
        let mut entries: Vec<(String, LegendMark)> = sets
            .iter()
            .enumerate()
            .map(|(i, (label, _))| ((*label).to_string(), LegendMark::Line(colour(i))))
            .collect();
        if band(true).is_some() || band(false).is_some() {
            let fmt_sigma = |s: Option<f64>, unit| match s {
                Some(s) => format!("{} {unit}", fmt_tick(s)),
                None => "none".to_string(),
            };
            entries.push((
                format!(
                    "±σ (position {}, attitude {})",
                    fmt_sigma(band(true), "m"),
                    fmt_sigma(band(false), "deg")
                ),
                LegendMark::Band(BAND),
            ));
        }
        draw_legend_strip(&legend, &entries)?;
        let x = padded_range(times_s.iter().copied(), 0.01);
        for (k, (panel, &(name, unit, is_pos))) in grid
            .split_evenly((2, 3))
            .iter()
            .zip(&RESIDUAL_CHANNELS)
            .enumerate()
        {
            let sigma = band(is_pos);
            let extent = sets
                .iter()
                .flat_map(|(_, v)| v.iter().map(|r| r[k].abs()))
                .chain(sigma.map(|s| 1.25 * s))
                .filter(|v| plottable(*v))
                .fold(0.0f64, f64::max);
            let half = if extent > 1e-200 { 1.08 * extent } else { 1.0 };
            let caption = format!("{name} [{unit}]");
            let mut chart = ChartBuilder::on(panel)
                .caption(caption, text(20.0))
                .margin(12)
                .x_label_area_size(48)
                .y_label_area_size(80)
                .build_cartesian_2d(x.0..x.1, -half..half)?;
            draw_mesh(
                &mut chart,
                "Time [s]",
                &format!("Residual [{unit}]"),
                fmt_tick,
                fmt_tick,
            )?;
            if let Some(s) = sigma {
                chart.draw_series(std::iter::once(Rectangle::new(
                    [(x.0, -s), (x.1, s)],
                    BAND.filled(),
                )))?;
            }
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(x.0, 0.0), (x.1, 0.0)],
                FLOOR_GREY.stroke_width(1),
            )))?;
            for (i, (_, values)) in sets.iter().enumerate() {
                let points = times_s.iter().zip(values.iter()).map(|(&t, r)| (t, r[k]));
                draw_polyline(&mut chart, points, colour(i).stroke_width(2), None)?;
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::testing::{check_png, dark_pixels};

    /// Residuals at `n` times, shaped by `k`.
    fn residuals(n: usize, k: f64) -> (Vec<f64>, Vec<[f64; 6]>) {
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.02).collect();
        let r = t
            .iter()
            .map(|&t| {
                let s = (7.0 * t).sin();
                [
                    0.04 * k * s,
                    0.02 * k * t,
                    -0.06 * k * s,
                    0.4 * k * s,
                    0.8 * k * t,
                    -0.3 * k,
                ]
            })
            .collect();
        (t, r)
    }

    #[test]
    fn residual_figure_draws_a_grid() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("residuals.png");
        let (t, base) = residuals(60, 3.0);
        let (_, ext) = residuals(60, 1.0);
        residual_figure(
            &path,
            &t,
            &[("baseline", &base), ("extended", &ext)],
            (0.05, 0.5),
            "Residuals, event 1",
        )
        .unwrap();
        check_png(&path, (1600, 1000));
        assert!(dark_pixels(&path, 0..40) > 200);
    }

    #[test]
    fn residual_figure_survives_nan_and_empty_and_refuses_mismatches() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("residuals.png");
        let (t, mut r) = residuals(20, 1.0);
        r[4] = [f64::NAN; 6];
        r[5][2] = f64::INFINITY;
        residual_figure(&path, &t, &[("odd", &r)], (f64::NAN, 0.0), "odd").unwrap();
        check_png(&path, (1600, 1000));
        residual_figure(&path, &[], &[("empty", &[])], (0.05, 0.5), "empty").unwrap();
        check_png(&path, (1600, 1000));
        residual_figure(&path, &[], &[], (0.05, 0.5), "").unwrap();
        check_png(&path, (1600, 1000));
        let err = residual_figure(&path, &t, &[("short", &r[..3])], (0.05, 0.5), "x").unwrap_err();
        assert!(matches!(err, FigureError::Input { .. }), "{err:?}");
        assert!(err.to_string().contains("residuals.png"), "{err}");
    }
}
