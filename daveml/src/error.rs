//! What makes a DAVE-ML file unusable, or a scenario unwritable as one: each error says what
//! was wrong and where (the file, the line and the element).

use std::fmt;
use std::path::PathBuf;

/// Where in a DAVE-ML file: its name, a line (from 1) and an element.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Place {
    /// The file (as the user named it).
    pub file: String,
    /// The line of the element's start tag (from 1).
    pub line: u32,
    /// The element's name, e.g. `griddedTableDef`.
    pub element: String,
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} line {}, <{}>", self.file, self.line, self.element)
    }
}

/// A check case's output that the imported tables do not reproduce.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "{place}: check case `{case}`: {output} is {got:?} through the imported tables, {expected:?} in the file (tolerance {tol:e})"
)]
pub struct Mismatch {
    /// The output signal's place.
    pub place: Place,
    /// The case's name.
    pub case: String,
    /// The output variable.
    pub output: String,
    /// What the imported tables give.
    pub got: f64,
    /// What the file states.
    pub expected: f64,
    /// The tolerance applied.
    pub tol: f64,
}

/// A DAVE-ML file refused, or a scenario that cannot be written as one.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DavemlError {
    /// The file cannot be read (missing, not a regular file, larger than the limit, not
    /// UTF-8).
    #[error(transparent)]
    Input(#[from] sepval_core::input_file::InputFileError),
    /// The file is not well-formed XML.
    #[error("{file}: not XML: {message}")]
    NotXml {
        /// The file.
        file: String,
        /// The XML parser's message, with its line and column.
        message: String,
    },
    /// The file's DOCTYPE declares an entity (internal or external, general or parameter):
    /// refused before the XML parser sees the text (docs/daveml.md section 1).
    #[error(
        "{file} line {line}: the DOCTYPE declares the {kind} `{name}`: sepval reads DAVE-ML without entity declarations (the standard needs none; an entity expanded many times would take gigabytes to parse); expand or remove it"
    )]
    Entity {
        /// The file.
        file: String,
        /// The line of the `<!ENTITY` (from 1).
        line: u32,
        /// `entity` or `parameter entity`.
        kind: &'static str,
        /// The entity's name.
        name: String,
    },
    /// An element of the file that sepval cannot read or represent.
    #[error("{place}: {message}")]
    At {
        /// Where.
        place: Place,
        /// What is wrong.
        message: String,
    },
    /// A `checkData` case that the imported tables do not reproduce.
    #[error("{0}")]
    Check(Box<Mismatch>),
    /// The map file cannot be used.
    #[error("map {file}: {message}")]
    Map {
        /// The map file.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// An update's correction whose band cannot be laid on the updated store's table.
    #[error("the correction of {field}: {message}")]
    Band {
        /// The correction's field (TOML path).
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The scenario made from the file is not valid.
    #[error("{file}: the scenario made from it is refused")]
    Scenario {
        /// The DAVE-ML file.
        file: String,
        /// Why.
        #[source]
        source: sepval_common::scenario::ScenarioError,
    },
    /// An output that cannot be written.
    #[error("{path}: {reason}")]
    Output {
        /// The output path.
        path: PathBuf,
        /// What is wrong.
        reason: ExportError,
    },
    /// Writing failed.
    #[error(transparent)]
    Write(#[from] sepval_core::atomic_file::WriteError),
    /// The scenario in table form could not be written into its directory.
    #[error(transparent)]
    Tables(#[from] sepval_common::table_form::TableDirError),
    /// Writing a staged directory failed.
    #[error("cannot write {path}")]
    Io {
        /// The path.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
}

impl DavemlError {
    /// An error at `place`.
    pub(crate) fn at(place: &Place, message: impl Into<String>) -> DavemlError {
        DavemlError::At {
            place: place.clone(),
            message: message.into(),
        }
    }
}

/// A scenario, or bands, that cannot be written as DAVE-ML.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// A scenario with an aircraft flowfield.
    #[error(
        "the scenario's interference is an aircraft flowfield ([flowfield], docs/model.md section 3b), which sepval does not write as DAVE-ML: only its aerodynamic tables would be exported and the field lost"
    )]
    Flowfield,
    /// A band of a field the scenario does not write.
    #[error("a band for {field}, a field the scenario leaves out")]
    BandWithoutField {
        /// The band's field.
        field: String,
    },
    /// A band without one value per value of its table.
    #[error("the band of {field} has {values} values, not one per value of its table")]
    BandValues {
        /// The band's field.
        field: String,
        /// The band's values.
        values: usize,
    },
}
