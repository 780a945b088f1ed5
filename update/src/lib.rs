//! `sepval update`: the store's aerodynamic data updated from its releases, as corrections in
//! the scenario's own table forms, kept only as far as they predict a release they were not
//! fitted to (docs/update.md).
//!
//! This is what engineers do with release data when the catalogue and the term library do not
//! name the cause: update the store's data with smooth corrections over the states the store
//! went through (distance from the aircraft, flow angles, Mach), estimated from all releases
//! together, and trusted only as far as they predict (the practice of aerodynamic model
//! identification from flight data: R. V. Jategaonkar, *Flight Vehicle System Identification*,
//! 2nd ed., AIAA 2015, chapters 4 and 12; V. Klein and E. A. Morelli, *Aircraft System
//! Identification*, AIAA 2006, chapter 5, on estimation before modelling). The update is a
//! pipeline of named stages ([`update`] shows it whole):
//!
//! 1. **baseline**: the 17 factors fitted to every release (the fit pipeline, `ga+lm`, into
//!    DIR/baseline), refined to convergence ([`Baseline`]);
//! 2. **misfit**: the missing force and moment reconstructed per release as coefficient
//!    increments (docs/discovery.md section 11.6; `sepval_diagnose::reconstruct_misfit`);
//! 3. **explored** and **screen**: the corrections the explored ranges allow, scored by how
//!    well each predicts the reconstruction of releases left out ([`screen::Screening`]);
//! 4. **select**: the corrections proposed refitted by output error with the factors, their
//!    smoothness and which are kept chosen by cross-validation over releases
//!    ([`select::Selected`]);
//! 5. **uncertainty**: the covariance, the bands and the effective number of parameters
//!    ([`uncertainty::Uncertainty`]);
//! 6. **validation**: releases given with `--validate`, predicted;
//! 7. **store**: the corrections merged into the scenario's tables ([`store::Store`]);
//! 8. **record** and **outputs**: DIR/update.json, DIR/scenario.toml with DIR/tables/*.csv,
//!    DIR/factors.json, DIR/figures/corrections.png, DIR/report.html.

#![deny(clippy::float_cmp)]

pub mod assemble;
pub mod command;
pub mod crossval;
pub mod daveml;
pub mod explored;
pub mod jobs;
pub mod outcome;
pub mod outputs;
mod page;
pub mod pipeline;
pub mod record;
pub mod refit;
pub mod screen;
pub mod select;
pub mod space;
pub mod store;
pub mod uncertainty;
pub mod validation;
pub mod words;

use sepval_common::evaluation::EvalError;
use sepval_solve::run::RunError;

pub use jobs::StartEvaluator;
pub use outcome::{Baseline, Update};
pub use outputs::{OutputsError, write_outputs};
pub use pipeline::{UpdateOptions, update};
pub use record::{UPDATE_FORMAT, UpdateFile};

/// An update that cannot be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum UpdateError {
    /// The baseline fit.
    #[error("the baseline fit")]
    Baseline(#[source] sepval_fit::FitError),
    /// The reconstruction of the misfit.
    #[error("the reconstruction of what the baseline lacks")]
    Misfit(#[source] sepval_diagnose::DiagnoseError),
    /// An evaluator that could not be started.
    #[error("cannot start the evaluator")]
    Start(#[source] EvalError),
    /// A search or an evaluation.
    #[error(transparent)]
    Run(#[from] RunError),
    /// A release's scenario with the corrections proposed.
    #[error("release {release} with the corrections proposed")]
    Corrected {
        /// The release.
        release: String,
        /// Why.
        #[source]
        source: sepval_common::scenario::ScenarioError,
    },
    /// The releases with the corrections proposed, as one job.
    #[error("the releases with the corrections proposed")]
    Releases(#[source] sepval_common::evaluation::JobError),
    /// The baseline fit ended without a refined optimum to correct from.
    #[error("the baseline fit produced no refined optimum")]
    NoRefinedOptimum,
    /// The baseline's joint refinement failed.
    #[error("the baseline's refinement")]
    Refinement(#[source] sepval_solve::run::SearchError),
    /// `--validate` named no release that could be read.
    #[error("--validate gave no release")]
    NoValidation,
    /// A correction that does not merge into the store's coefficient.
    #[error("the updated store: `{field}` {reason}")]
    Merge {
        /// The scenario's field.
        field: String,
        /// Why.
        reason: store::MergeError,
    },
    /// The updated store is not a valid scenario.
    #[error("the updated store")]
    Store(#[source] sepval_common::scenario::ScenarioError),
    /// A list of free factors that is empty or names no factor: refused before anything runs.
    #[error("the free factors {0:?}: expected at least one, each the index of one of the 17")]
    Free(Vec<usize>),
    /// A name of `--free` that is not a factor's.
    #[error(
        "--free {name}: not one of the 17 factors (expected a comma-separated list of {names})",
        names = sepval_core::factors::Factor::NAMES.join(", ")
    )]
    FreeName {
        /// The name given.
        name: String,
    },
    /// A name of `--free` given twice.
    #[error("--free {name}: given twice")]
    FreeTwice {
        /// The name given again.
        name: String,
    },
    /// The releases (`--data`, `--validate`) or the store (`--scenario`, `--extension`) that
    /// cannot be read.
    #[error(transparent)]
    Inputs(Box<sepval_run::inputs::InputError>),
    /// The baseline search's settings or noise levels refused.
    #[error(transparent)]
    Search(sepval_fit::FitError),
}

impl From<EvalError> for UpdateError {
    fn from(e: EvalError) -> Self {
        UpdateError::Run(RunError::from(e))
    }
}

/// The update's results.
pub type Result<T> = std::result::Result<T, UpdateError>;
