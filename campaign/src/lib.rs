//! The test program as one record (`sepval campaign`, docs/campaign.md): the separation
//! envelope predicted before any release from a prior, the next release to fly chosen among
//! the conditions predicted safe by what it is expected to settle, each release flown checked
//! against its prediction and every release diagnosed again, until no condition is
//! undecided or no safe release is expected to settle any. The field's practice, a few
//! releases validating the simulation and the rest of the envelope cleared by prediction, is
//! M. B. Anderson's purpose ("a tenth of the test assets"); sequential planning for the
//! envelope decision itself is this crate's.
//!
//! The campaign is a pipeline of named stages over one directory:
//! 1. [`prior`]: the factors before any release ([`Prior`]);
//! 2. [`mod@assess`]: an envelope of the campaign, every condition's clearance predicted from what
//!    a round believes ([`Model`] to [`Assessed`]), its [`state`];
//! 3. [`next`]: the releases to fly next ([`Plan`]), with what a release would tell the
//!    [`rivals`] apart;
//! 4. [`program`] and [`add`]: `init`, `add`, `next` and `status` over the directory
//!    ([`record`]: campaign.json, status.json, next.json), each change staged and committed
//!    whole;
//! 5. [`page`]: report.html and the figures;
//! 6. [`rehearse`]: a virtual test program flown against a stated truth.

#![deny(clippy::float_cmp)]

pub mod add;
pub mod assess;
pub mod begin;
pub mod joint;
mod journal;
pub mod next;
pub mod page;
pub mod preflight;
pub mod preposterior;
pub mod prior;
pub mod prior_daveml;
pub mod prior_shape;
pub mod program;
pub mod record;
pub mod refusal;
pub mod rehearse;
pub mod release;
pub mod request;
pub mod rivals;
pub mod seal;
pub mod sources;
pub mod state;

pub use assess::{AssessSettings, Fitted, Model, StartEvaluator, assess};
pub use next::{Plan, Planned, plan};
pub use prior::{Prior, PriorError};
pub use record::{CAMPAIGN_FORMAT, CampaignFile, NEXT_FORMAT, NextFile, StatusFile};
pub use refusal::Refusal;
pub use state::{Assessed, Counts, State};

use sepval_common::evaluation::EvalError;

/// A campaign command that could not be carried out. Nothing in the campaign's directory
/// changed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CampaignError {
    /// A condition's prediction.
    #[error("the prediction of a condition")]
    Condition(#[source] Box<sepval_predict::PredictError>),
    /// The model could not be made of its parameters.
    #[error("the model")]
    Model(#[source] sepval_solve::run::RunError),
    /// An evaluator that could not be started.
    #[error("cannot start the evaluator")]
    Start(#[source] EvalError),
    /// The diagnosis of the releases.
    #[error("the diagnosis of the releases flown")]
    Diagnose(#[source] Box<sepval_diagnose::DiagnoseError>),
    /// The diagnosis's record as a prediction reads it.
    #[error("the diagnosis of the releases flown")]
    Source(#[source] Box<sepval_predict::PredictError>),
    /// The campaign's directory or one of its records.
    #[error("{path}: {message}")]
    Record {
        /// The file or directory.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A campaign record edited after sepval wrote it ([`seal`]).
    #[error(
        "{path}: {part} does not match its digest: edited after sepval wrote it? an edited campaign record is not used (put the file back as sepval wrote it)"
    )]
    Edited {
        /// The record.
        path: String,
        /// The part that changed.
        part: String,
    },
    /// A file the campaign wrote whose SHA-256 is not the one campaign.json records.
    #[error(
        "{path}: changed since the campaign wrote it (SHA-256 {recorded} recorded in campaign.json, {now} now): a campaign's releases and rounds are used as they were recorded (put the file back as the campaign wrote it)"
    )]
    Changed {
        /// The file.
        path: String,
        /// The SHA-256 campaign.json records.
        recorded: String,
        /// Its SHA-256 now.
        now: String,
    },
    /// A flag's value outside what a campaign can run.
    #[error("{flag} {value}: {expected}")]
    Setting {
        /// The flag.
        flag: &'static str,
        /// Its value, as given.
        value: String,
        /// What it must be, and why.
        expected: String,
    },
    /// A release, a flag or a step refused.
    #[error(transparent)]
    Refused(Box<Refusal>),
    /// The store's data with uncertainty (`--prior-daveml`) that cannot be taken into the
    /// prior.
    #[error("--prior-daveml {path}: {reason}")]
    PriorDaveml {
        /// The file.
        path: String,
        /// Why.
        reason: Box<prior_daveml::PriorDavemlError>,
    },
    /// The store's estimate from its shape (`--prior-from-shape`) that cannot be taken into
    /// the prior.
    #[error("--prior-from-shape {path}: {reason}")]
    PriorShape {
        /// The file.
        path: String,
        /// Why.
        reason: Box<prior_daveml::PriorDavemlError>,
    },
    /// The store's shape (`--prior-from-shape`) that cannot be estimated.
    #[error("--prior-from-shape {path}")]
    Aero {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: Box<sepval_aero::AeroError>,
    },
    /// The prior (`--prior`).
    #[error(transparent)]
    Prior(#[from] PriorError),
    /// The fit of the pre-flight trajectories (`--preflight`).
    #[error("the fit of the pre-flight trajectories (--preflight)")]
    Preflight(#[source] Box<sepval_fit::FitError>),
    /// The store's data with uncertainty (`--prior-daveml`).
    #[error("--prior-daveml {path}")]
    Daveml {
        /// The file.
        path: String,
        /// Why it cannot be read.
        #[source]
        source: Box<sepval_daveml::DavemlError>,
    },
    /// The campaign's grid, as its settings name it.
    #[error(transparent)]
    Grid(#[from] sepval_envelope::GridError),
    /// The releases flown as one job (refused as a job of the fit refuses them).
    #[error(transparent)]
    Job(#[from] sepval_common::evaluation::JobError),
    /// The campaign's scenario, as its settings name it.
    #[error(transparent)]
    Inputs(Box<sepval_run::inputs::InputError>),
    /// The campaign's geometry, as its settings name it.
    #[error(transparent)]
    Clearance(Box<sepval_predict::clearance::ClearanceInputError>),
    /// The directory is locked by another command.
    #[error(transparent)]
    Locked(#[from] sepval_run::out_dir::OutDirError),
    /// The outputs.
    #[error(transparent)]
    Outputs(#[from] sepval_report::OutputError),
    /// A signal asked the process to stop.
    #[error("interrupted by a signal: the campaign is as it was before the command")]
    Interrupted,
}

impl From<Refusal> for CampaignError {
    fn from(r: Refusal) -> Self {
        CampaignError::Refused(Box::new(r))
    }
}

impl From<sepval_core::cancel::Cancelled> for CampaignError {
    fn from(_: sepval_core::cancel::Cancelled) -> Self {
        CampaignError::Interrupted
    }
}

impl CampaignError {
    /// The error of an evaluator that could not be started (a signal's is an interruption).
    pub fn from_eval(e: EvalError) -> CampaignError {
        match e {
            EvalError::Interrupted => CampaignError::Interrupted,
            e => CampaignError::Start(e),
        }
    }
}
