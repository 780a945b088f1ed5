//! Checkpoints of a genetic search: one JSON file per generation, written atomically, holding
//! the population with its goals, the archive, the generator state, the settings and the hashes
//! of the data and scenario it was run on (argmin's checkpointing model: the solver state and
//! its generator, so a resumed run is identical to an uninterrupted one). Statistics that may
//! be infinite are written with [`nonfinite`].

pub mod nonfinite;

use std::path::{Path, PathBuf};

use sepval_common::atomic_file::{WriteError, write_atomically};
use sepval_common::evaluation::Job;
use serde::{Deserialize, Serialize};

use crate::search::ga::{GaSettings, GaState};
use crate::search::hill::HillSettings;
use crate::sigma::Sigma;

/// Errors reading, writing or using a checkpoint.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CheckpointError {
    /// The file cannot be read.
    #[error("cannot read checkpoint {path}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a checkpoint.
    #[error("checkpoint {path} is not a sepval checkpoint")]
    Parse {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: serde_json::Error,
    },
    /// The file does not fit this sepval or its job.
    #[error("checkpoint {path}: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
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
pub const CHECKPOINT_FORMAT: &str = "sepval-ga-checkpoint/1";

/// Where the fit's inputs came from (so that `rerun` and `--resume` can find them again).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InputsRecord {
    /// Data files (absolute paths); empty for the embedded default flight test.
    pub data: Vec<PathBuf>,
    /// Scenario file (absolute path); none for the embedded default.
    pub scenario: Option<PathBuf>,
}

/// One generation's checkpoint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// [`CHECKPOINT_FORMAT`].
    pub format: String,
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

impl Checkpoint {
    /// Path of generation `g`'s checkpoint in the run directory `dir`.
    pub fn path(dir: &Path, generation: usize) -> PathBuf {
        dir.join("generations")
            .join(format!("gen-{generation:04}.json"))
    }

    /// Writes the checkpoint atomically.
    pub fn save(&self, path: &Path) -> Result<(), CheckpointError> {
        let json = serde_json::to_vec(self).expect("a checkpoint serialises");
        write_atomically(path, &json)?;
        Ok(())
    }

    /// Reads and checks a checkpoint file.
    pub fn load(path: &Path) -> Result<Checkpoint, CheckpointError> {
        let text = std::fs::read_to_string(path).map_err(|source| CheckpointError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let c: Checkpoint =
            serde_json::from_str(&text).map_err(|source| CheckpointError::Parse {
                path: path.to_path_buf(),
                source,
            })?;
        let invalid = |message: String| CheckpointError::Invalid {
            path: path.to_path_buf(),
            message,
        };
        if c.format != CHECKPOINT_FORMAT {
            return Err(invalid(format!(
                "format `{}`, this sepval reads `{CHECKPOINT_FORMAT}`",
                c.format
            )));
        }
        c.settings.validate().map_err(|e| invalid(e.to_string()))?;
        if c.state.population.len() != c.settings.population {
            return Err(invalid(format!(
                "population of {} members, settings say {}",
                c.state.population.len(),
                c.settings.population
            )));
        }
        Ok(c)
    }

    /// Refuses a job whose data or scenario differ from the checkpoint's.
    pub fn check_job(&self, job: &Job, path: &Path) -> Result<(), CheckpointError> {
        let other = |what, saved: &str, given: &str, inputs| CheckpointError::OtherJob {
            path: path.to_path_buf(),
            what,
            saved: short(saved).to_string(),
            given: short(given).to_string(),
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
        Ok(())
    }
}

fn short(hash: &str) -> &str {
    &hash[..hash.len().min(12)]
}
