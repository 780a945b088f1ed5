//! Errors of tables: every variant names the file, those about content the line and column.

/// Errors reading a table file. Every variant names the file; those about its content name the
/// line and, where there is one, the column (both counted from 1).
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum TableError {
    /// The file could not be read.
    #[error("{file}: cannot read table: {message}")]
    Io {
        /// The file.
        file: String,
        /// The cause.
        message: String,
    },
    /// No header row.
    #[error("{file}: empty table: expected a header row such as `mach [-],alpha [deg],cz [-]`")]
    Empty {
        /// The file.
        file: String,
    },
    /// A header without a unit.
    #[error(
        "{file}: line {line}, column {column}: `{header}` has no unit: write it as `{header} [{example}]`"
    )]
    MissingUnit {
        /// The file.
        file: String,
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The header given.
        header: String,
        /// A unit it could have.
        example: String,
    },
    /// A unit sepval does not know for this column.
    #[error(
        "{file}: line {line}, column {column}: unknown unit in `{header}`: expected {expected}"
    )]
    UnknownUnit {
        /// The file.
        file: String,
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The header given.
        header: String,
        /// The units accepted.
        expected: String,
    },
    /// Something wrong with the header other than units.
    #[error("{file}: line {line}, column {column}: `{header}`: {reason}")]
    Header {
        /// The file.
        file: String,
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The header given.
        header: String,
        /// What is wrong.
        reason: String,
    },
    /// A row with another number of fields than the header.
    #[error("{file}: line {line}: expected {expected} fields as in the header, found {found}")]
    Ragged {
        /// The file.
        file: String,
        /// Line.
        line: usize,
        /// Fields in the header.
        expected: usize,
        /// Fields found.
        found: usize,
    },
    /// A field that is not a finite number.
    #[error(
        "{file}: line {line}, column {column} (`{header}`): expected a finite number, found `{value}`"
    )]
    NotFinite {
        /// The file.
        file: String,
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// Its header.
        header: String,
        /// The field.
        value: String,
    },
    /// Rows that do not form the table's grid.
    #[error("{file}: line {line}, column {column} (`{header}`): {reason}")]
    Grid {
        /// The file.
        file: String,
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// Its header.
        header: String,
        /// What is wrong.
        reason: String,
    },
}
