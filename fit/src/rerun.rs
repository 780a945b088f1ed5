//! `sepval rerun`, and the check of `sepval fit --resume`: a saved generation re-evaluated and
//! replayed, bit for bit.
//!
//! After the checkpoint's own checks (its digest and consistency on loading, then the job:
//! [`crate::checkpoint`]), [`check`] simulates every member of the population *and of the
//! archive* again: each must give its recorded outcome to the last bit. And it replays the
//! generation: from the seed for generation 1, else from the checkpoint of the generation
//! before, when that lies beside this one (`gen-NNNN.json` in the same directory), passes its
//! own checks and comes from the same fit (same GA settings but for the count of generations,
//! same noise levels, data and scenario); otherwise the report says why it was not replayed.
//! The children are drawn with that checkpoint's generator, simulated and selected exactly as
//! the search did, and the state must come out identical: population, archive, generator,
//! counts and history. The replay is what checks the generator's position, which no
//! re-evaluation sees. All of it is one batch of simulations: population + archive + children
//! (about two generations' worth, once per `rerun` or `--resume`).

use std::collections::BTreeSet;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use sepval_common::evaluation::{Candidate, EvalError, Evaluator, Job, Outcome};
use sepval_common::telemetry::outliers::Policy;

use crate::checkpoint::{Checkpoint, CheckpointError};
use crate::problem::factors_of;
use sepval_solve::ga::{GaError, GaSearch, GaSettings};
use sepval_solve::run::{RunError, Solver};

/// Members named in a summary, at most.
const NAMED: usize = 5;

/// Where a member is kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Set {
    /// The current population.
    Population,
    /// The archive of non-dominated runs.
    Archive,
}

impl fmt::Display for Set {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Set::Population => "population",
            Set::Archive => "archive",
        })
    }
}

/// A member whose re-evaluation differs from the checkpoint.
#[derive(Debug, Clone, PartialEq)]
pub struct Mismatch {
    /// Population or archive.
    pub set: Set,
    /// Index in its set.
    pub member: usize,
    /// The saved outcome.
    pub saved: Outcome,
    /// The new outcome.
    pub rerun: Outcome,
}

impl fmt::Display for Mismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} member {}: saved {:?}, rerun {:?}",
            self.set, self.member, self.saved, self.rerun
        )
    }
}

/// What the generation was replayed from.
#[derive(Debug, Clone, PartialEq)]
pub enum Origin {
    /// The settings' seed (generation 1).
    Seed,
    /// The previous generation's checkpoint.
    Previous(PathBuf),
}

impl fmt::Display for Origin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Origin::Seed => f.write_str("the settings' seed"),
            Origin::Previous(p) => {
                write!(f, "the previous generation's checkpoint {}", p.display())
            }
        }
    }
}

/// The replay of the generation.
#[derive(Debug, Clone)]
pub enum Replay {
    /// Replayed, and the state came out identical.
    Same(Origin),
    /// Replayed, and these parts of the state differ (`state.rng`, `state.population[3]`).
    Differs(Origin, Vec<String>),
    /// Not replayed, for this reason.
    Skipped(NoReplay),
}

/// Why a generation is not replayed (the members are still re-evaluated).
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum NoReplay {
    /// The checkpoint of the generation before is not there.
    #[error("the previous generation's checkpoint {} is not there", path.display())]
    Missing {
        /// Where it would be.
        path: PathBuf,
    },
    /// The checkpoint of the generation before cannot be read, or is of another job.
    #[error("{0}")]
    Unreadable(Arc<CheckpointError>),
    /// A checkpoint there that is not of the generation before in the same fit.
    #[error("{} is not the previous generation of the same fit", path.display())]
    NotPrevious {
        /// The checkpoint.
        path: PathBuf,
    },
    /// No checkpoint of a generation before (tests).
    #[cfg(test)]
    #[error("no previous checkpoint")]
    NoPrevious,
}

/// Why a generation that could be replayed was not.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReplayFailure {
    /// The search could not be started or resumed from the state before.
    #[error("{0}")]
    Ga(GaError),
    /// The search could not ask or be told a generation.
    #[error("{0}")]
    Run(RunError),
    /// The search asked for nothing more.
    #[error("the search is already finished")]
    Finished,
}

