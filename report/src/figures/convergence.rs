//! Convergence: the best weighted goal against the number of simulations run.

use std::path::Path;

use plotters::prelude::*;

use super::FigureError;
use super::kit::{
    FLOOR_GREY, colour, draw_dashed, draw_legend, draw_mesh, draw_polyline, fmt_count_tick,
    fmt_tick, legend_corner, log_range, padded_range_from_zero, plottable, render, text,
};

/// Convergence: the best weighted goal J_pos/σ_pos + J_att/σ_att against simulations run, one
/// line per method (a staircase: the best so far holds until the next entry), log y axis, with
/// a grey dashed horizontal line at `floor` (2.0 = both goals at the noise) when given.
///
/// Each history is (simulations run, best goal); it is drawn in order of simulations. Goals
/// that are not positive cannot be drawn on the log axis and are skipped. 1000 × 700 px.
pub fn convergence_figure(
    path: &Path,
    histories: &[(&str, &[(u64, f64)])],
    floor: Option<f64>,
) -> Result<(), FigureError> {
    let floor = floor.filter(|f| plottable(*f) && *f >= 1e-100);
    let steps: Vec<Vec<(f64, f64)>> = histories
        .iter()
        .map(|(_, h)| {
            let mut h: Vec<(f64, f64)> = h
                .iter()
                .map(|&(n, j)| (n as f64, j))
                .filter(|&(_, j)| plottable(j) && j >= 1e-100)
                .collect();
            h.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut staircase = Vec::with_capacity(2 * h.len());
            for (k, &(n, j)) in h.iter().enumerate() {
                if k > 0 {
                    staircase.push((n, h[k - 1].1));
                }
                staircase.push((n, j));
            }
            staircase
        })
        .collect();
    render(path, (1000, 700), |root| {
        let all = || steps.iter().flatten().copied();
        let x = padded_range_from_zero(all().map(|p| p.0).collect::<Vec<_>>(), 0.03);
        let y = log_range(all().map(|p| p.1).chain(floor));
        let mut chart = ChartBuilder::on(root)
            .caption("Convergence of the weighted goal", text(26.0))
            .margin(18)
            .x_label_area_size(55)
            .y_label_area_size(85)
            .build_cartesian_2d(x.0..x.1, (y.0..y.1).log_scale())?;
        draw_mesh(
            &mut chart,
            "Simulations run",
            "Best J_pos/σ_pos + J_att/σ_att",
            fmt_count_tick,
            fmt_tick,
        )?;
        if let Some(f) = floor {
            let label = format!("Noise floor: {}", fmt_tick(f));
            let style = FLOOR_GREY.stroke_width(2);
            draw_dashed(&mut chart, vec![(x.0, f), (x.1, f)], style, Some(&label))?;
        }
        for (i, ((label, _), points)) in histories.iter().zip(&steps).enumerate() {
            draw_polyline(
                &mut chart,
                points.iter().copied(),
                colour(i).stroke_width(2),
                Some(label),
            )?;
        }
        if !histories.is_empty() || floor.is_some() {
            let in_log = all().map(|(n, j)| (n, j.log10()));
            let corner = legend_corner(in_log, x, (y.0.log10(), y.1.log10()));
            draw_legend(&mut chart, corner)?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::testing::check_png;

    #[test]
    fn convergence_figure_draws_log_histories() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("convergence.png");
        let ga: Vec<(u64, f64)> = (1..=40).map(|g| (g * 50, 2.0 + 300.0 / g as f64)).collect();
        let nm = [(10, 500.0), (200, 60.0), (900, 9.0), (2000, 3.1)];
        convergence_figure(&path, &[("GA", &ga), ("Nelder-Mead", &nm)], Some(2.0)).unwrap();
        check_png(&path, (1000, 700));
    }

    #[test]
    fn convergence_figure_survives_nan_zero_and_empty() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("convergence.png");
        let odd = [(5, f64::NAN), (3, 0.0), (9, -1.0), (12, 4.0)];
        convergence_figure(&path, &[("odd", &odd), ("empty", &[])], Some(f64::NAN)).unwrap();
        check_png(&path, (1000, 700));
        convergence_figure(&path, &[], None).unwrap();
        check_png(&path, (1000, 700));
        let constant = [(7, 3.0), (7, 3.0)];
        convergence_figure(&path, &[("constant", &constant)], None).unwrap();
        check_png(&path, (1000, 700));
    }
}
