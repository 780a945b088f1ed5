//! Checkpoints of a genetic search: one JSON file per generation, written atomically, holding
//! the population with its goals, the archive, the generator state, the settings and the hashes
//! of the data and scenario it was run on (argmin's checkpointing model: the solver state and
//! its generator, so a resumed run is identical to an uninterrupted one).
//!
//! # Digest
//!
//! A checkpoint carries a digest of its own content, `digest.sha256`: the SHA-256 (lower-case
//! hex) of its *canonical form*, which is the compact JSON that this sepval writes for the
//! checkpoint with the `digest` field left out (`serde_json::to_vec`: fields in declaration
//! order, no whitespace, numbers in serde_json's shortest spelling that reads back exactly,
//! non-finite numbers as the strings of [`nonfinite`](sepval_core::nonfinite)). [`Checkpoint::save`] writes it;
//! [`Checkpoint::load`] reads the file, writes the canonical form of what it read, and refuses
//! the file unless the two digests are equal.
//!
//! The canonical form holds the values read and nothing else, so what does not change a value
//! does not matter: whitespace and line breaks, the order of keys, another spelling of the same
//! number (`0.5`, `5e-1`). Every change of a value is refused: one ulp of a goal, one bit of a
//! chromosome, the generator's position. So is a key that sepval does not read (named in the
//! message), since it is not in the canonical form. `digest.parts` holds a short digest (16
//! hex) of each part, computed the same way (`format`, `settings`, `state.rng`,
//! `state.population[4]`, `state.archive[0]`, ...: see [`Digest`]): they name what was edited
//! when the whole does not match, and are checked as well.
//!
//! The digest detects edits, by hand or by accident; it is not a signature: who knows this rule
//! can write a matching digest for edited content. Such content still meets the consistency
//! checks below, and `sepval rerun` and `sepval fit --resume` re-evaluate the population and the
//! archive and replay the generation from the previous checkpoint ([`crate::rerun`]).
//!
//! # Consistency
//!
//! Besides the digest, [`Checkpoint::load`] checks, naming what disagrees:
//!
//! - the method runs the GA, the settings are valid, the noise levels are positive, the data
//!   and scenario hashes are SHA-256 hex;
//! - the generation is within the settings' generations and the simulations are generations x
//!   population;
//! - the generator state restores, is written as [`RngState::of`](sepval_solve::rng::RngState::of)
//!   writes it, and has the key and stream of the settings' seed;
//! - the history has one entry per generation with the right counts, and its last entry is what
//!   the population gives;
//! - every recorded outcome is one a simulation can give: goals finite and non-negative, a
//!   divergence time finite and non-negative, a failure reason no longer than
//!   [`MAX_REASON_BYTES`](sepval_common::evaluation::MAX_REASON_BYTES);
//! - the archive holds finished runs only, without duplicate chromosomes, in order of J_pos,
//!   none dominating another; every finished member of the population is in the archive with
//!   the same outcome or dominated by an archive member;
//! - the probes' counts follow from the generations and the earlier probes.
//!
//! [`Checkpoint::check_job`] adds what needs the job: every member's chromosome has the factor
//! table's length and decodes
//! ([`Chromosome::decode_values`](sepval_core::encoding::Chromosome::decode_values)) to
//! exactly its recorded values, and a divergence names an event of the job.
//!
//! # Earlier checkpoints
//!
//! This sepval writes and reads format [`CHECKPOINT_FORMAT`] (`sepval-ga-checkpoint/2`).
//! Checkpoints of format `sepval-ga-checkpoint/1`, written before the digest, are refused with
//! a message saying so: they carry no digest, so an edit to them cannot be detected, and
//! reading them would let any edited checkpoint pass by claiming the old format (some of them,
//! those with an infinite statistic, could not be read anyway: it was written as `null`). Run
//! the fit again to get checkpoints of the current format.

mod content;
mod digest;
mod verify;