/// The outcome of [`check`].
#[derive(Debug, Clone)]
pub struct Report {
    /// The checkpoint's generation.
    pub generation: usize,
    /// Members of its population.
    pub population: usize,
    /// Members of its archive.
    pub archive: usize,
    /// The members that do not reproduce.
    pub mismatches: Vec<Mismatch>,
    /// The replay.
    pub replay: Replay,
    /// The arithmetic version of the build that wrote the checkpoint, if recorded.
    pub arithmetic: Option<u32>,
}

impl Report {
    /// Whether every member reproduces and the replay (if made) gives the same state.
    pub fn reproduces(&self) -> bool {
        self.mismatches.is_empty() && !matches!(self.replay, Replay::Differs(..))
    }

    /// What does not reproduce, in one line (empty when everything does).
    pub fn failures(&self) -> String {
        let mut parts = Vec::new();
        if !self.mismatches.is_empty() {
            let count = |set| self.mismatches.iter().filter(|m| m.set == set).count();
            parts.push(format!(
                "{} of {} population members and {} of {} archive members do not reproduce \
                 their goals bit for bit ({}{})",
                count(Set::Population),
                self.population,
                count(Set::Archive),
                self.archive,
                self.mismatches
                    .iter()
                    .take(NAMED)
                    .map(|m| format!("{} member {}", m.set, m.member))
                    .collect::<Vec<_>>()
                    .join(", "),
                if self.mismatches.len() > NAMED {
                    ", ..."
                } else {
                    ""
                }
            ));
            parts.extend(arithmetic_hint(self.arithmetic));
        }
        if let Replay::Differs(origin, differ) = &self.replay {
            parts.push(format!(
                "replayed from {origin}, its state differs in {}",
                differ.join(", ")
            ));
        }
        if parts.is_empty() {
            String::new()
        } else {
            format!("generation {}: {}", self.generation, parts.join("; "))
        }
    }

    /// What was checked, in one line.
    pub fn checked(&self) -> String {
        let replay = match &self.replay {
            Replay::Same(origin) => format!("replaying it from {origin} gives the same state"),
            Replay::Differs(origin, _) => format!("replaying it from {origin} gives another state"),
            Replay::Skipped(why) => format!("not replayed: {why}"),
        };
        format!(
            "generation {}: {} population and {} archive members re-evaluated; {replay}",
            self.generation, self.population, self.archive
        )
    }
}

/// Why members may not reproduce, from the checkpoint's arithmetic version (nothing when it is
/// this build's).
fn arithmetic_hint(written: Option<u32>) -> Option<String> {
    let ours = sepval_common::ARITHMETIC_VERSION;
    match written {
        Some(v) if v == ours => None,
        Some(v) => Some(format!(
            "it was written by a build whose simulation arithmetic is version {v}, this one's is \
             {ours}: results differ in their last bits, so run the fit again with this build"
        )),
        None => Some(format!(
            "it does not record the build's arithmetic version: if a sepval older than version \
             {ours} of the arithmetic (wire protocol 3 or earlier, before sepval's own elementary \
             functions) wrote it, results differ in their last bits, so run the fit again with \
             this build"
        )),
    }
}

/// Errors of a rerun.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RerunError {
    /// The checkpoint (or the previous one) is refused or does not fit the job.
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    /// The evaluator failed.
    #[error(transparent)]
    Eval(#[from] EvalError),
    /// The generation cannot be replayed.
    #[error("checkpoint {path}: the generation cannot be replayed: {reason}")]
    Replay {
        /// The checkpoint.
        path: PathBuf,
        /// Why.
        reason: Box<ReplayFailure>,
    },
    /// The inputs of the rerun (its releases, scenario or extension) that cannot be read.
    #[error(transparent)]
    Inputs(#[from] sepval_run::inputs::InputError),
    /// The extension given is not the one the checkpoint was made with (the releases and the
    /// scenario are).
    #[error(
        "checkpoint {} was made with another extension: --extension {} is not {}; give that extension file, or leave --extension out to use the recorded one",
        path.display(), given.display(),
        recorded.as_ref().map_or(
            "none (the checkpoint was made without an extension)".into(),
            |p| format!("the one it was made with ({})", p.display())
        )
    )]
    OtherExtension {
        /// The checkpoint.
        path: PathBuf,
        /// `--extension`.
        given: PathBuf,
        /// The extension it records.
        recorded: Option<PathBuf>,
    },
    /// The checkpoint does not reproduce ([`confirm`]).
    #[error("checkpoint {path} does not reproduce: {failures}")]
    NotReproduced {
        /// The checkpoint.
        path: PathBuf,
        /// [`Report::failures`].
        failures: String,
    },
}

