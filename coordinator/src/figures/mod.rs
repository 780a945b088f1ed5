//! Figures: PNG plots of fitted trajectories, found factors, Pareto fronts, convergence,
//! residuals, factor correlations and worker throughput.
//!
//! The trajectory and factor figures follow M. B. Anderson's store-separation GA study,
//! Figures 1-7:
//! - [`trajectory_figures`] draws Figures 1-6: pitch, yaw, roll, downrange, crossrange and
//!   altitude against time, the flight data as points and each fitted simulation as a line.
//! - [`factor_figure`] draws Figure 7: the factors each method found beside the true ones, every
//!   factor normalised to its search range so that factors of different units share one axis.
//!
//! The others show how a fit went and what is left of it:
//! - [`pareto_figure`]: the Pareto fronts of the two goals (position and attitude error), with
//!   the measurement noise floor below which no fit can honestly go.
//! - [`convergence_figure`]: the best weighted goal against the number of simulations run.
//! - [`residual_figure`]: simulated minus measured for the six channels, with the noise bands.
//! - [`correlation_figure`]: a heat map of a correlation matrix (for example of the fitted
//!   factors over the final population).
//! - [`throughput_figure`]: simulations per second against worker count, per transport.
//!
//! Choices made here:
//! - Rendering needs no system library and no installed font: `plotters` draws into an in-memory
//!   RGB buffer, its text drawn with `ab_glyph` from DejaVu Sans, which is embedded in the binary
//!   (`assets/fonts/DejaVuSans.ttf`, licence beside it), and the PNG is encoded by the pure-Rust
//!   `png` crate. Files are written atomically (a temporary file in the target directory, then
//!   renamed), so a failed figure never leaves a partial file.
//! - Odd data never panics: values that are not finite (or beyond ±1e100, which no axis can
//!   show) are skipped, a line is broken where they were; empty series draw empty axes;
//!   degenerate axis ranges (one value, or none) are widened. Inputs whose lengths must agree
//!   (factor names and ranges, residual sets and times, a square correlation matrix) are
//!   checked and refused with [`FigureError::Input`]. Within a [`Trajectory`] the samples are
//!   paired up to the shortest of its vectors.
//! - Colours follow label order: the i-th fit, method, residual set or transport always gets
//!   the i-th colour of one ten-colour palette (Tableau 10); measured data and the truth are
//!   black, noise floors grey.

use std::path::{Path, PathBuf};

use plotters::prelude::*;
use plotters::style::FontTransform;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use sepval_common::telemetry::Trajectory;

mod kit;

use kit::{
    DrawResult, FLOOR_GREY, Root, box_mark, colour, draw_dashed, draw_legend, draw_mesh,
    draw_polyline, estimate_width, fmt_count_tick, fmt_tick, legend_corner, line_mark,
    linear_chart, log_range, padded_range, padded_range_from_zero, plottable, plottable_point,
    render, text,
};

/// A labelled trajectory to draw beside the measured data.
#[derive(Debug, Clone, Copy)]
pub struct Series<'a> {
    /// The legend label (for example the method that found the fit).
    pub label: &'a str,
    /// The trajectory (for example the simulation with the fitted factors).
    pub traj: &'a Trajectory,
}

/// Failure to draw or write a figure. Every variant names the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FigureError {
    /// The inputs do not fit together (for example fewer names than factors).
    #[error("{}: {message}", path.display())]
    Input {
        /// The figure file.
        path: PathBuf,
        /// What does not fit.
        message: String,
    },
    /// The embedded font could not be loaded.
    #[error("{}: cannot load the embedded font DejaVuSans.ttf", path.display())]
    Font {
        /// The figure file.
        path: PathBuf,
    },
    /// The plotting library failed to draw the figure.
    #[error("{}: cannot draw the figure: {message}", path.display())]
    Draw {
        /// The figure file.
        path: PathBuf,
        /// The cause.
        message: String,
    },
    /// The image could not be encoded as PNG.
    #[error("{}: cannot encode the PNG: {message}", path.display())]
    Encode {
        /// The figure file.
        path: PathBuf,
        /// The cause.
        message: String,
    },
    /// The file could not be written (for example because its directory does not exist).
    #[error("{}: cannot write: {source}", path.display())]
    Write {
        /// The figure file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
}

