//! The Pareto fronts of the two goals, with the measurement noise floor.

use std::path::Path;

use plotters::prelude::*;

use super::FigureError;
use super::kit::{
    FLOOR_GREY, colour, draw_dashed, draw_legend, draw_mesh, fmt_tick, legend_corner, linear_chart,
    padded_range_from_zero, plottable, plottable_point, render,
};

/// Pareto fronts (J_pos \[m\] on x, J_att \[deg\] on y), one colour per method, each front as
/// points joined in order of J_pos, with the noise floor `(sigma_pos_m, sigma_att_deg)` drawn
/// as grey dashed lines when given (a front below it fits the noise). 1000 × 700 px.
pub fn pareto_figure(
    path: &Path,
    fronts: &[(&str, &[[f64; 2]])],
    noise_floor: Option<(f64, f64)>,
) -> Result<(), FigureError> {
    let sorted: Vec<Vec<(f64, f64)>> = fronts
        .iter()
        .map(|(_, points)| {
            let mut p: Vec<(f64, f64)> = points
                .iter()
                .map(|p| (p[0], p[1]))
                .filter(|p| plottable_point(*p))
                .collect();
            p.sort_by(|a, b| a.0.total_cmp(&b.0));
            p
        })
        .collect();
    let floor = noise_floor.filter(|&(p, a)| plottable(p) && plottable(a));
    render(path, (1000, 700), |root| {
        let all = || sorted.iter().flatten().copied();
        let xs = all().map(|p| p.0).chain(floor.map(|f| f.0));
        let ys = all().map(|p| p.1).chain(floor.map(|f| f.1));
        let x = padded_range_from_zero(xs.collect::<Vec<_>>(), 0.06);
        let y = padded_range_from_zero(ys.collect::<Vec<_>>(), 0.06);
        let mut chart = linear_chart(root, "Pareto fronts of the two goals", 26.0, x, y)?;
        draw_mesh(
            &mut chart,
            "Position goal J_pos [m]",
            "Attitude goal J_att [deg]",
            fmt_tick,
            fmt_tick,
        )?;
        if let Some((sp, sa)) = floor {
            let style = FLOOR_GREY.stroke_width(2);
            let label = format!(
                "Noise floor (σ_pos = {} m, σ_att = {} deg)",
                fmt_tick(sp),
                fmt_tick(sa)
            );
            draw_dashed(&mut chart, vec![(sp, y.0), (sp, y.1)], style, Some(&label))?;
            draw_dashed(&mut chart, vec![(x.0, sa), (x.1, sa)], style, None)?;
        }
        for (i, ((label, _), points)) in fronts.iter().zip(&sorted).enumerate() {
            let c = colour(i);
            chart.draw_series(std::iter::once(PathElement::new(
                points.clone(),
                c.stroke_width(1),
            )))?;
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 4, c.filled())))?
                .label(*label)
                .legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (22, 0)], c.stroke_width(1))
                        + Circle::new((11, 0), 4, c.filled())
                });
        }
        if !fronts.is_empty() || floor.is_some() {
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
    fn pareto_figure_draws_fronts_and_floor() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("pareto.png");
        let ga: Vec<[f64; 2]> = (0..12)
            .map(|i| {
                let a = f64::from(i) / 11.0;
                [0.05 + 0.3 * a, 0.4 + 2.0 * (1.0 - a).powi(2)]
            })
            .collect();
        let nm = [[0.2, 0.9], [0.12, 1.5], [0.35, 0.6]];
        pareto_figure(
            &path,
            &[("GA", &ga), ("Nelder-Mead", &nm)],
            Some((0.05, 0.5)),
        )
        .unwrap();
        check_png(&path, (1000, 700));
    }

    #[test]
    fn pareto_figure_survives_nan_and_empty() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("pareto.png");
        let odd = [[f64::NAN, 1.0], [0.1, f64::INFINITY], [0.2, 0.3]];
        pareto_figure(
            &path,
            &[("odd", &odd), ("empty", &[])],
            Some((f64::NAN, 0.5)),
        )
        .unwrap();
        check_png(&path, (1000, 700));
        pareto_figure(&path, &[], None).unwrap();
        check_png(&path, (1000, 700));
    }
}
