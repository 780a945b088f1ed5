//! Throughput: simulations per second against worker count, per transport.

use std::path::Path;

use plotters::prelude::*;

use super::FigureError;
use super::kit::{
    FLOOR_GREY, colour, draw_dashed, draw_legend, draw_mesh, draw_polyline, fmt_count_tick,
    fmt_tick, legend_corner, linear_chart, padded_range_from_zero, plottable, plottable_point,
    render,
};

/// Throughput benchmark: simulations per second against worker count, one line per transport
/// (points at the measurements), with a grey dashed ideal-scaling line (1-worker value × worker
/// count) from the 1-worker value of the first transport, when it has one. 1000 × 700 px.
pub fn throughput_figure(
    path: &Path,
    series: &[(&str, &[(usize, f64)])],
) -> Result<(), FigureError> {
    let lines: Vec<Vec<(f64, f64)>> = series
        .iter()
        .map(|(_, s)| {
            let mut p: Vec<(f64, f64)> = s.iter().map(|&(w, r)| (w as f64, r)).collect();
            p.sort_by(|a, b| a.0.total_cmp(&b.0));
            p
        })
        .collect();
    // Ideal scaling from the one-thread lane evaluator (`single`) when measured (the `scalar`
    // row is a reference, not what workers run), else from the first series.
    let reference = series
        .iter()
        .position(|(name, _)| *name == "single")
        .unwrap_or(0);
    let base = series.get(reference).and_then(|(_, s)| {
        s.iter()
            .find(|&&(w, r)| w == 1 && plottable(r) && r > 0.0)
            .map(|&(_, r)| r)
    });
    render(path, (1000, 700), |root| {
        let all = || {
            lines
                .iter()
                .flatten()
                .copied()
                .filter(|p| plottable_point(*p))
        };
        let most_workers = all().map(|p| p.0).fold(1.0, f64::max);
        let x = (0.0, most_workers + 0.5);
        let ideal = base.map(|b| vec![(1.0, b), (most_workers, b * most_workers)]);
        let ideal_y = ideal.iter().flatten().map(|p| p.1);
        let y = padded_range_from_zero(all().map(|p| p.1).chain(ideal_y).collect::<Vec<_>>(), 0.06);
        let mut chart = linear_chart(root, "Throughput against worker count", 26.0, x, y)?;
        draw_mesh(
            &mut chart,
            "Workers",
            "Simulations per second [1/s]",
            fmt_count_tick,
            fmt_tick,
        )?;
        if let (Some(points), Some((first, _))) = (ideal, series.get(reference)) {
            let label = format!("Ideal scaling (from {first} at 1 worker)");
            draw_dashed(&mut chart, points, FLOOR_GREY.stroke_width(2), Some(&label))?;
        }
        for (i, ((label, _), points)) in series.iter().zip(&lines).enumerate() {
            let c = colour(i);
            draw_polyline(
                &mut chart,
                points.iter().copied(),
                c.stroke_width(2),
                Some(label),
            )?;
            chart.draw_series(
                points
                    .iter()
                    .filter(|p| plottable_point(**p))
                    .map(|&p| Circle::new(p, 4, c.filled())),
            )?;
        }
        if !series.is_empty() {
            draw_legend(&mut chart, legend_corner(all(), x, y))?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::testing::check_png;

    #[test]
    fn throughput_figure_draws_lines_and_ideal() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("throughput.png");
        let channels = [(1, 950.0), (2, 1800.0), (4, 3300.0), (8, 5200.0)];
        let tcp = [(1, 900.0), (2, 1650.0), (4, 2900.0), (8, 4100.0)];
        throughput_figure(&path, &[("in-process", &channels), ("tcp", &tcp)]).unwrap();
        check_png(&path, (1000, 700));
    }

    #[test]
    fn throughput_figure_survives_nan_and_empty() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("throughput.png");
        let odd = [(1, f64::NAN), (2, 100.0), (0, f64::INFINITY)];
        throughput_figure(&path, &[("odd", &odd), ("empty", &[])]).unwrap();
        check_png(&path, (1000, 700));
        throughput_figure(&path, &[]).unwrap();
        check_png(&path, (1000, 700));
        throughput_figure(&path, &[("one", &[(1, 10.0)])]).unwrap();
        check_png(&path, (1000, 700));
    }
}