impl FigureError {
    /// The figure file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            Self::Input { path, .. }
            | Self::Font { path }
            | Self::Draw { path, .. }
            | Self::Encode { path, .. }
            | Self::Write { path, .. } => path,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Figures 1-6: trajectories.

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
fn channel_samples(traj: &Trajectory, channel: &Channel) -> Vec<(f64, f64)> {
    traj.times_s
        .iter()
        .zip(&traj.pos_m)
        .zip(&traj.att_deg)
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
    data: &Trajectory,
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

// ---------------------------------------------------------------------------------------------
// Figure 7: factors.

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
    let n = names.len();
    let input_error = |message: String| FigureError::Input {
        path: path.to_path_buf(),
        message,
    };
    if ranges.len() != n {
        return Err(input_error(format!(
            "{} factor names but {} ranges",
            n,
            ranges.len()
        )));
    }
    for (label, values) in methods {
        if values.len() != n {
            return Err(input_error(format!(
                "method {label:?} gives {} values for {n} factors",
                values.len()
            )));
        }
    }
    if let Some(given) = truth.map(<[f64]>::len).filter(|&len| len != n) {
        return Err(input_error(format!(
            "the truth gives {given} values for {n} factors"
        )));
    }
    let normalised: Vec<Vec<Option<f64>>> = methods
        .iter()
        .map(|(_, values)| {
            values
                .iter()
                .zip(ranges)
                .map(|(&v, &r)| normalise(v, r))
                .collect()
        })
        .collect();
    let truth_normalised: Option<Vec<Option<f64>>> = truth.map(|t| {
        t.iter()
            .zip(ranges)
            .map(|(&v, &r)| normalise(v, r))
            .collect()
    });
    let all_values = normalised
        .iter()
        .flatten()
        .chain(truth_normalised.iter().flatten())
        .flatten()
        .copied();
    let (vmin, vmax) = all_values.fold((0.0f64, 1.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let width = (200 + 60 * n).clamp(1000, 2000) as u32;
    let label_size = 15.0;

    // Room for the names: horizontal when each fits its group, vertical otherwise.
    let name_widths: Vec<u32> = names
        .iter()
        .map(|name| estimate_width(name, label_size))
        .collect();
    let widest = name_widths.iter().copied().max().unwrap_or(0);
    let group_px = (width.saturating_sub(140)) / (n.max(1) as u32);
    let vertical = widest + 8 > group_px;
    let label_area = if vertical {
        (widest + 24).clamp(40, 260)
    } else {
        40
    };
    let height = 660 + label_area;
    // Headroom above the bars for the legend (upper right), about 24 px an entry.
    let entries = methods.len() + usize::from(truth.is_some());
    let plot_px = f64::from(height - label_area - 110);
    let free = if entries > 0 {
        ((24.0 * entries as f64 + 34.0) / plot_px).min(0.6)
    } else {
        0.0
    };
    let lo = vmin - 0.05 * (vmax - vmin);
    let top = vmax + 0.03 * (vmax - vmin);
    let y = (lo, lo + (top - lo) / (1.0 - free));

    render(path, (width, height), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                "Figure 7. Factors found by each method, normalised to their ranges",
                text(26.0),
            )
            .margin(18)
            .x_label_area_size(label_area)
            .y_label_area_size(85)
            .build_cartesian_2d(-0.5..(n.max(1) as f64 - 0.5), y.0..y.1)?;
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
        // The ends of the search ranges.
        let x_ends = (-0.5, n.max(1) as f64 - 0.5);
        for level in [0.0, 1.0] {
            draw_dashed(
                &mut chart,
                vec![(x_ends.0, level), (x_ends.1, level)],
                RGBColor(150, 150, 150).stroke_width(1),
                None,
            )?;
        }
        let m = methods.len().max(1) as f64;
        let bar = 0.8 / m;
        for (j, ((label, _), values)) in methods.iter().zip(&normalised).enumerate() {
            let style = colour(j).filled();
            let bars: Vec<Rectangle<(f64, f64)>> = values
                .iter()
                .enumerate()
                .filter_map(|(i, v)| {
                    let v = (*v)?;
                    let x0 = i as f64 - 0.4 + j as f64 * bar;
                    Some(Rectangle::new([(x0, 0.0), (x0 + bar * 0.92, v)], style))
                })
                .collect();
            chart
                .draw_series(bars)?
                .label(*label)
                .legend(box_mark(style));
        }
        if let Some(truth) = &truth_normalised {
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
        // Factor names under their groups.
        let style = text(label_size);
        // Every name while they fit side by side, else every `step`-th.
        let step = (16 / group_px.max(1) + 1) as usize;
        for (i, name) in names.iter().enumerate().step_by(step) {
            let (px, py) = chart.backend_coord(&(i as f64, y.0));
            if vertical {
                let style = style
                    .transform(FontTransform::Rotate270)
                    .pos(Pos::new(HPos::Right, VPos::Center));
                root.draw(&Text::new(*name, (px, py + 8), style))?;
            } else {
                let style = style.pos(Pos::new(HPos::Center, VPos::Top));
                root.draw(&Text::new(*name, (px, py + 10), style))?;
            }
        }
        if entries > 0 {
            draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        }
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------------
// Pareto fronts and convergence.

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

// ---------------------------------------------------------------------------------------------
// Residuals.

/// The six residual channels: caption, unit, whether the channel is a position.
const RESIDUAL_CHANNELS: [(&str, &str, bool); 6] = [
    ("x (downrange)", "m", true),
    ("y (crossrange)", "m", true),
    ("z (down)", "m", true),
    ("Roll φ", "deg", false),
    ("Pitch θ", "deg", false),
    ("Yaw ψ", "deg", false),
];

/// A legend mark in a legend strip.
enum Mark {
    Line(RGBColor),
    Band(RGBColor),
}

/// Draws a one-row legend centred in `area`.
fn draw_legend_strip(area: &Root<'_>, entries: &[(String, Mark)]) -> DrawResult {
    let style = text(17.0);
    let (w, h) = area.dim_in_pixel();
    let widths: Vec<i32> = entries
        .iter()
        .map(|(label, _)| area.estimate_text_size(label, &style).map(|s| s.0 as i32))
        .collect::<Result<_, _>>()?;
    let gap = 30;
    let mark = 30;
    let total: i32 =
        widths.iter().map(|w| w + mark + 8).sum::<i32>() + gap * (entries.len() as i32 - 1).max(0);
    let mut x = ((w as i32 - total) / 2).max(4);
    let y = h as i32 / 2;
    for ((label, m), width) in entries.iter().zip(widths) {
        match m {
            Mark::Line(c) => area.draw(&PathElement::new(
                vec![(x, y), (x + mark, y)],
                c.stroke_width(3),
            ))?,
            Mark::Band(c) => {
                area.draw(&Rectangle::new([(x, y - 8), (x + mark, y + 8)], c.filled()))?
            }
        }
        let style = style.pos(Pos::new(HPos::Left, VPos::Center));
        area.draw(&Text::new(label.as_str(), (x + mark + 8, y), style))?;
        x += mark + 8 + width + gap;
    }
    Ok(())
}

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
                message: format!(
                    "residual set {label:?} has {} samples for {} times",
                    values.len(),
                    times_s.len()
                ),
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
        let mut entries: Vec<(String, Mark)> = sets
            .iter()
            .enumerate()
            .map(|(i, (label, _))| ((*label).to_string(), Mark::Line(colour(i))))
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
                Mark::Band(BAND),
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

// ---------------------------------------------------------------------------------------------
// Correlation matrix.

/// The most rows and columns a correlation figure draws (2 px a cell).
const MAX_CORRELATION_NAMES: usize = 450;

/// The diverging colour of a correlation: dark blue at −1, near white at 0, dark red at +1
/// (ColorBrewer RdBu); grey when not finite.
fn diverging(rho: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (-1.0, [5.0, 48.0, 97.0]),
        (-0.5, [67.0, 147.0, 195.0]),
        (0.0, [247.0, 247.0, 247.0]),
        (0.5, [214.0, 96.0, 77.0]),
        (1.0, [103.0, 0.0, 31.0]),
    ];
    if !rho.is_finite() {
        return RGBColor(170, 170, 170);
    }
    let r = rho.clamp(-1.0, 1.0);
    let k = (((r + 1.0) * 2.0).floor() as usize).min(3);
    let (r0, c0) = STOPS[k];
    let (r1, c1) = STOPS[k + 1];
    let f = (r - r0) / (r1 - r0);
    let mix = |i: usize| (c0[i] + f * (c1[i] - c0[i])).round().clamp(0.0, 255.0) as u8;
    RGBColor(mix(0), mix(1), mix(2))
}

/// A correlation matrix heat map (values in [−1, 1], diverging colours: blue negative, red
/// positive; a value outside is drawn at the end colour, one that is not finite in grey), the
/// value printed in each cell when n ≤ 24, rows and columns labelled with `names` (every k-th
/// when the cells are too small for all), a colour bar on the right. At least 800 × 600 px:
/// cells of 2 to 90 px, the matrix 900 px at most; at most 450 names.
pub fn correlation_figure(
    path: &Path,
    names: &[&str],
    rho: &[Vec<f64>],
    title: &str,
) -> Result<(), FigureError> {
    let n = names.len();
    if rho.len() != n || rho.iter().any(|row| row.len() != n) {
        let shape: Vec<usize> = rho.iter().map(Vec::len).collect();
        return Err(FigureError::Input {
            path: path.to_path_buf(),
            message: format!(
                "the correlation matrix must be {n} × {n} for {n} names, found {} rows of lengths {shape:?}",
                rho.len()
            ),
        });
    }
    if n > MAX_CORRELATION_NAMES {
        return Err(FigureError::Input {
            path: path.to_path_buf(),
            message: format!(
                "{n} names: a correlation figure draws at most {MAX_CORRELATION_NAMES}"
            ),
        });
    }
    let cell = if n == 0 {
        40
    } else {
        (900 / n as u32).clamp(2, 90)
    };
    let grid = cell * n as u32;
    let name_size = (f64::from(cell) * 0.45).clamp(9.0, 16.0);
    let value_size = (f64::from(cell) * 0.3).clamp(8.0, 16.0);
    let widest = names
        .iter()
        .map(|s| estimate_width(s, name_size))
        .max()
        .unwrap_or(0)
        .min(300);
    let (left, top) = ((widest + 30).max(60), 80u32);
    let bottom = (widest + 30).max(60);
    let bar_area = 130u32;
    let content = left + grid + bar_area;
    let width = content.max(800);
    let height = (top + grid + bottom).max(600);
    render(path, (width, height), |root| {
        let title_style = text(26.0).pos(Pos::new(HPos::Center, VPos::Center));
        root.draw(&Text::new(title, (width as i32 / 2, 36), title_style))?;
        let x0 = (left + (width - content) / 2) as i32;
        let (y0, c) = (top as i32, cell as i32);
        if n == 0 {
            let style = text(18.0).pos(Pos::new(HPos::Center, VPos::Center));
            root.draw(&Text::new(
                "(no factors)",
                (width as i32 / 2, height as i32 / 2),
                style,
            ))?;
        }
        for (i, row) in rho.iter().enumerate() {
            for (j, &v) in row.iter().enumerate() {
                let (cx, cy) = (x0 + j as i32 * c, y0 + i as i32 * c);
                root.draw(&Rectangle::new(
                    [(cx, cy), (cx + c, cy + c)],
                    diverging(v).filled(),
                ))?;
                if n <= 24 && v.is_finite() {
                    let ink = if v.abs() > 0.55 { WHITE } else { BLACK };
                    let style = text(value_size)
                        .color(&ink)
                        .pos(Pos::new(HPos::Center, VPos::Center));
                    let s = format!("{:.2}", v.clamp(-99.0, 99.0));
                    root.draw(&Text::new(s, (cx + c / 2, cy + c / 2), style))?;
                }
            }
        }
        // Thin white lines between cells, and a frame.
        if n > 0 && cell >= 16 {
            for k in 1..n as i32 {
                let style = WHITE.stroke_width(1);
                root.draw(&PathElement::new(
                    vec![(x0 + k * c, y0), (x0 + k * c, y0 + n as i32 * c)],
                    style,
                ))?;
                root.draw(&PathElement::new(
                    vec![(x0, y0 + k * c), (x0 + n as i32 * c, y0 + k * c)],
                    style,
                ))?;
            }
        }
        if n > 0 {
            let g = grid as i32;
            root.draw(&Rectangle::new(
                [(x0, y0), (x0 + g, y0 + g)],
                RGBColor(80, 80, 80).stroke_width(1),
            ))?;
        }
        // Every name while they fit side by side, else every `step`-th.
        let step = (9 / cell.max(1) + 1) as usize;
        for (k, name) in names.iter().enumerate().step_by(step) {
            let mid = k as i32 * c + c / 2;
            let row_style = text(name_size).pos(Pos::new(HPos::Right, VPos::Center));
            root.draw(&Text::new(*name, (x0 - 8, y0 + mid), row_style))?;
            let col_style = text(name_size)
                .transform(FontTransform::Rotate270)
                .pos(Pos::new(HPos::Right, VPos::Center));
            root.draw(&Text::new(
                *name,
                (x0 + mid, y0 + grid as i32 + 8),
                col_style,
            ))?;
        }
        // Colour bar.
        let bar_h = (grid as i32).clamp(200, 500);
        let (bx, by) = (x0 + grid as i32 + 40, y0 + (grid as i32 - bar_h).max(0) / 2);
        for p in 0..bar_h {
            let v = 1.0 - 2.0 * f64::from(p) / f64::from(bar_h - 1);
            root.draw(&PathElement::new(
                vec![(bx, by + p), (bx + 24, by + p)],
                diverging(v).stroke_width(1),
            ))?;
        }
        root.draw(&Rectangle::new(
            [(bx, by), (bx + 24, by + bar_h)],
            RGBColor(80, 80, 80).stroke_width(1),
        ))?;
        for tick in [-1.0, -0.5, 0.0, 0.5, 1.0] {
            let ty = by + ((1.0 - tick) / 2.0 * f64::from(bar_h - 1)).round() as i32;
            root.draw(&PathElement::new(
                vec![(bx + 24, ty), (bx + 30, ty)],
                BLACK.stroke_width(1),
            ))?;
            let style = text(14.0).pos(Pos::new(HPos::Left, VPos::Center));
            root.draw(&Text::new(fmt_tick(tick), (bx + 34, ty), style))?;
        }
        let style = text(18.0).pos(Pos::new(HPos::Center, VPos::Bottom));
        root.draw(&Text::new("ρ", (bx + 12, by - 10), style))?;
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------------
// Throughput.

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
    let base = series.first().and_then(|(_, s)| {
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
        if let (Some(points), Some((first, _))) = (ideal, series.first()) {
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
    use std::collections::HashSet;
    use std::fs::File;
    use std::io::BufReader;

    /// Decodes a PNG: (width, height, number of distinct colours).
    fn decode(path: &Path) -> (u32, u32, usize) {
        let file = File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut reader = png::Decoder::new(BufReader::new(file)).read_info().unwrap();
        let (w, h) = (reader.info().width, reader.info().height);
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let frame = reader.next_frame(&mut buf).unwrap();
        assert_eq!(frame.color_type, png::ColorType::Rgb);
        let colours: HashSet<&[u8]> = buf[..frame.buffer_size()].chunks_exact(3).collect();
        (w, h, colours.len())
    }

    /// Checks a written figure: a PNG of `size` with more than a few colours, and no temporary
    /// file left beside it.
    fn check_png(path: &Path, size: (u32, u32)) {
        let (w, h, colours) = decode(path);
        assert_eq!((w, h), size, "{}", path.display());
        assert!(colours > 10, "{}: only {colours} colours", path.display());
        let dir = path.parent().unwrap();
        for entry in std::fs::read_dir(dir).unwrap() {
            let name = entry.unwrap().file_name();
            assert!(
                !name.to_string_lossy().starts_with(".sepval-tmp"),
                "temporary file {name:?} left"
            );
        }
    }

    /// Dark pixels in rows `rows` of a figure (text drawn there).
    fn dark_pixels(path: &Path, rows: std::ops::Range<usize>) -> usize {
        let file = File::open(path).unwrap();
        let mut reader = png::Decoder::new(BufReader::new(file)).read_info().unwrap();
        let w = reader.info().width as usize;
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut buf).unwrap();
        buf[rows.start * w * 3..rows.end * w * 3]
            .chunks_exact(3)
            .filter(|p| p.iter().all(|&c| c < 100))
            .count()
    }

    /// A trajectory over 1.2 s at 50 Hz, shaped by `k`.
    fn trajectory(k: f64) -> Trajectory {
        let times_s: Vec<f64> = (0..60).map(|i| f64::from(i) * 0.02).collect();
        let pos_m = times_s
            .iter()
            .map(|&t| [k * 2.0 * t, 0.3 * k * t * t, 4.9 * t * t])
            .collect();
        let att_deg = times_s
            .iter()
            .map(|&t| [10.0 * (3.0 * t).sin(), -8.0 * k * t, 2.0 * t * t])
            .collect();
        Trajectory {
            times_s,
            pos_m,
            att_deg,
            ..Trajectory::default()
        }
    }

    #[test]
    fn trajectory_figures_writes_six_pngs() {
        let dir = tempfile::tempdir().unwrap();
        let data = trajectory(1.0);
        let (fit_a, fit_b) = (trajectory(1.05), trajectory(0.9));
        let fits = [
            Series {
                label: "GA",
                traj: &fit_a,
            },
            Series {
                label: "Nelder-Mead",
                traj: &fit_b,
            },
        ];
        let paths = trajectory_figures(dir.path(), &data, &fits).unwrap();
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
        let empty = Trajectory::default();
        let mut constant = trajectory(1.0);
        for p in &mut constant.pos_m {
            *p = [1.0, 1.0, 1.0];
        }
        let mut short = trajectory(1.0);
        short.att_deg.truncate(5);
        let fits = [
            Series {
                label: "empty",
                traj: &empty,
            },
            Series {
                label: "constant",
                traj: &constant,
            },
            Series {
                label: "short",
                traj: &short,
            },
        ];
        for path in trajectory_figures(dir.path(), &data, &fits).unwrap() {
            check_png(&path, (1000, 700));
        }
        // Nothing at all to draw still gives figures with axes.
        let dir2 = tempfile::tempdir().unwrap();
        for path in trajectory_figures(dir2.path(), &empty, &[]).unwrap() {
            check_png(&path, (1000, 700));
        }
    }

    #[test]
    fn missing_directory_is_an_error_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("no-such-dir");
        let err = trajectory_figures(&missing, &trajectory(1.0), &[]).unwrap_err();
        assert!(matches!(err, FigureError::Write { .. }), "{err:?}");
        assert_eq!(err.path(), missing.join("fig1_pitch.png"));
        assert!(err.to_string().contains("no-such-dir"), "{err}");

        let path = missing.join("pareto.png");
        let err = pareto_figure(&path, &[("GA", &[[1.0, 2.0]][..])], None).unwrap_err();
        assert!(
            err.to_string().contains(&path.display().to_string()),
            "{err}"
        );
        assert!(!missing.exists());
    }

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

    fn decode_size(path: &Path) -> (u32, u32) {
        let (w, h, _) = decode(path);
        (w, h)
    }

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

    #[test]
    fn correlation_figure_draws_a_heat_map() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("correlation.png");
        let names = [
            "C_m_alpha",
            "C_n_beta",
            "C_l_p",
            "ejector_force",
            "cg_x",
            "mass",
        ];
        let n = names.len();
        let rho: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        if i == j {
                            1.0
                        } else {
                            ((i * 7 + j * 3) % 11) as f64 / 5.0 - 1.0
                        }
                    })
                    .collect()
            })
            .collect();
        correlation_figure(&path, &names, &rho, "Factor correlations (GA)").unwrap();
        let (w, h) = decode_size(&path);
        assert!(w >= 700 && h >= 500);
        check_png(&path, (w, h));
        assert!(dark_pixels(&path, 10..60) > 100);
    }

    #[test]
    fn correlation_figure_survives_odd_and_large_matrices_and_refuses_bad_shapes() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("correlation.png");
        let rho = vec![vec![1.0, f64::NAN], vec![f64::INFINITY, -3.0]];
        correlation_figure(&path, &["a", "b"], &rho, "odd").unwrap();
        check_png(&path, decode_size(&path));
        correlation_figure(&path, &[], &[], "empty").unwrap();
        check_png(&path, decode_size(&path));
        let names: Vec<String> = (0..40).map(|i| format!("f{i}")).collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        let rho: Vec<Vec<f64>> = (0..40)
            .map(|i| (0..40).map(|j| ((i as f64) - (j as f64)).cos()).collect())
            .collect();
        correlation_figure(&path, &names, &rho, "large").unwrap();
        check_png(&path, decode_size(&path));
        let names: Vec<String> = (0..300).map(|i| format!("f{i}")).collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        let rho = vec![vec![0.3; 300]; 300];
        correlation_figure(&path, &names, &rho, "very large").unwrap();
        let (w, h) = decode_size(&path);
        assert!(w < 1400 && h < 1400, "{w} x {h}");
        check_png(&path, (w, h));
        let names = vec!["f"; 451];
        let rho = vec![vec![0.0; 451]; 451];
        let err = correlation_figure(&path, &names, &rho, "too large").unwrap_err();
        assert!(matches!(err, FigureError::Input { .. }), "{err:?}");

        let err =
            correlation_figure(&path, &["a", "b"], &[vec![1.0, 0.0], vec![0.0]], "x").unwrap_err();
        assert!(matches!(err, FigureError::Input { .. }), "{err:?}");
        assert!(err.to_string().contains("correlation.png"), "{err}");
    }

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

    #[test]
    fn diverging_colours_run_from_blue_to_red() {
        assert_eq!(diverging(f64::NAN), RGBColor(170, 170, 170));
        assert_eq!(diverging(-1.0), RGBColor(5, 48, 97));
        assert_eq!(diverging(1.0), RGBColor(103, 0, 31));
        assert_eq!(diverging(7.0), RGBColor(103, 0, 31));
    }
}
