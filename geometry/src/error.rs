//! The errors of reading geometry and of assessing a trajectory: each names the file (or the
//! sample) and what is wrong, with the line or field where there is one.

use std::path::PathBuf;

/// Why a geometry file, a pair of bodies or a trajectory was refused.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GeometryError {
    /// The file could not be opened or read.
    #[error("{path}: cannot read the geometry file")]
    Unreadable {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// The path is not a regular file (a directory, a FIFO, a device).
    #[error("{path}: not a regular file ({kind})")]
    NotAFile {
        /// The file.
        path: PathBuf,
        /// What it is instead.
        kind: &'static str,
    },
    /// The file is larger than [`crate::MAX_FILE_BYTES`].
    #[error(
        "{path}: {size_bytes} bytes, over the limit of {limit_bytes} bytes for a geometry file"
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Its size (at least this many bytes).
        size_bytes: u64,
        /// The limit.
        limit_bytes: u64,
    },
    /// The extension is neither `.stl` nor `.toml`.
    #[error("{path}: not a geometry file: the extension must be .stl or .toml")]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// The STL file is malformed; `line` is 0 for a binary file.
    #[error("{path}: {}{what}", line_prefix(*.line))]
    Stl {
        /// The file.
        path: PathBuf,
        /// The line of an ASCII file (1-based), 0 where there is none.
        line: usize,
        /// What is wrong.
        what: String,
    },
    /// More triangles than [`crate::MAX_TRIANGLES`].
    #[error("{path}: {count} triangles, over the limit of {limit}")]
    TooManyTriangles {
        /// The file.
        path: PathBuf,
        /// How many the file declares or holds (at least).
        count: u64,
        /// The limit.
        limit: u64,
    },
    /// The TOML file does not parse or has an unknown field (the message has line and column).
    #[error("{path}: {message}")]
    Toml {
        /// The file.
        path: PathBuf,
        /// The parser's message, with line, column and field.
        message: String,
    },
    /// A value is not finite, a length or radius is not positive, or a shape is flat.
    #[error("{path}: {field}: {what}")]
    Invalid {
        /// The file (or `<default store>`).
        path: PathBuf,
        /// The field, part or triangle.
        field: String,
        /// What is wrong.
        what: String,
    },
    /// The file describes no part or no triangle.
    #[error("{path}: empty geometry: {what}")]
    Empty {
        /// The file.
        path: PathBuf,
        /// What is missing.
        what: String,
    },
    /// The store intersects the aircraft at carriage.
    #[error("{0}")]
    IntersectsAtCarriage(Box<CarriageOverlap>),
    /// The caller's [`crate::Stop`] asked to stop.
    #[error("interrupted while {what}")]
    Interrupted {
        /// What was under way ("reading FILE", "checking the carriage", ...).
        what: String,
    },
    /// A trajectory that cannot be assessed (lengths differ, no sample, a non-finite value).
    #[error("trajectory: {what}")]
    Trajectory {
        /// What is wrong, with the sample index and time.
        what: String,
    },
}

fn line_prefix(line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!("line {line}: ")
    }
}

/// Where the store intersects the aircraft at carriage.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "the store ({store}) intersects the aircraft ({aircraft}) at carriage: store part \
     \"{store_part}\" and aircraft part \"{aircraft_part}\" {how}, over the tolerance of \
     {tolerance_m} m"
)]
#[non_exhaustive]
pub struct CarriageOverlap {
    /// Where the store came from.
    pub store: String,
    /// Where the aircraft came from.
    pub aircraft: String,
    /// The store's part.
    pub store_part: String,
    /// The aircraft's part.
    pub aircraft_part: String,
    /// "overlap by D m" or "one lies inside the other".
    pub how: String,
    /// [`crate::CARRIAGE_TOLERANCE_M`].
    pub tolerance_m: f64,
}