/// The job of a rerun of `checkpoint` (at `path`): each input given (`given`, `outliers`) or,
/// where not given, the one the checkpoint records, independently of the others; checked to be
/// the checkpoint's job (when only the extension given differs from the recorded one, the
/// error says so rather than "another scenario").
pub fn job(
    checkpoint: &Checkpoint,
    path: &Path,
    given: &crate::resume::InputPaths,
    outliers: Option<Policy>,
    tell: sepval_run::inputs::Tell,
) -> Result<Job, RerunError> {
    let recorded = &checkpoint.inputs;
    let data = if given.data.is_empty() {
        &recorded.data
    } else {
        &given.data
    };
    let scenario = given.scenario.as_deref().or(recorded.scenario.as_deref());
    let extension = given.extension.as_deref().or(recorded.extension.as_deref());
    let policy = outliers.unwrap_or(recorded.outliers);
    let (job, _) = sepval_run::inputs::job(data, scenario, extension, policy, tell)?;
    let Err(e) = checkpoint.check_job(&job, path) else {
        return Ok(job);
    };
    if let (Some(x), CheckpointError::OtherJob { .. }) = (&given.extension, &e) {
        let recorded_x = recorded.extension.as_deref();
        let same_but_extension = job.data_sha256() == checkpoint.data_sha256
            && sepval_run::inputs::job(data, scenario, recorded_x, policy, &mut |_| {})
                .is_ok_and(|(j, _)| j.scenario_sha256() == checkpoint.scenario_sha256);
        if same_but_extension {
            return Err(RerunError::OtherExtension {
                path: path.to_path_buf(),
                given: x.clone(),
                recorded: recorded.extension.clone(),
            });
        }
    }
    Err(e.into())
}

/// Re-evaluates the checkpoint's population and archive with `evaluator` (whose job must be
/// the checkpoint's: checked) and replays its generation; see the module documentation.
pub fn check(
    checkpoint: &Checkpoint,
    path: &Path,
    evaluator: &mut dyn Evaluator,
) -> Result<Report, RerunError> {
    checkpoint.check_job(evaluator.job(), path)?;
    let replay_error = |reason: ReplayFailure| RerunError::Replay {
        path: path.to_path_buf(),
        reason: Box::new(reason),
    };
    let state = &checkpoint.state;
    // The search that replays the generation, with what it starts from, or why there is none.
    let mut replaying = match previous(checkpoint, path, evaluator) {
        Ok((origin, before)) => {
            let genes = evaluator.job().factor_table().0.to_vec();
            let (settings, weights) = (checkpoint.settings.clone(), checkpoint.sigma.weights());
            let search = match before {
                None => GaSearch::new(settings, weights, genes),
                Some(before) => GaSearch::resume(settings, weights, genes, before.state),
            }
            .map_err(|e: GaError| replay_error(ReplayFailure::Ga(e)))?;
            Ok((origin, search))
        }
        Err(why) => Err(why),
    };
    let children = match &mut replaying {
        Ok((_, search)) => {
            search
                .ask()
                .map_err(|e: RunError| replay_error(ReplayFailure::Run(e)))?
                .ok_or_else(|| replay_error(ReplayFailure::Finished))?
                .points
        }
        Err(_) => Vec::new(),
    };
    let members: Vec<_> = state
        .population
        .iter()
        .map(|m| (Set::Population, m))
        .chain(state.archive.iter().map(|m| (Set::Archive, m)))
        .collect();
    let batch: Vec<Candidate> = members
        .iter()
        .map(|(_, m)| m.values.as_slice())
        .chain(children.iter().map(Vec::as_slice))
        .map(|v| Candidate::baseline(factors_of(v)))
        .collect();
    let mut evaluated = evaluator.evaluate(&batch, false)?;
    let told = evaluated.split_off(members.len());
    let mut index = [0usize; 2];
    let mut mismatches = Vec::new();
    for ((set, m), e) in members.iter().zip(evaluated) {
        let i = &mut index[usize::from(*set == Set::Archive)];
        if !m.outcome.same_bits(&e.outcome) {
            mismatches.push(Mismatch {
                set: *set,
                member: *i,
                saved: m.outcome.clone(),
                rerun: e.outcome,
            });
        }
        *i += 1;
    }
    let replay = match replaying {
        Ok((origin, mut search)) => {
            search
                .tell(told.into_iter().map(|e| e.outcome).collect())
                .map_err(|e: RunError| replay_error(ReplayFailure::Run(e)))?;
            let replayed = Checkpoint {
                state: search.state().cloned().expect("told a generation"),
                ..checkpoint.clone()
            };
            let (a, b) = (replayed.compute_digest(), checkpoint.compute_digest());
            let differ: Vec<String> = a
                .parts
                .keys()
                .chain(b.parts.keys())
                .filter(|k| a.parts.get(*k) != b.parts.get(*k))
                .cloned()
                .collect::<BTreeSet<_>>()
                .into_iter()
                .collect();
            if differ.is_empty() {
                Replay::Same(origin)
            } else {
                Replay::Differs(origin, differ)
            }
        }
        Err(why) => Replay::Skipped(why),
    };
    Ok(Report {
        arithmetic: checkpoint.arithmetic,
        generation: state.generation,
        population: state.population.len(),
        archive: state.archive.len(),
        mismatches,
        replay,
    })
}

