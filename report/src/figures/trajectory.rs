//! Figures 1-6 of Anderson's study: pitch, yaw, roll, downrange, crossrange and altitude
//! against time, the flight data as points and each fit as a line.

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::kit::{
    colour, draw_legend, draw_mesh, draw_polyline, fmt_tick, legend_corner, linear_chart,
    padded_range, plottable_point, render,
};
use super::{FigureError, Series, Track};

/// One channel of Figures 1-6.
struct Channel {
    file: &'static str,
    title: &'static str,
    y_desc: &'static str,
    /// The plotted value from a position \[m\] and attitude \[deg\].
    value: fn(&[f64; 3], &[f64; 3]) -> f64,
}

const CHANNELS: [Channel; 6] = [
    Channel {
        file: "fig1_pitch.png",
        title: "Figure 1. Pitch angle against time",
        y_desc: "Pitch θ [deg]",
        value: |_, att| att[1],
    },
    Channel {
        file: "fig2_yaw.png",
        title: "Figure 2. Yaw angle against time",
        y_desc: "Yaw ψ [deg]",
        value: |_, att| att[2],
    },
    Channel {
        file: "fig3_roll.png",
        title: "Figure 3. Roll angle against time",
        y_desc: "Roll φ [deg]",
        value: |_, att| att[0],
    },
    Channel {
        file: "fig4_downrange.png",
        title: "Figure 4. Downrange displacement against time",
        y_desc: "Downrange x [m]",
        value: |pos, _| pos[0],
    },
    Channel {
        file: "fig5_crossrange.png",
        title: "Figure 5. Crossrange displacement against time",
        y_desc: "Crossrange y [m]",
        value: |pos, _| pos[1],
    },
    Channel {
        file: "fig6_altitude.png",
        title: "Figure 6. Altitude (−z) against time",
        y_desc: "Altitude −z [m]",
        value: |pos, _| -pos[2],
    },
];

/// The (time \[s\], value) samples of one channel of a trajectory, paired up to the shortest of
/// its vectors.
fn channel_samples(traj: Track<'_>, channel: &Channel) -> Vec<(f64, f64)> {
    traj.times_s
        .iter()
        .zip(traj.pos_m)
        .zip(traj.att_deg)
        .map(|((&t, pos), att)| (t, (channel.value)(pos, att)))
        .collect()
}

/// Anderson's study Figures 1-6: pitch, yaw, roll, downrange, crossrange and altitude (= -z)
/// against time: the flight data as points, each fit as a line. Files `fig1_pitch.png`,
/// `fig2_yaw.png`, `fig3_roll.png`, `fig4_downrange.png`, `fig5_crossrange.png`,
/// `fig6_altitude.png` in `dir` (1000 × 700 px). Returns the paths written.
///
/// Positions are in metres (x downrange, y crossrange, z down; altitude is drawn as −z),
/// angles in degrees. Stops at the first figure that cannot be written.
pub fn trajectory_figures(
    dir: &Path,
    data: Track<'_>,
    fits: &[Series<'_>],
) -> Result<Vec<PathBuf>, FigureError> {
    let mut written = Vec::with_capacity(CHANNELS.len());
    for channel in &CHANNELS {
        let path = dir.join(channel.file);
        let measured = channel_samples(data, channel);
        let fitted: Vec<Vec<(f64, f64)>> = fits
            .iter()
            .map(|f| channel_samples(f.traj, channel))
            .collect();
        render(&path, (1000, 700), |root| {
            let all = || measured.iter().chain(fitted.iter().flatten()).copied();
            let x = padded_range(all().map(|p| p.0), 0.02);
            let y = padded_range(all().map(|p| p.1), 0.08);
            let mut chart = linear_chart(root, channel.title, 26.0, x, y)?;
            draw_mesh(&mut chart, "Time [s]", channel.y_desc, fmt_tick, fmt_tick)?;
            for (i, (fit, points)) in fits.iter().zip(&fitted).enumerate() {
                let style = colour(i).stroke_width(2);
                draw_polyline(&mut chart, points.iter().copied(), style, Some(fit.label))?;
            }
            let data_style = BLACK.stroke_width(1);
            chart
                .draw_series(
                    measured
                        .iter()
                        .filter(|p| plottable_point(**p))
                        .map(|&p| Circle::new(p, 3, data_style)),
                )?
                .label("Flight data")
                .legend(move |(x, y)| Circle::new((x + 11, y), 3, data_style));
            draw_legend(&mut chart, legend_corner(all(), x, y))
        })?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::testing::{Samples, check_png, dark_pixels, trajectory};

    #[test]
    fn trajectory_figures_writes_six_pngs() {
        let dir = tempfile::tempdir().unwrap();
        let data = trajectory(1.0);
        let (fit_a, fit_b) = (trajectory(1.05), trajectory(0.9));
        let fits = [
            Series {
                label: "GA",
                traj: fit_a.track(),
            },
            Series {
                label: "Nelder-Mead",
                traj: fit_b.track(),
            },
        ];
        let paths = trajectory_figures(dir.path(), data.track(), &fits).unwrap();
        let names: Vec<String> = paths
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            names,
            [
                "fig1_pitch.png",
                "fig2_yaw.png",
                "fig3_roll.png",
                "fig4_downrange.png",
                "fig5_crossrange.png",
                "fig6_altitude.png"
            ]
        );
        for path in &paths {
            assert_eq!(path.parent(), Some(dir.path()));
            check_png(path, (1000, 700));
        }
        // The title is text in the embedded font: dark pixels in the top rows.
        assert!(dark_pixels(&paths[0], 0..50) > 200);
    }

    #[test]
    fn trajectory_figures_survive_nan_empty_and_constant_data() {
        let dir = tempfile::tempdir().unwrap();
        let mut data = trajectory(1.0);
        data.pos_m[3][0] = f64::NAN;
        data.att_deg[7] = [f64::INFINITY, f64::NAN, f64::NEG_INFINITY];
        data.times_s[10] = f64::NAN;
        let empty = Samples::default();
        let mut constant = trajectory(1.0);
        for p in &mut constant.pos_m {
            *p = [1.0, 1.0, 1.0];
        }
        let mut short = trajectory(1.0);
        short.att_deg.truncate(5);
        let fits = [
            Series {
                label: "empty",
                traj: empty.track(),
            },
            Series {
                label: "constant",
                traj: constant.track(),
            },
            Series {
                label: "short",
                traj: short.track(),
            },
        ];
        for path in trajectory_figures(dir.path(), data.track(), &fits).unwrap() {
            check_png(&path, (1000, 700));
        }
        // Nothing at all to draw still gives figures with axes.
        let dir2 = tempfile::tempdir().unwrap();
        for path in trajectory_figures(dir2.path(), empty.track(), &[]).unwrap() {
            check_png(&path, (1000, 700));
        }
    }
}
