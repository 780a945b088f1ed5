//! Checkpoints of a genetic search: one JSON file per generation, written atomically, holding
//! the population with its goals, the archive, the generator state, the settings and the hashes
//! of the data and scenario it was run on (argmin's checkpointing model: the solver state and
//! its generator, so a resumed run is identical to an uninterrupted one).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use sepval_common::atomic_file::write_atomically;
use sepval_common::evaluation::Job;
use serde::{Deserialize, Serialize};

use crate::search::ga::{GaSettings, GaState};
use crate::search::hill::HillSettings;

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
    pub sigma: crate::fit::Sigma,
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
    pub fn save(&self, path: &Path) -> Result<()> {
        let json = serde_json::to_vec(self).context("serialising a checkpoint")?;
        write_atomically(path, &json)?;
        Ok(())
    }

    /// Reads and checks a checkpoint file.
    pub fn load(path: &Path) -> Result<Checkpoint> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read checkpoint {}", path.display()))?;
        let c: Checkpoint = serde_json::from_str(&text)
            .with_context(|| format!("checkpoint {} is not a sepval checkpoint", path.display()))?;
        if c.format != CHECKPOINT_FORMAT {
            bail!(
                "checkpoint {}: format `{}`, this sepval reads `{CHECKPOINT_FORMAT}`",
                path.display(),
                c.format
            );
        }
        c.settings
            .validate()
            .with_context(|| format!("checkpoint {}", path.display()))?;
        if c.state.population.len() != c.settings.population {
            bail!(
                "checkpoint {}: population of {} members, settings say {}",
                path.display(),
                c.state.population.len(),
                c.settings.population
            );
        }
        Ok(c)
    }

    /// Refuses a job whose data or scenario differ from the checkpoint's.
    pub fn check_job(&self, job: &Job, path: &Path) -> Result<()> {
        if job.data_sha256() != self.data_sha256 {
            bail!(
                "checkpoint {} was made with other data (sha256 {}, given {}): give the same --data files",
                path.display(),
                short(&self.data_sha256),
                short(job.data_sha256())
            );
        }
        if job.scenario_sha256() != self.scenario_sha256 {
            bail!(
                "checkpoint {} was made with another scenario (sha256 {}, given {}): give the same --scenario",
                path.display(),
                short(&self.scenario_sha256),
                short(job.scenario_sha256())
            );
        }
        Ok(())
    }
}

fn short(hash: &str) -> &str {
    &hash[..hash.len().min(12)]
}