/// [`check`], and an error unless everything reproduces (for `fit --resume`).
pub fn confirm(
    checkpoint: &Checkpoint,
    path: &Path,
    evaluator: &mut dyn Evaluator,
) -> Result<Report, RerunError> {
    let report = check(checkpoint, path, evaluator)?;
    if report.reproduces() {
        Ok(report)
    } else {
        Err(RerunError::NotReproduced {
            path: path.to_path_buf(),
            failures: report.failures(),
        })
    }
}

/// Where to replay the generation from (with the previous checkpoint, unless from the seed),
/// or why it is not replayed: the previous checkpoint is not there, is refused (its own
/// message) or is of another fit. Passing over it is no weaker than insisting: who can edit it
/// can as well remove it.
fn previous(
    checkpoint: &Checkpoint,
    path: &Path,
    evaluator: &dyn Evaluator,
) -> Result<(Origin, Option<Checkpoint>), NoReplay> {
    let Some(before_path) = checkpoint.previous_path(path) else {
        return Ok((Origin::Seed, None));
    };
    if !before_path.exists() {
        return Err(NoReplay::Missing { path: before_path });
    }
    let before = Checkpoint::load(&before_path)
        .and_then(|b| b.check_job(evaluator.job(), &before_path).map(|()| b))
        .map_err(|e| NoReplay::Unreadable(Arc::new(e)))?;
    let same_settings = GaSettings {
        generations: checkpoint.settings.generations,
        ..before.settings.clone()
    } == checkpoint.settings;
    if !same_settings
        || before.sigma != checkpoint.sigma
        || before.state.generation + 1 != checkpoint.state.generation
    {
        return Err(NoReplay::NotPrevious { path: before_path });
    }
    Ok((Origin::Previous(before_path), Some(before)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(arithmetic: Option<u32>) -> Report {
        let goals = |j: f64| Outcome::Goals {
            j_pos_m: j,
            j_att_deg: 1.0,
        };
        Report {
            generation: 3,
            population: 4,
            archive: 2,
            mismatches: vec![Mismatch {
                set: Set::Population,
                member: 1,
                saved: goals(0.1),
                rerun: goals(0.1 + 1e-17),
            }],
            replay: Replay::Skipped(NoReplay::NoPrevious),
            arithmetic,
        }
    }

    #[test]
    fn a_checkpoint_of_other_arithmetic_says_why_it_does_not_reproduce() {
        let ours = sepval_common::ARITHMETIC_VERSION;
        let same = report(Some(ours)).failures();
        assert!(same.contains("population member 1"), "{same}");
        assert!(!same.contains("arithmetic"), "{same}");
        let older = report(Some(ours - 1)).failures();
        assert!(
            older.contains(&format!(
                "arithmetic is version {}, this one's is {ours}",
                ours - 1
            )),
            "{older}"
        );
        let unrecorded = report(None).failures();
        assert!(
            unrecorded.contains("does not record the build's arithmetic version"),
            "{unrecorded}"
        );
        // Nothing to explain when everything reproduces.
        let fine = Report {
            mismatches: Vec::new(),
            ..report(None)
        };
        assert!(fine.failures().is_empty());
    }
}
