//! Several models' predicted trajectories of one release, six channels in one figure (for
//! example the rival explanations of a diagnosis at the condition planned to separate them).

use std::path::Path;

use plotters::prelude::*;

use super::kit::{
    LegendMark, colour, draw_legend_strip, draw_mesh, draw_polyline, fmt_tick, padded_range,
    render, text,
};
use super::{FigureError, FigureInput};

/// The six channels: caption and unit, in the order of a sample's values.
const CHANNELS: [(&str, &str); 6] = [
    ("Downrange x", "m"),
    ("Crossrange y", "m"),
    ("Down z", "m"),
    ("Roll φ", "deg"),
    ("Pitch θ", "deg"),
    ("Yaw ψ", "deg"),
];

/// Trajectories against time for six channels in a 2 × 3 grid (x, y, z \[m\]; roll, pitch,
/// yaw \[deg\]), one line per labelled set, each set one `[x, y, z, roll, pitch, yaw]` per time
/// in `times_s`. 1600 × 1000 px, `title` on top and one legend below it.
pub fn channel_figure(
    path: &Path,
    times_s: &[f64],
    sets: &[(&str, &[[f64; 6]])],
    title: &str,
) -> Result<(), FigureError> {
    for (label, values) in sets {
        if values.len() != times_s.len() {
            return Err(FigureError::Input {
                path: path.to_path_buf(),
                reason: FigureInput::Set {
                    label: label.to_string(),
                    samples: values.len(),
                    times: times_s.len(),
                },
            });
        }
    }
    render(path, (1600, 1000), |root| {
        let (_, body) = root.split_vertically(8);
        let body = body.titled(title, text(28.0))?;
        let (legend, grid) = body.split_vertically(44);
        let entries: Vec<(String, LegendMark)> = sets
            .iter()
            .enumerate()
            .map(|(i, (label, _))| ((*label).to_string(), LegendMark::Line(colour(i))))
            .collect();
        draw_legend_strip(&legend, &entries)?;
        let x = padded_range(times_s.iter().copied(), 0.01);
        for (k, (panel, &(name, unit))) in
            grid.split_evenly((2, 3)).iter().zip(&CHANNELS).enumerate()
        {
            let y = padded_range(sets.iter().flat_map(|(_, v)| v.iter().map(|r| r[k])), 0.08);
            let mut chart = ChartBuilder::on(panel)
                .caption(format!("{name} [{unit}]"), text(20.0))
                .margin(12)
                .x_label_area_size(48)
                .y_label_area_size(80)
                .build_cartesian_2d(x.0..x.1, y.0..y.1)?;
            draw_mesh(
                &mut chart,
                "Time [s]",
                &format!("{name} [{unit}]"),
                fmt_tick,
                fmt_tick,
            )?;
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

    #[test]
    fn six_channels_of_two_sets_are_drawn_and_a_short_set_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let t: Vec<f64> = (0..50).map(|i| i as f64 * 0.02).collect();
        let a: Vec<[f64; 6]> = t
            .iter()
            .map(|&t| [t, 0.1 * t, 2.0 * t * t, 3.0 * t, -t, 0.5])
            .collect();
        let b: Vec<[f64; 6]> = a.iter().map(|r| r.map(|v| 1.1 * v)).collect();
        let path = dir.path().join("m.png");
        channel_figure(&path, &t, &[("answer", &a), ("rival", &b)], "Two models").unwrap();
        check_png(&path, (1600, 1000));
        assert!(dark_pixels(&path, 100..1000) > 1000);
        let e = channel_figure(&path, &t, &[("short", &a[..3])], "x").unwrap_err();
        assert!(e.to_string().contains("3 samples for 50 times"), "{e}");
    }
}
