//! The one order of every command that writes an output directory (fit, diagnose, plan,
//! predict, envelope, update), in the spirit of argmin's executor (`argmin::core::Executor`:
//! the problem and the solver built first, the executor owning the loop and its observers).
//! A command's flags become a [`Run`] in its library (everything the run reads read and
//! checked, nothing written, no worker started), and [`execute`] owns the sequence from there,
//! the same for every command:
//!
//! 1. `--out` claimed: locked and checked against what the run reads ([`Writes`]), nothing in
//!    it changed yet;
//! 2. the evaluator started: one for a run of one job ([`Run::job`]), or a starter for a run
//!    of several ([`Evaluators`]);
//! 3. what must be checked with it running before anything changes ([`Run::confirm`]: a
//!    resumed fit's generation re-evaluated and replayed);
//! 4. the directory cleared (`--overwrite`: the earlier run set aside, put back if this one
//!    fails) or, for a resumed run, its abandoned continuation removed;
//! 5. the run ([`Run::run`]), which may write into the directory as it goes (a checkpoint per
//!    generation, an envelope's progress), its evaluator stopped when it returns;
//! 6. its files written, and what the run says of them ([`Run::write`]);
//! 7. the directory committed (its manifest written, the earlier run removed);
//! 8. what the run says ([`Said`]) handed back, for the front end to print: the summary on
//!    stdout, then the warnings on stderr.
//!
//! A refusal at any step before 7 leaves the directory as it was (or the earlier run put back),
//! and a refusal before 2 starts no worker. How an evaluator is started is the caller's (the
//! transports lie above this crate): [`execute`] is handed a function that starts them.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use sepval_common::evaluation::{EvalError, Evaluator, Job, StartEvaluator};
use sepval_solve::run::ProgressObserver;

use crate::out_dir::{Claim, Input, OutDirError, Request, RunDir};

/// Where a run writes and what it reads, which its directory may not be, hold or lie inside.
#[derive(Debug, Clone)]
pub struct Writes {
    /// `--out`.
    pub out: PathBuf,
    /// The command, as the directory's marker records it.
    pub command: &'static str,
    /// How the directory is claimed (fresh, `--overwrite`, `--resume`).
    pub claim: Claim,
    /// What the run reads.
    pub inputs: Vec<Input>,
    /// How to go on with the run in this directory, said when it is refused as not empty.
    pub resume: Option<String>,
}

impl Writes {
    /// A run of `command` into `out`, claimed as `claim` says, reading `inputs`; nothing to
    /// resume from.
    pub fn new(out: PathBuf, command: &'static str, claim: Claim, inputs: Vec<Input>) -> Writes {
        Writes {
            out,
            command,
            claim,
            inputs,
            resume: None,
        }
    }
}

/// The evaluators of a run: the one of its job, or a starter of one per job for a run of
/// several (an envelope's conditions, an update's rounds), whose zenoh hosts serve every job.
pub enum Evaluators<'a> {
    /// The evaluator of the run's one job.
    One(Box<dyn Evaluator>),
    /// Starts the evaluator of each job in turn.
    Each(Box<StartEvaluator<'a>>),
}

impl<'a> Evaluators<'a> {
    /// The evaluator of the run's one job; a run of several jobs has none (a defect in its
    /// [`Run::job`]).
    pub fn one(&mut self) -> Result<&mut dyn Evaluator, EvalError> {
        match self {
            Evaluators::One(e) => Ok(e.as_mut()),
            Evaluators::Each(_) => Err(EvalError::transport(
                "a run of several jobs has no single evaluator",
            )),
        }
    }

    /// The starter of a run of several jobs; a run of one job has none (a defect in its
    /// [`Run::job`]).
    pub fn each(&mut self) -> Result<&mut StartEvaluator<'a>, EvalError> {
        match self {
            Evaluators::Each(start) => Ok(start.as_mut()),
            Evaluators::One(_) => Err(EvalError::transport("a run of one job has no starter")),
        }
    }
}

/// What a run says once its directory is committed: its summary on stdout, then its warnings
/// on stderr.
#[derive(Debug, Default)]
pub struct Said {
    /// The summary.
    pub summary: String,
    /// One line each, `warning: ` put before.
    pub warnings: Vec<String>,
}

impl Said {
    /// A summary and no warning.
    pub fn summary(summary: String) -> Said {
        Said {
            summary,
            warnings: Vec::new(),
        }
    }
}

