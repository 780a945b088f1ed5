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
//! - [`increment_figure`]: what force and moment a fitted model lacks, as reconstructed
//!   coefficient increments per axis with ±2σ bands, beside what the found model terms give.
//! - [`correlation_figure`]: a heat map of a correlation matrix (for example of the fitted
//!   factors over the final population).
//! - [`throughput_figure`]: simulations per second against worker count, per transport.
//! - [`condition_map`]: a score over a grid of conditions (a plan's separation), the best cell
//!   outlined; [`channel_figure`]: several models' predicted trajectories, six channels.
//! - [`band_figure`]: a predicted release with its bands, six channels, a flown release over
//!   them.
//! - [`envelope_map`]: a per-condition value over a grid of flight conditions (the probability
//!   of too small a clearance, or a low percentile of it) coloured by which side of the
//!   criterion is [`Safety`], the criterion's contour ([`contour_segments`], marching squares)
//!   over it and the releases flown marked.
//! - [`correction_figure`]: what an update changed in a store's data, each correction along
//!   its variable with its band, the range the releases explored and the evidence.
//! - [`clearance_figure`]: the clearance between a store and the aircraft against time, one
//!   line per release, the criterion, each release's smallest clearance counted, the time the
//!   ejector holds the store shaded, and a panel near the criterion when the clearances span
//!   metres.
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
//!   (factor names and ranges, residual sets and times, an increment's times, values and
//!   standard deviations, a square correlation matrix) are checked and refused with
//!   [`FigureError::Input`]. Within a [`Track`] the samples are paired up to the shortest
//!   of its vectors.
//! - Colours follow label order: the i-th fit, method, residual set, event or transport always
//!   gets the i-th colour of one ten-colour palette (Tableau 10); measured data, the truth and
//!   found model terms are black, noise floors grey.
//!
//! Layout: the plotting kit every figure is drawn with (font, rendering and PNG encoding,
//! ranges, ticks, palette, legends, lines and marks) is the private submodule `kit`; each
//! figure family has a submodule of its own (`trajectory`, `factors`, `pareto`,
//! `convergence`, `residuals`, `increments`, `correlation`, `throughput`, `condition_map`,
//! `channels`, `bands`, `envelope_map` with its colour scale `envelope_scale`, `clearance`)
//! whose function is re-exported here; `contour` computes contours for the maps.

use std::path::{Path, PathBuf};

mod bands;
mod channels;
mod clearance;
mod condition_map;
mod contour;
mod convergence;
mod corrections;
mod correlation;
mod envelope_map;
mod envelope_scale;
mod factors;
mod increments;
mod input;
mod kit;
mod pareto;
mod residuals;
mod state_counts;
mod state_map;
#[cfg(test)]
mod testing;
mod throughput;
mod trajectory;

pub use bands::{Band, band_figure};
pub use channels::channel_figure;
pub use clearance::{ClearanceSeries, clearance_figure};
pub use condition_map::{MapAxis, condition_map};
pub use contour::{GridError, Segment, contour_segments, row_crossings};
pub use convergence::convergence_figure;
pub use corrections::{CorrectionPanel, correction_figure};
pub use correlation::correlation_figure;
pub use envelope_map::{EnvelopeMap, envelope_map};
pub use envelope_scale::Safety;
pub use factors::factor_figure;
pub use increments::{IncrementPanel, IncrementSeries, increment_figure};
pub use input::FigureInput;
pub use pareto::pareto_figure;
pub use residuals::residual_figure;
pub use state_counts::{RoundCounts, state_counts_figure};
pub use state_map::state_map;
pub use throughput::throughput_figure;
pub use trajectory::trajectory_figures;

/// A trajectory as the figures draw it, plain data borrowed from whoever computed it: the
/// samples are paired up to the shortest of the three.
#[derive(Debug, Clone, Copy, Default)]
pub struct Track<'a> {
    /// Sample times \[s\].
    pub times_s: &'a [f64],
    /// Launch-frame positions (x, y, z; z down) \[m\].
    pub pos_m: &'a [[f64; 3]],
    /// Euler angles (roll, pitch, yaw) \[deg\].
    pub att_deg: &'a [[f64; 3]],
}

/// A labelled trajectory to draw beside the measured data.
#[derive(Debug, Clone, Copy)]
pub struct Series<'a> {
    /// The legend label (for example the method that found the fit).
    pub label: &'a str,
    /// The trajectory (for example the simulation with the fitted factors).
    pub traj: Track<'a>,
}

/// Failure to draw or write a figure. Every variant names the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FigureError {
    /// The inputs do not fit together (for example fewer names than factors).
    #[error("{}: {reason}", path.display())]
    Input {
        /// The figure file.
        path: PathBuf,
        /// What does not fit.
        reason: FigureInput,
    },
    /// The embedded font could not be loaded.
    #[error("{}: cannot load the embedded font DejaVuSans.ttf", path.display())]
    Font {
        /// The figure file.
        path: PathBuf,
    },
    /// The plotting library failed to draw the figure (its words: plotters' error borrows the
    /// image being drawn, and a panic carries text only).
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
    #[error("{}: cannot write", path.display())]
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

#[cfg(test)]
mod tests {
    use super::testing::trajectory;
    use super::*;

    #[test]
    fn missing_directory_is_an_error_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("no-such-dir");
        let err = trajectory_figures(&missing, trajectory(1.0).track(), &[]).unwrap_err();
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
}
