//! The one order of every command that writes an output directory (fit, diagnose, plan,
//! predict, envelope, update), in the spirit of argmin's executor: the command's file turns
//! its flags into a [`Run`] (everything the run reads read and checked, nothing written, no
//! worker started), and [`execute`] owns the sequence from there, the same for every command:
//!
//! 1. `--out` claimed: locked and checked against what the run reads ([`Writes`]), nothing in
//!    it changed yet;
//! 2. the evaluator started: one for a run of one job, or a starter for a run of several
//!    ([`Evaluators`]);
//! 3. what must be checked with it running before anything changes ([`Run::confirm`]: a
//!    resumed fit's generation re-evaluated and replayed);
//! 4. the directory cleared (`--overwrite`: the earlier run set aside, put back if this one
//!    fails) or, for a resumed run, its abandoned continuation removed;
//! 5. the run ([`Run::run`]), which may write into the directory as it goes (a checkpoint per
//!    generation, an envelope's progress), its evaluator stopped when it returns;
//! 6. its files written, and what the run says of them ([`Run::write`]);
//! 7. the directory committed (its manifest written, the earlier run removed);
//! 8. the summary on stdout and the warnings on stderr ([`Said`]).
//!
//! A refusal at any step before 7 leaves the directory as it was (or the earlier run put back),
//! and a refusal before 2 starts no worker.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::Result;
use sepval_common::evaluation::{Evaluator, Job, StartEvaluator};
use sepval_run::out_dir::{Claim, Input, Request};
use sepval_solve::run::ProgressObserver;
use sepval_transport::spec::EvaluatorSpec;

use super::{claim_out, notices, starter};

/// Where a run writes and what it reads, which its directory may not be, hold or lie inside.
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
    /// command).
    pub fn one(&mut self) -> Result<&mut dyn Evaluator> {
        match self {
            Evaluators::One(e) => Ok(e.as_mut()),
            Evaluators::Each(_) => anyhow::bail!("a run of several jobs has no single evaluator"),
        }
    }

    /// The starter of a run of several jobs; a run of one job has none (a defect in its
    /// command).
    pub fn each(&mut self) -> Result<&mut StartEvaluator<'a>> {
        match self {
            Evaluators::Each(start) => Ok(start.as_mut()),
            Evaluators::One(_) => anyhow::bail!("a run of one job has no starter"),
        }
    }
}

/// What a run says once its directory is committed: its summary on stdout, then its warnings
/// on stderr.
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

/// A command's run once its flags are checked: what [`execute`] asks of it, in order.
pub trait Run {
    /// What the run finds.
    type Found;

    /// What is checked with the evaluator running, before the directory changes.
    fn confirm(&mut self, _evaluators: &mut Evaluators<'_>) -> Result<()> {
        Ok(())
    }

    /// The run itself.
    fn run(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        progress: &mut dyn ProgressObserver,
    ) -> Result<Self::Found>;

    /// Its files, written into `out` (the run took `wall_s`), and what it says of them.
    fn write(&self, found: Self::Found, out: &Path, wall_s: f64) -> Result<Said>;
}

/// Runs `run` in the one order of every command (the module's steps 1 to 8): its directory
/// claimed as `writes` says, its evaluators from `spec` (one for `job`, or one per job it
/// starts when `job` is `None`).
pub fn execute<R: Run>(
    spec: &EvaluatorSpec,
    writes: Writes,
    job: Option<Arc<Job>>,
    mut run: R,
) -> Result<()> {
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
    let run_dir = claim_out(&out, request)?;
    let mut evaluators = match job {
        Some(job) => Evaluators::One(spec.start(job, notices())?),
        None => Evaluators::Each(Box::new(starter(spec))),
    };
    run.confirm(&mut evaluators)?;
    for removed in run_dir.prepare()? {
        note!(
            "sepval: removed {} (a later generation of the continuation being replaced)",
            removed.display()
        );
    }
    let start = Instant::now();
    let found = run.run(&mut evaluators, &mut *crate::front::progress());
    drop(evaluators);
    let said = run.write(found?, &out, start.elapsed().as_secs_f64())?;
    run_dir.commit();
    crate::front::out(&said.summary);
    for w in &said.warnings {
        note!("warning: {w}");
    }
    Ok(())
}
