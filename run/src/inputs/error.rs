//! The refusals of what a run reads: each names the flag or file given and what is wrong with
//! it, and keeps the reader's own error as its source.

use std::path::PathBuf;

use sepval_common::effects::EffectError;
use sepval_common::evaluation::JobError;
use sepval_common::extension::ExtensionError;
use sepval_common::scenario::{ScenarioError, StoreDifference};
use sepval_common::telemetry::TelemetryError;
use sepval_core::factors::{FactorError, FactorsFileError};
use sepval_core::input_file::InputFileError;

/// Why two releases may not both be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Twice {
    /// The same release given twice to one list.
    GivenTwice,
    /// A release held out to validate that was also fitted.
    Fitted,
}

impl std::fmt::Display for Twice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Twice::GivenTwice => "give each release once",
            Twice::Fitted => "a release used for fitting cannot measure prediction",
        })
    }
}

/// A refusal of the releases, scenario, factors or effects a run reads.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum InputError {
    /// The scenario file cannot be read, or the scenario (extended, or at a release's
    /// condition) is not valid.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The extension file cannot be read.
    #[error(transparent)]
    Extension(#[from] ExtensionError),
    /// A telemetry file cannot be read.
    #[error(transparent)]
    Telemetry(#[from] TelemetryError),
    /// The releases do not make a job (none, or of different lengths of record).
    #[error(transparent)]
    Job(#[from] JobError),
    /// A factors file cannot be read.
    #[error(transparent)]
    FactorsRead(#[from] InputFileError),
    /// A factors file does not hold this scenario's factors.
    #[error("factors file {path}")]
    FactorsFile {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: FactorsFileError,
    },
    /// The built-in factors named do not fit the scenario's factor table.
    #[error("the {name} factors do not fit this scenario's factor table")]
    FactorsTable {
        /// `truth` or `nominal`.
        name: String,
        /// Why.
        #[source]
        source: FactorError,
    },
    /// An `--effect ID=V1,...` (or `--truth-effect`) that names no effect or gives wrong
    /// values.
    #[error("{flag} {spec}")]
    Effect {
        /// The flag.
        flag: &'static str,
        /// The flag's value.
        spec: String,
        /// Why.
        #[source]
        source: EffectError,
    },
    /// The same file given twice, or to fit and to validate.
    #[error("{flag} {} is the same file as {earlier_flag} {}: {why}", .path.display(), .earlier.display())]
    SameFile {
        /// The flag of the later file.
        flag: &'static str,
        /// The later file.
        path: PathBuf,
        /// The flag of the earlier file.
        earlier_flag: &'static str,
        /// The earlier file.
        earlier: PathBuf,
        /// Why that is refused.
        why: Twice,
    },
    /// The same samples at the same condition, whatever the files.
    #[error("{given} holds the same samples as {earlier}: {why}")]
    SameSamples {
        /// How the later release was given (`--validate b.csv`).
        given: String,
        /// How the earlier one was (`--data a.csv`).
        earlier: String,
        /// Why that is refused.
        why: Twice,
    },
    /// A release's `# key = value` metadata that should be a number.
    #[error("{release}: metadata `# {key} = {text}` is not a number")]
    Metadata {
        /// The release.
        release: String,
        /// The key.
        key: String,
        /// Its text.
        text: String,
    },
    /// A release whose metadata records another store than the one fitted.
    #[error(
        "{release}: its metadata records another store than the one fitted ({fitted}): \
         {difference}; releases of different stores are not pooled: fit each store with its \
         own --scenario"
    )]
    OtherStore {
        /// The release.
        release: String,
        /// How the store fitted is named (`scenario s.toml`).
        fitted: String,
        /// What differs.
        difference: StoreDifference,
    },
    /// Outliers in a release read with the policy that refuses them.
    #[error(
        "{}: {count} outlier(s), sample(s) far from the trend of their neighbours \
         (docs/model.md section 6): {named}; correct the file, or give --outliers drop \
         to leave out the rows that hold one", .path.display()
    )]
    Outliers {
        /// The file.
        path: PathBuf,
        /// How many.
        count: usize,
        /// The first few, each with its line and value, and how many more.
        named: String,
    },
    /// A release read for a flag, refused for the reason in its source.
    #[error("{given}")]
    Given {
        /// The flag and file (`--validate b.csv`).
        given: String,
        /// Why.
        #[source]
        source: Box<InputError>,
    },
}

impl InputError {
    /// This error, said of the release given as `given`.
    pub fn given(self, given: impl Into<String>) -> InputError {
        InputError::Given {
            given: given.into(),
            source: Box::new(self),
        }
    }
}
