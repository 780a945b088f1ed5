//! What makes a correction, its values or the field they change unusable.

use super::{MAX_CORRECTION_VALUES, MAX_CORRECTIONS, MAX_SHAPE_POINTS};

/// What makes a correction or its values unusable (the caller says where).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CorrectionError {
    /// A field no correction can change.
    #[error(
        "`field` `{field}` is not a field a correction can change (expected aero.ca0, aero.cy ... aero.cn, a derivative such as aero.cm_alpha_per_rad, interference.dcx0 ... interference.dcn0, flowfield.half_depth_m or flowfield.reversal_m)"
    )]
    Field {
        /// The field given.
        field: String,
    },
    /// A variable the field cannot be corrected over.
    #[error("`variable` `{variable}`: {field} may be corrected over {allowed} only")]
    Variable {
        /// The field.
        field: String,
        /// The variable given.
        variable: String,
        /// The variables allowed.
        allowed: String,
    },
    /// No breakpoints.
    #[error("`breakpoints` is empty: expected at least one")]
    NoBreakpoints,
    /// A breakpoint that is not a finite number.
    #[error("`breakpoints` holds {value}: expected finite numbers")]
    BreakpointNotFinite {
        /// The breakpoint.
        value: f64,
    },
    /// Breakpoints that do not increase strictly.
    #[error("`breakpoints` are not strictly increasing ({before} then {after})")]
    BreakpointsNotIncreasing {
        /// The breakpoint before.
        before: f64,
        /// The one after it, not above it.
        after: f64,
    },
    /// One correction with more breakpoints than a run carries values.
    #[error("{count} breakpoints: a run carries at most {MAX_CORRECTION_VALUES} correction values")]
    TooManyBreakpoints {
        /// Its breakpoints.
        count: usize,
    },
    /// More corrections than a scenario may have.
    #[error("{count} corrections: at most {MAX_CORRECTIONS}")]
    TooManyCorrections {
        /// The corrections given.
        count: usize,
    },
    /// Corrections whose breakpoints together exceed what a run carries.
    #[error(
        "{count} correction values up to this one: a run carries at most {MAX_CORRECTION_VALUES}"
    )]
    TooManyValuesUpTo {
        /// The breakpoints up to and with this correction.
        count: usize,
    },
    /// A candidate with more correction values than a run carries.
    #[error("{count} correction values: a run carries at most {MAX_CORRECTION_VALUES}")]
    TooManyValues {
        /// The values given.
        count: usize,
    },
    /// A candidate whose values do not match the scenario's breakpoints in number.
    #[error(
        "the candidate carries {carried} correction values, the scenario's corrections have {needed} breakpoints"
    )]
    ValueCount {
        /// The candidate's values.
        carried: usize,
        /// The breakpoints of the scenario's corrections.
        needed: usize,
    },
    /// A correction value that is not a finite number.
    #[error("correction value {index} is {value}: expected a finite number")]
    ValueNotFinite {
        /// Its index among the candidate's values.
        index: usize,
        /// The value.
        value: f64,
    },
    /// Values that change the flowfield into one that cannot be used.
    #[error(transparent)]
    FieldChange(#[from] FieldChangeError),
}

/// A change of the aircraft's flowfield (by corrections, docs/update.md section 15.3a) that the
/// field cannot take.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FieldChangeError {
    /// A shape table and its correction on too many depths together.
    #[error(
        "the flowfield's shape table and its correction have {depths} depths together: expected at most {MAX_SHAPE_POINTS}"
    )]
    ShapeDepths {
        /// The depths of the union of the two grids.
        depths: usize,
    },
    /// A corrected shape that is not 1 at carriage.
    #[error(
        "the flowfield's corrected shape is {value} at carriage: expected 1 (a correction of the shape starts at depth 0 with the value 0)"
    )]
    ShapeAtCarriage {
        /// g(0) corrected.
        value: f64,
    },
    /// A change of how the field grows with alpha, for a field of tables over position.
    #[error(
        "the flowfield is given as tables over position: it scales with alpha by its zero-lift angle, with no upwash_per_alpha or sidewash_per_alpha to correct"
    )]
    GridPerAlpha,
    /// A change of the shape table of a field without one.
    #[error("the flowfield's shape is not a table over depth: it has no table to correct")]
    NoShapeTable,
    /// A change of the half depth or reversal depth of a field whose shape is a table.
    #[error("the flowfield's shape is a table: it has no half depth or reversal depth to correct")]
    ShapeIsTable,
    /// A correction of the shape table of a scenario without one.
    #[error("the scenario has no [flowfield] shape table to correct")]
    NoShapeTableToCorrect,
    /// A correction of the shape table that does not start at carriage.
    #[error("a correction of the shape starts at depth 0 (where g stays 1)")]
    ShapeNotFromCarriage,
    /// A corrected 1 / L_z not above 0.
    #[error("the flowfield's corrected 1 / half_depth_m is {inverse} per m: expected above 0")]
    HalfDepth {
        /// 1 / L_z corrected \[1/m\].
        inverse: f64,
    },
    /// A corrected 1 / z_r below 0.
    #[error("the flowfield's corrected 1 / reversal_m is {inverse} per m: expected 0 or above")]
    Reversal {
        /// 1 / z_r corrected \[1/m\].
        inverse: f64,
    },
}
