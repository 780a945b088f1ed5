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
    /// The path is not a regular file, or the file is over its byte limit.
    #[error(transparent)]
    Input(Box<sepval_core::input_file::InputFileError>),
    /// No header row.
    #[error("{file}: empty table: expected a header row such as `mach [-],alpha [deg],cz [-]`")]
    Empty {
        /// The file.
        file: String,
    },
    /// A header row that is not one of a table (its text is not quoted: the file may be
    /// anything).
    #[error(
        "{file}: line {line}, column {column}: not a table header: expected columns `name [unit]` such as `mach [-],alpha [deg],cz [-]` (is it a table file?)"
    )]
    NotAHeader {
        /// The file.
        file: String,
        /// Line.
        line: usize,
        /// Column.
        column: usize,
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
    /// A field that is not a finite number (quoted when it is short and could be a number; a
    /// field that could not be one is only described, see [`shown_field`]).
    #[error(
        "{file}: line {line}, column {column} (`{header}`): expected a finite number, found {}",
        shown_field(value)
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

/// Longest header field or value an error quotes \[characters\].
const MAX_QUOTED_CHARS: usize = 32;

/// Whether a header field could name a table column (`name [unit]`): short, of the characters
/// of names and units. A field that could not is never quoted in a message (the file may be
/// anything: issue 21, item 14).
pub(crate) fn could_be_header(field: &str) -> bool {
    field.len() <= 2 * MAX_QUOTED_CHARS
        && field
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || " _-.[]/^()*".contains(c))
}

/// A field as an error shows it: quoted when it is short and made of the characters of numbers
/// and names (`NaN`, `inf`, `1.2.3`), described by its length otherwise.
pub fn shown_field(value: &str) -> String {
    let plausible = value.len() <= MAX_QUOTED_CHARS
        && value
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "+-._ ".contains(c));
    if plausible {
        format!("`{value}`")
    } else {
        format!(
            "a field of {} characters that is not a number",
            value.chars().count()
        )
    }
}
