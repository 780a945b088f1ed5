//! Errors of telemetry files: every variant names the file, those about content the line and
//! column; and the bounds of plausible telemetry they cite.

use sepval_core::limits::{MAX_ANGLE_DEG, MAX_POSITION_M, MAX_SPAN_S};

/// Errors reading a telemetry file. Every variant names the file; those about content name the
/// line and column.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum TelemetryError {
    /// The file could not be read.
    #[error("{file}: cannot read: {message}")]
    Io {
        /// The file.
        file: String,
        /// The cause.
        message: String,
    },
    /// The path is not a regular file, or the file is over its byte limit.
    #[error(transparent)]
    Input(Box<sepval_core::input_file::InputFileError>),
    /// No header row.
    #[error(
        "{file}: empty file: expected a header row `t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg`"
    )]
    Empty {
        /// The file.
        file: String,
    },
    /// A header without data rows.
    #[error("{file}: no samples after the header (line {line})")]
    NoSamples {
        /// The file.
        file: String,
        /// Header line.
        line: usize,
    },
    /// A required quantity has no column.
    #[error("{file}: line {line}: missing column for {quantity}: expected {expected}")]
    MissingColumn {
        /// The file.
        file: String,
        /// Header line.
        line: usize,
        /// The quantity.
        quantity: &'static str,
        /// Accepted headers.
        expected: &'static str,
    },
    /// A known quantity with an unknown unit.
    #[error(
        "{file}: line {line}, column {column}: unknown unit in `{header}`: expected {expected}"
    )]
    UnknownUnit {
        /// The file.
        file: String,
        /// Header line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The header given.
        header: String,
        /// Accepted headers.
        expected: &'static str,
    },
    /// Two columns for one quantity.
    #[error("{file}: line {line}, column {column}: `{header}` repeats the {quantity} column")]
    DuplicateColumn {
        /// The file.
        file: String,
        /// Header line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The header given.
        header: String,
        /// The quantity.
        quantity: &'static str,
    },
    /// A row with the wrong number of fields.
    #[error("{file}: line {line}: expected {expected} fields as in the header, found {found}")]
    FieldCount {
        /// The file.
        file: String,
        /// The line.
        line: usize,
        /// Fields in the header.
        expected: usize,
        /// Fields found.
        found: usize,
    },
    /// A field that is not a number.
    #[error(
        "{file}: line {line}, column {column} (`{header}`): expected a number, found `{value}`"
    )]
    NotNumeric {
        /// The file.
        file: String,
        /// The line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// Its header.
        header: String,
        /// The text found.
        value: String,
    },
    /// A field that is NaN or infinite.
    #[error(
        "{file}: line {line}, column {column} (`{header}`): expected a finite number, found `{value}`"
    )]
    NotFinite {
        /// The file.
        file: String,
        /// The line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// Its header.
        header: String,
        /// The text found.
        value: String,
    },
    /// A line that is not UTF-8 text.
    #[error("{file}: line {line}: not valid UTF-8 text")]
    NotText {
        /// The file.
        file: String,
        /// The line.
        line: usize,
    },
    /// A double quote that does not enclose a whole field.
    #[error(
        "{file}: line {line}, column {column}: unbalanced double quote in `{value}` (a quoted field must start and end with a quote)"
    )]
    Quote {
        /// The file.
        file: String,
        /// The line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The field.
        value: String,
    },
    /// A line longer than [`MAX_TELEMETRY_LINE_BYTES`](sepval_core::limits::MAX_TELEMETRY_LINE_BYTES),
    /// refused once that many bytes of it were read.
    #[error(
        "{file}: line {line} is longer than {limit} bytes, the limit of a telemetry line (sepval_core::limits; a row is a few hundred bytes): is it a telemetry file?"
    )]
    LineTooLong {
        /// The file.
        file: String,
        /// The line.
        line: usize,
        /// The limit \[bytes\].
        limit: usize,
    },
    /// More samples than an event may have.
    #[error("{file}: line {line}: more than {limit} samples, the limit per event")]
    TooManySamples {
        /// The file.
        file: String,
        /// The line of the first sample beyond the limit.
        line: usize,
        /// The limit.
        limit: usize,
    },
    /// A value beyond the bounds of plausible telemetry.
    #[error(
        "{file}: line {line}, column {column} (`{header}`): {value} is beyond the plausible bound of +-{} {} for {}",
        kind.bound(),
        kind.unit(),
        kind.what()
    )]
    Implausible {
        /// The file.
        file: String,
        /// The line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// Its header.
        header: String,
        /// The value (in the file's unit).
        value: String,
        /// Which bound.
        kind: Bound,
    },
    /// A metadata key given twice with different values (which one was meant cannot be told).
    #[error(
        "{file}: line {line}: metadata `{key}` is given twice with different values: `{value}` here, `{first_value}` at line {first_line}; give it once"
    )]
    MetadataTwice {
        /// The file.
        file: String,
        /// The line of the second value.
        line: usize,
        /// The key.
        key: String,
        /// The second value.
        value: String,
        /// The line of the first value.
        first_line: usize,
        /// The first value.
        first_value: String,
    },
    /// Time not strictly increasing.
    #[error(
        "{file}: line {line}, column {column} (`t_s`): time {t_s} s is not after the previous sample's {previous_s} s (times must increase strictly)"
    )]
    TimeNotIncreasing {
        /// The file.
        file: String,
        /// The line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The time found.
        t_s: f64,
        /// The previous time.
        previous_s: f64,
    },
}

/// The bounds of plausible telemetry ([`sepval_core::limits`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bound {
    /// A sample time: +-[`MAX_SPAN_S`].
    Time,
    /// A position coordinate: +-[`MAX_POSITION_M`].
    Position,
    /// An Euler angle: +-[`MAX_ANGLE_DEG`].
    Angle,
}

impl Bound {
    /// The bound, SI.
    pub fn bound(self) -> f64 {
        match self {
            Bound::Time => MAX_SPAN_S,
            Bound::Position => MAX_POSITION_M,
            Bound::Angle => MAX_ANGLE_DEG,
        }
    }

    /// Its unit.
    pub fn unit(self) -> &'static str {
        match self {
            Bound::Time => "s",
            Bound::Position => "m",
            Bound::Angle => "deg",
        }
    }

    /// What it bounds.
    pub fn what(self) -> &'static str {
        match self {
            Bound::Time => "a sample time",
            Bound::Position => "a position",
            Bound::Angle => "an angle",
        }
    }
}
