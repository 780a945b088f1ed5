//! Figure inputs that do not fit together, each naming the series, panel or count that does not
//! and what it should be (the figure's file is named by [`super::FigureError::Input`]).

/// Inputs of a figure that do not fit together.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FigureInput {
    /// A band whose edges are not one per time.
    #[error("band of {channel} has edges of another length than {times} times")]
    BandEdges {
        /// The channel.
        channel: &'static str,
        /// The times.
        times: usize,
    },
    /// Data of another length than the times.
    #[error("data {label:?} has {samples} samples for {times} times")]
    Data {
        /// Its label.
        label: String,
        /// Its samples.
        samples: usize,
        /// The times.
        times: usize,
    },
    /// A set of predictions of another length than the times.
    #[error("set {label:?} has {samples} samples for {times} times")]
    Set {
        /// Its label.
        label: String,
        /// Its samples.
        samples: usize,
        /// The times.
        times: usize,
    },
    /// A set of residuals of another length than the times.
    #[error("residual set {label:?} has {samples} samples for {times} times")]
    Residuals {
        /// Its label.
        label: String,
        /// Its samples.
        samples: usize,
        /// The times.
        times: usize,
    },
    /// A map whose cells are not one per point of its axes.
    #[error("the map must be {rows} rows of {columns} cells, found {found} rows")]
    Map {
        /// The rows its y axis makes.
        rows: usize,
        /// The cells its x axis makes.
        columns: usize,
        /// The rows given.
        found: usize,
    },
    /// A correction panel whose vectors differ in length.
    #[error(
        "panel {caption:?}: {points} points, {values} values, {stds} standard deviations, {breakpoints} breakpoints for {knot_values} values"
    )]
    CorrectionPanel {
        /// Its caption.
        caption: String,
        /// Its points.
        points: usize,
        /// Its values.
        values: usize,
        /// Its standard deviations.
        stds: usize,
        /// Its breakpoints.
        breakpoints: usize,
        /// The values at its breakpoints.
        knot_values: usize,
    },
    /// A correlation matrix that is not n x n.
    #[error(
        "the correlation matrix must be {n} × {n} for {n} names, found {rows} rows of lengths {lengths:?}"
    )]
    CorrelationShape {
        /// The names.
        n: usize,
        /// Its rows.
        rows: usize,
        /// Their lengths.
        lengths: Vec<usize>,
    },
    /// More names than a correlation figure draws.
    #[error("{n} names: a correlation figure draws at most {max}")]
    CorrelationNames {
        /// The names.
        n: usize,
        /// The most it draws.
        max: usize,
    },
    /// Factor ranges not one per name.
    #[error("{names} factor names but {ranges} ranges")]
    FactorRanges {
        /// The names.
        names: usize,
        /// The ranges.
        ranges: usize,
    },
    /// A method's values not one per factor.
    #[error("method {label:?} gives {values} values for {factors} factors")]
    MethodValues {
        /// The method.
        label: String,
        /// Its values.
        values: usize,
        /// The factors.
        factors: usize,
    },
    /// The truth's values not one per factor.
    #[error("the truth gives {values} values for {factors} factors")]
    TruthValues {
        /// Its values.
        values: usize,
        /// The factors.
        factors: usize,
    },
    /// An increment series whose vectors differ in length.
    #[error(
        "panel {axis:?}, series {label:?}: {times} times, {values} values and {stds} standard deviations (one of each per window)"
    )]
    IncrementSeries {
        /// The panel's axis.
        axis: String,
        /// The series.
        label: String,
        /// Its times.
        times: usize,
        /// Its values.
        values: usize,
        /// Its standard deviations.
        stds: usize,
    },
    /// A found-terms curve whose times and values differ in length.
    #[error(
        "panel {axis:?}, found-terms curve of {}: {times} times for {values} values",
        label.as_ref().map_or_else(|| format!("event {}", event + 1), |l| format!("{l:?}"))
    )]
    IncrementModel {
        /// The panel's axis.
        axis: String,
        /// The event (from 0).
        event: usize,
        /// Its series' label, when the panel has one.
        label: Option<String>,
        /// The curve's times.
        times: usize,
        /// Its values.
        values: usize,
    },
    /// A clearance figure's series or criterion.
    #[error("clearance figure: {0}")]
    Clearance(super::clearance::ClearanceInput),
    /// An envelope map's grid.
    #[error("envelope map: {0}")]
    EnvelopeGrid(super::contour::GridError),
    /// An envelope map's criterion that is not finite.
    #[error("envelope map: the criterion must be finite, found {criterion}")]
    EnvelopeCriterion {
        /// The criterion.
        criterion: f64,
    },
}