use std::path::{Path, PathBuf};

use sepval_common::evaluation::Job;
use sepval_core::atomic_file::{WriteError, write_atomically};
use serde::{Deserialize, Serialize};

pub use self::content::{ContentError, DigestMismatch, MemberError};
pub use self::digest::Digest;
use crate::sigma::Sigma;
use sepval_solve::ga::{GaSettings, GaState};
use sepval_solve::hill::HillSettings;

/// Errors reading, writing or using a checkpoint.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CheckpointError {
    /// The file cannot be read (missing, not a regular file, over the size limit).
    #[error(transparent)]
    Read(#[from] sepval_core::input_file::InputFileError),
    /// The file is not a checkpoint.
    #[error("checkpoint {path} is not a sepval checkpoint")]
    Parse {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: serde_json::Error,
    },
    /// The content does not match its digest.
    #[error(
        "checkpoint {path}: its content does not match its digest: edited by hand? ({what}); \
         an edited checkpoint is not used: take an unedited one or run the fit again"
    )]
    Edited {
        /// The file.
        path: PathBuf,
        /// What differs (`changed: state.population[4]`).
        what: Box<DigestMismatch>,
    },
    /// The file does not fit this sepval or its job, or its content is inconsistent.
    #[error("checkpoint {path}: {reason}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: Box<ContentError>,
    },
    /// A job other than the checkpoint's.
    #[error(
        "checkpoint {path} was made with {what} (sha256 {saved}, given {given}): give the same {inputs}"
    )]
    OtherJob {
        /// The file.
        path: PathBuf,
        /// "other data", "another scenario".
        what: &'static str,
        /// The checkpoint's hash (shortened).
        saved: String,
        /// The given job's hash (shortened).
        given: String,
        /// What to give.
        inputs: &'static str,
    },
    /// The checkpoint cannot be written.
    #[error(transparent)]
    Write(#[from] WriteError),
}

/// Format tag of checkpoint files.
pub const CHECKPOINT_FORMAT: &str = "sepval-ga-checkpoint/2";

/// Format tag of the checkpoints written before the digest (refused).
pub const CHECKPOINT_FORMAT_1: &str = "sepval-ga-checkpoint/1";

use sepval_run::inputs::InputsRecord;

/// One generation's checkpoint.
///
/// A field added here must also be added to the parts of [`Digest`] (the compiler says where).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// [`CHECKPOINT_FORMAT`].
    pub format: String,
    /// The digest of everything else (see the module documentation). [`Checkpoint::save`]
    /// computes it (whatever is here is ignored); [`Checkpoint::load`] checks it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub digest: Option<Digest>,
    /// [`sepval_common::ARITHMETIC_VERSION`] of the build that wrote it (absent in checkpoints
    /// written before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arithmetic: Option<u32>,
    /// Method being run (`ga`, `both`, ...).
    pub method: String,
    /// GA settings.
    pub settings: GaSettings,
    /// Hill-climber settings (for `both`).
    pub hill: HillSettings,
    /// Noise levels used to weight the goals.
    pub sigma: Sigma,
    /// SHA-256 of the measured data.
    pub data_sha256: String,
    /// SHA-256 of the scenario(s).
    pub scenario_sha256: String,
    /// Where the inputs came from.
    pub inputs: InputsRecord,
    /// The search state after this generation.
    pub state: GaState,
    /// Refinement attempts made so far (ga+lm).
    #[serde(default)]
    pub probes: Vec<crate::results::Probe>,
}

/// Just the format tag, read first so that a file of another format is named as such even when
/// the rest would not read.
#[derive(Deserialize)]
struct FormatOnly {
    format: String,
}

impl Checkpoint {
    /// Path of generation `g`'s checkpoint in the run directory `dir`.
    pub fn path(dir: &Path, generation: usize) -> PathBuf {
        sepval_run::out_dir::generation_path(dir, generation)
    }

