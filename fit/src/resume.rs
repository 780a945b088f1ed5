//! A fit resumed from a checkpoint (`sepval fit --resume`, docs/guide.md): what the run reads
//! (so that its `--out` may be none of it), which inputs, method and search settings it goes on
//! with (the checkpoint's, unless the flags give them; only the generations may grow).

use std::path::{Path, PathBuf};

use sepval_common::evaluation::Job;
use sepval_solve::ga::GaSettings;
use sepval_solve::hill::HillSettings;

use crate::Method;
use crate::checkpoint::{Checkpoint, CheckpointError};
use crate::sigma::Sigma;
use sepval_run::out_dir::{Claim, Input};
use sepval_run::sequence::Writes;

/// Why a checkpoint cannot be gone on with as asked.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ResumeError {
    /// The checkpoint does not fit the job (other data, another scenario, ...).
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    /// The checkpoint names a method this sepval does not know.
    #[error("checkpoint {path}: unknown method `{method}`")]
    UnknownMethod {
        /// The checkpoint.
        path: PathBuf,
        /// The method it names.
        method: String,
    },
    /// Fewer generations asked for than the checkpoint has run.
    #[error("--generations {requested}: the checkpoint is already at generation {reached}")]
    Generations {
        /// `--generations`.
        requested: usize,
        /// The checkpoint's generation.
        reached: usize,
    },
}

/// Where a fit writes, `out`, and what it reads, `inputs` (its flags' files) and, resumed
/// from the checkpoint `resume` (its path and itself), what the checkpoint holds
/// ([`inputs_read`]). The directory is claimed over an earlier run (`overwrite`), as the
/// continuation of the checkpoint, or fresh. Its directory may be none of the run's inputs:
/// with a checkpoint, the checkpoint and its run directory too, unless the run goes on in that
/// directory (so `--resume DIR/generations/gen-0005.json --overwrite --out DIR` is refused: it
/// would clear the checkpoint it resumes from).
pub fn writes(
    out: &Path,
    resume: Option<(&Path, &Checkpoint)>,
    overwrite: bool,
    mut inputs: Vec<Input>,
) -> Writes {
    let claim = match resume {
        _ if overwrite => Claim::Overwrite,
        Some((path, c)) => Claim::Resume {
            checkpoint: path.to_path_buf(),
            generation: c.state.generation,
        },
        None => Claim::Fresh,
    };
    if let Some((path, c)) = resume {
        inputs.extend(inputs_read(path, c));
    }
    let hint = format!(
        "resume from one of its checkpoints (--resume {})",
        out.join("generations/gen-NNNN.json").display()
    );
    Writes {
        resume: Some(hint),
        ..Writes::new(out.to_path_buf(), "fit", claim, inputs)
    }
}

/// What a run resumed from the checkpoint `c` at `path` reads besides its flags' files: the
/// run directory it lies in (`DIR/generations/gen-NNNN.json`), the checkpoint, and the files it
/// records (releases, scenario, extension).
pub fn inputs_read(path: &Path, c: &Checkpoint) -> Vec<Input> {
    let mut read = Vec::new();
    let dir = path
        .parent()
        .filter(|d| d.file_name().is_some_and(|n| n == "generations"));
    if let Some(run) = dir.and_then(Path::parent) {
        read.push(Input::resumed_run(path, run));
    }
    read.push(Input::file("--resume", path));
    let whose = format!("--resume {}", path.display());
    let recorded = c
        .inputs
        .data
        .iter()
        .chain(&c.inputs.scenario)
        .chain(&c.inputs.extension);
    read.extend(recorded.map(|p| Input::recorded(&whose, p)));
    read
}

/// The input files of a run: its releases, scenario and extension.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct InputPaths {
    /// `--data`.
    pub data: Vec<PathBuf>,
    /// `--scenario`.
    pub scenario: Option<PathBuf>,
    /// `--extension`.
    pub extension: Option<PathBuf>,
}

impl InputPaths {
    /// These inputs, or, when none is given and the run resumes from `resume`, those the
    /// checkpoint records.
    pub fn or_recorded(self, resume: Option<&Checkpoint>) -> InputPaths {
        let none_given =
            self.data.is_empty() && self.scenario.is_none() && self.extension.is_none();
        match resume {
            Some(c) if none_given => InputPaths {
                data: c.inputs.data.clone(),
                scenario: c.inputs.scenario.clone(),
                extension: c.inputs.extension.clone(),
            },
            _ => self,
        }
    }
}

/// The method of a run: the one asked for, else the checkpoint's (at `path`) when resuming,
/// else [`Method::Both`].
pub fn method(
    requested: Option<Method>,
    resume: Option<(&Path, &Checkpoint)>,
) -> Result<Method, ResumeError> {
    match (requested, resume) {
        (Some(m), _) => Ok(m),
        (None, Some((path, c))) => {
            Method::from_name(&c.method).ok_or_else(|| ResumeError::UnknownMethod {
                path: path.to_path_buf(),
                method: c.method.clone(),
            })
        }
        (None, None) => Ok(Method::Both),
    }
}

/// The searches of a run resumed from the checkpoint `c` at `path` for `job`: the
/// checkpoint's GA and hill-climber settings and noise levels, after checking the checkpoint
/// against the job, with `generations` when given (never fewer than it has run).
pub fn searches(
    c: &Checkpoint,
    path: &Path,
    job: &Job,
    generations: Option<usize>,
) -> Result<(GaSettings, HillSettings, Sigma), ResumeError> {
    c.check_job(job, path)?;
    let mut ga = c.settings.clone();
    if let Some(g) = generations {
        if g < c.state.generation {
            return Err(ResumeError::Generations {
                requested: g,
                reached: c.state.generation,
            });
        }
        ga.generations = g;
    }
    Ok((ga, c.hill.clone(), c.sigma.clone()))
}