/// The error of a run's own stages (its library's, whatever the stage: a search, a sweep, its
/// outputs), kept whole with its cause chain.
pub type RunError = Box<dyn std::error::Error + Send + Sync>;

/// A refusal of what a flag names: the flag and its value, then why (`--scenario b.toml: ...`).
#[derive(Debug, thiserror::Error)]
#[error("{flag} {}", path.display())]
pub struct Named {
    /// The flag.
    pub flag: &'static str,
    /// What it names.
    pub path: PathBuf,
    /// Why it is refused.
    #[source]
    pub source: RunError,
}

impl Named {
    /// `flag path` refused for `source`, as a [`RunError`].
    pub fn error(flag: &'static str, path: &Path, source: impl Into<RunError>) -> RunError {
        Box::new(Named {
            flag,
            path: path.to_path_buf(),
            source: source.into(),
        })
    }
}

/// A command's run once its flags are checked: what [`execute`] asks of it, in order.
pub trait Run {
    /// What the run finds.
    type Found;

    /// The job of a run of one job, its evaluator started once; `None`: a run of several
    /// jobs, each job's evaluator started in turn.
    fn job(&self) -> Option<Arc<Job>>;

    /// What is checked with the evaluator running, before the directory changes; what is
    /// found worth saying is told.
    fn confirm(
        &mut self,
        _evaluators: &mut Evaluators<'_>,
        _tell: &mut dyn FnMut(String),
    ) -> Result<(), RunError> {
        Ok(())
    }

    /// The run itself.
    fn run(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        progress: &mut dyn ProgressObserver,
    ) -> Result<Self::Found, RunError>;

    /// Its files, written into `out` (the run took `wall_s`), and what it says of them.
    fn write(&self, found: Self::Found, out: &Path, wall_s: f64) -> Result<Said, RunError>;
}

/// Why a sequence stopped. Each renders as its cause does (with the flag for a claim), so a
/// command refuses with the words of the stage that refused.
#[derive(Debug, thiserror::Error)]
pub enum SequenceError {
    /// `--out` cannot be claimed.
    #[error("--out {}", out.display())]
    Claim {
        /// The directory.
        out: PathBuf,
        /// Why.
        #[source]
        source: OutDirError,
    },
    /// The evaluator did not start.
    #[error(transparent)]
    Start(RunError),
    /// The directory cannot be cleared.
    #[error(transparent)]
    Prepare(#[from] OutDirError),
    /// The run or its outputs failed.
    #[error(transparent)]
    Run(RunError),
}

/// The function that starts a run's evaluators: for its one job, or (`None`) a starter of one
/// per job.
pub type Start<'s, 'a> = &'s mut dyn FnMut(Option<Arc<Job>>) -> Result<Evaluators<'a>, RunError>;

/// Runs `run` in the one order of every command (the module's steps 1 to 7), into the
/// directory `writes` says (claimed as it says, with what the run reads), its evaluators
/// started by `start`, its progress shown to `progress`; what the directory's claim and
/// clearing say is told. Returns what the run says, for the front end to print (step 8).
pub fn execute<R: Run>(
    writes: Writes,
    mut run: R,
    start: Start<'_, '_>,
    progress: &mut dyn ProgressObserver,
    tell: &mut dyn FnMut(String),
) -> Result<Said, SequenceError> {
    let Writes {
        out,
        command,
        claim,
        inputs,
        resume,
    } = writes;
    let request = Request {
        command,
        claim,
        inputs: &inputs,
        resume,
    };
    let run_dir = RunDir::claim(&out, request).map_err(|source| SequenceError::Claim {
        out: out.clone(),
        source,
    })?;
    if let Some(n) = run_dir.notice() {
        tell(format!("sepval: {n}"));
    }
    sepval_core::defect::inject("claimed");
    let mut evaluators = start(run.job()).map_err(SequenceError::Start)?;
    run.confirm(&mut evaluators, tell)
        .map_err(SequenceError::Run)?;
    for removed in run_dir.prepare()? {
        tell(format!(
            "sepval: removed {} (a later generation of the continuation being replaced)",
            removed.display()
        ));
    }
    let clock = Instant::now();
    let found = run.run(&mut evaluators, progress);
    drop(evaluators);
    let found = found.map_err(SequenceError::Run)?;
    let said = run
        .write(found, &out, clock.elapsed().as_secs_f64())
        .map_err(SequenceError::Run)?;
    run_dir.commit();
    Ok(said)
}