    /// Where the same fit wrote the previous generation's checkpoint, if this one is at `path`:
    /// `gen-NNNN.json` beside it; none for the first generation.
    pub fn previous_path(&self, path: &Path) -> Option<PathBuf> {
        let g = self.state.generation.checked_sub(1).filter(|&g| g >= 1)?;
        Some(
            path.parent()
                .unwrap_or(Path::new(""))
                .join(format!("gen-{g:04}.json")),
        )
    }

    /// Writes the checkpoint atomically, with the digest of its content.
    pub fn save(&self, path: &Path) -> Result<(), CheckpointError> {
        let mut sealed = self.clone();
        sealed.digest = None;
        sealed.digest = Some(sealed.compute_digest());
        let json = serde_json::to_vec(&sealed).expect("a checkpoint serialises");
        write_atomically(path, &json)?;
        Ok(())
    }

    /// Reads a checkpoint file and checks its format, its digest and the consistency of its
    /// content (see the module documentation); [`Checkpoint::check_job`] checks the rest
    /// against the job.
    pub fn load(path: &Path) -> Result<Checkpoint, CheckpointError> {
        let text = sepval_core::input_file::read_string(
            path,
            "checkpoint",
            sepval_core::limits::MAX_JSON_BYTES,
        )?;
        let parse = |source| CheckpointError::Parse {
            path: path.to_path_buf(),
            source,
        };
        let invalid = |reason: ContentError| CheckpointError::Invalid {
            path: path.to_path_buf(),
            reason: Box::new(reason),
        };
        let format = serde_json::from_str::<FormatOnly>(&text)
            .map_err(parse)?
            .format;
        if format == CHECKPOINT_FORMAT_1 {
            return Err(invalid(ContentError::EarlierFormat { format }));
        }
        if format != CHECKPOINT_FORMAT {
            return Err(invalid(ContentError::OtherFormat { format }));
        }
        let mut c: Checkpoint = serde_json::from_str(&text).map_err(parse)?;
        let file: serde_json::Value = serde_json::from_str(&text).map_err(parse)?;
        let stored = c.digest.take();
        if let Some(key) = digest::unread_key(&file, &serde_json::to_value(&c).expect("serialises"))
        {
            return Err(invalid(ContentError::UnknownKey { key }));
        }
        let Some(stored) = stored else {
            return Err(invalid(ContentError::NoDigest));
        };
        c.check_digest(&stored)
            .map_err(|what| CheckpointError::Edited {
                path: path.to_path_buf(),
                what: Box::new(what),
            })?;
        c.check_content().map_err(invalid)?;
        c.digest = Some(stored);
        Ok(c)
    }

    /// Refuses a job whose data or scenario differ from the checkpoint's, and a checkpoint whose
    /// members do not fit the job's factor table: every chromosome must have its length and
    /// decode to exactly the member's recorded values.
    pub fn check_job(&self, job: &Job, path: &Path) -> Result<(), CheckpointError> {
        let other = |what, saved: &str, given: &str, inputs| CheckpointError::OtherJob {
            path: path.to_path_buf(),
            what,
            saved: short(saved),
            given: short(given),
            inputs,
        };
        if job.data_sha256() != self.data_sha256 {
            return Err(other(
                "other data",
                &self.data_sha256,
                job.data_sha256(),
                "data files",
            ));
        }
        if job.scenario_sha256() != self.scenario_sha256 {
            return Err(other(
                "another scenario",
                &self.scenario_sha256,
                job.scenario_sha256(),
                "scenario",
            ));
        }
        self.check_members(job)
            .map_err(|reason| CheckpointError::Invalid {
                path: path.to_path_buf(),
                reason: Box::new(reason),
            })
    }
}

/// The first 12 characters of a hash (of any text: never cut inside a character).
fn short(hash: &str) -> String {
    hash.chars().take(12).collect()
}

#[cfg(test)]
mod tests;
