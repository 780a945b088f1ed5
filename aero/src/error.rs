//! Why an estimate was refused: the shape file (its own errors name the file and field), a
//! shape outside the methods' domain (naming the field), a grid flag, or the output.

use std::path::PathBuf;

/// Why an aerodynamic estimate was refused or could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AeroError {
    /// The store TOML was refused by `sepval-geometry` (file, line or field in the message).
    #[error(transparent)]
    Shape(#[from] sepval_geometry::GeometryError),
    /// The shape is a valid store but outside what the build-up's methods cover.
    #[error("{source_name}: {field}: {what}")]
    Outside {
        /// Where the shape came from.
        source_name: String,
        /// The field (`fins.count`, `body.nose_length_m`, ...).
        field: String,
        /// What is outside, and the domain.
        what: String,
    },
    /// A grid of Mach or alpha is not `LO:HI:N` within its domain.
    #[error("{flag} {value}: {what}")]
    Grid {
        /// The flag (`--mach`, `--alpha-deg`).
        flag: String,
        /// Its value as given.
        value: String,
        /// What is wrong.
        what: String,
    },
    /// The estimate could not be made into the scenario's tables (a table check refused it).
    #[error("the estimate's table {field}: {what}")]
    Table {
        /// The `[aero]` field.
        field: String,
        /// The table check's message.
        what: String,
    },
    /// The output directory exists, or writing it failed (nothing is left behind).
    #[error("{path}: {what}")]
    Output {
        /// The directory or file.
        path: PathBuf,
        /// What went wrong.
        what: String,
    },
}
