//! One file per subcommand: each turns its raw flags into a validated configuration before any
//! I/O, then calls the libraries and renders what they return. What several commands share
//! lives here: counts and durations from flags, the evaluator configuration, the worker
//! executable, and the rendering of transport notices. What a command prints goes through the
//! front end ([`crate::front`]: `say!`, `note!`, `front::progress()`), never to stdout directly.

pub mod aero;
pub mod bench;
pub mod campaign;
pub mod clean_ipc;
pub mod diagnose;
pub mod effects;
pub mod envelope;
pub mod fit;
pub mod gateway;
pub mod goals;
pub mod plan;
pub mod predict;
pub mod rerun;
pub mod scenario;
pub mod selftest;
pub mod simulate;
pub mod update;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context, Result, bail};
use sepval_common::evaluation::{EvalError, Evaluator, Job};
use sepval_run::clearance::GeometryPaths;
use sepval_run::out_dir::{Claim, Input, Request, RunDir};
use sepval_run::sequence::{Evaluators, Run, RunError, Writes};
use sepval_transport::flags::{EvaluatorFlags, Kind};
use sepval_transport::link::{Notice, Notices};
use sepval_transport::spec::{EvaluatorSpec, Starter};

use crate::cli::{EvalArgs, EvaluatorKind};
/// The terminal's progress bar, where commands used to find it; a command shows progress with
/// `front::progress()`, which is the bar on the terminal and the callback in Python.
pub use crate::front::Bar;

pub use sepval_core::flag_value::{count, positive, seconds};

/// The worker executable: $SEPVAL_WORKER, the front end's (the Python package finds one on
/// the PATH), or `sepval-worker` beside this executable.
pub fn worker_executable() -> Result<PathBuf> {
    if let Some(p) = std::env::var_os("SEPVAL_WORKER") {
        return Ok(PathBuf::from(p));
    }
    if let Some(p) = crate::front::current().worker() {
        return Ok(p);
    }
    let me = std::env::current_exe().context("cannot locate the sepval executable")?;
    let worker = me.with_file_name(format!("sepval-worker{}", std::env::consts::EXE_SUFFIX));
    if !worker.exists() {
        bail!(
            "cannot find the worker executable {} (build it with `cargo build --release`, or set SEPVAL_WORKER)",
            worker.display()
        );
    }
    Ok(worker)
}

/// The evaluation flags as given, for the transport to check ([`EvaluatorFlags::spec`]).
pub fn evaluator_flags(args: &EvalArgs) -> EvaluatorFlags {
    EvaluatorFlags {
        kind: match args.evaluator {
            EvaluatorKind::Inproc => Kind::InProcess,
            EvaluatorKind::Ipc => Kind::Ipc,
            EvaluatorKind::Zenoh => Kind::Zenoh,
        },
        workers: args.workers,
        threads: args.threads,
        listen: args.listen.clone(),
        zenoh_config: args.zenoh_config.clone(),
        attach: args.attach.clone(),
        run_id: args.run_id.clone(),
        worker_timeout_s: args.worker_timeout,
        join_timeout_s: args.join_timeout,
        announce_protocol: args.announce_protocol,
    }
}

/// The evaluator of the shared evaluation flags, validated (nothing is started yet).
pub fn evaluator_spec(args: &EvalArgs) -> Result<EvaluatorSpec> {
    let worker = || worker_executable().map_err(|e| format!("{e:#}"));
    Ok(evaluator_flags(args).spec(worker)?)
}

/// Refuses `--attach` for `command`, which evaluates several jobs one after another
/// ([`EvaluatorFlags::several_jobs`]).
pub fn several_jobs(args: &EvalArgs, command: &str, jobs: &str) -> Result<()> {
    Ok(evaluator_flags(args).several_jobs(command, jobs)?)
}

/// Where the libraries' words about what they read go (what `--outliers drop` left out):
/// stderr, through the front end.
pub fn tell() -> impl FnMut(String) {
    |said| note!("{said}")
}

/// Transport notices, told on stderr as `sepval: ...`.
pub fn notices() -> Notices {
    Arc::new(|n| note!("sepval: {n}"))
}

/// Claims `--out` as `request` says: the one place where every command claims its output
/// directory, with what the run reads (the directory may be none of its inputs, hold none and
/// lie inside none, whatever the flags). A refusal names the flag; a lock taken over because
/// it named no process is told.
pub fn claim_out(out: &Path, request: Request<'_>) -> Result<RunDir> {
    let run_dir =
        RunDir::claim(out, request).with_context(|| format!("--out {}", out.display()))?;
    if let Some(n) = run_dir.notice() {
        note!("sepval: {n}");
    }
    sepval_core::defect::inject("claimed");
    Ok(run_dir)
}

/// The claim of a new run: `--overwrite` clears an earlier run, else the directory must be
/// empty.
pub fn fresh_or_overwrite(overwrite: &crate::cli::OverwriteArgs) -> Claim {
    if overwrite.overwrite {
        Claim::Overwrite
    } else {
        Claim::Fresh
    }
}

/// `--aircraft`, `--store-shape` and `--clearance-mm` as given.
pub fn geometry(g: &crate::cli::GeometryArgs) -> GeometryPaths {
    GeometryPaths {
        aircraft: g.aircraft.clone(),
        store_shape: g.store_shape.clone(),
        clearance_mm: g.clearance_mm,
    }
}

/// The files of `--data`, `--scenario` (with the table files it names) and `--extension`, as
/// inputs.
pub fn model_inputs(i: &crate::cli::InputArgs) -> Vec<Input> {
    let mut out = Input::files("--data", &i.data);
    out.extend(scenario_inputs(
        i.model.scenario.as_ref(),
        i.model.extension.as_ref(),
    ));
    out
}

/// The files of `--scenario`, the table files it names, and `--extension`, as inputs.
pub fn scenario_inputs(scenario: Option<&PathBuf>, extension: Option<&PathBuf>) -> Vec<Input> {
    let mut out = Input::files("--scenario", scenario);
    if let Some(path) = scenario {
        let whose = format!("--scenario {}", path.display());
        let tables = sepval_common::Scenario::table_files(path);
        out.extend(tables.iter().map(|t| Input::named_by(&whose, t)));
    }
    out.extend(Input::files("--extension", extension));
    out
}

/// Refuses a file `--out` that is one of the run's `inputs` (the same file by any name),
/// before any work: a run that wrote it would destroy what it reads.
pub fn out_file_apart(out: &Path, inputs: &[Input]) -> Result<()> {
    sepval_run::out_dir::check_file(out, inputs).with_context(|| format!("--out {}", out.display()))
}

/// Runs `run` into the directory `writes` says, in the one order of every command
/// ([`sepval_run::sequence::execute`]): its evaluators started from `spec` (one for its job,
/// or one per job), its progress on the front end; then prints what it says: the summary on
/// stdout, then the warnings on stderr.
pub fn execute<R: Run>(spec: &EvaluatorSpec, writes: Writes, run: R) -> Result<()> {
    let mut start = |job: Option<Arc<Job>>| -> Result<Evaluators<'_>, RunError> {
        Ok(match job {
            Some(job) => Evaluators::One(spec.start(job, notices())?),
            None => Evaluators::Each(Box::new(starter(spec))),
        })
    };
    let progress = &mut *crate::front::progress();
    let said =
        sepval_run::sequence::execute(writes, run, &mut start, progress, &mut |s| note!("{s}"))?;
    crate::front::out(&said.summary);
    for w in &said.warnings {
        note!("warning: {w}");
    }
    Ok(())
}

/// Starts each job's evaluator (an envelope's conditions, an update's rounds) with one
/// [`Starter`], so that zenoh hosts that joined serve every job: their joining is told once, the
/// rest of what the transport says (a worker lost, refused) every time.
pub fn starter(
    spec: &EvaluatorSpec,
) -> impl FnMut(Arc<Job>) -> Result<Box<dyn Evaluator>, EvalError> + '_ {
    let mut started = false;
    let mut evaluators = Starter::new(spec.clone());
    move |job| {
        let told: Notices = if started {
            Arc::new(|n: Notice| {
                if !matches!(n, Notice::Joined { .. }) {
                    note!("sepval: {n}");
                }
            })
        } else {
            notices()
        };
        started = true;
        evaluators.start(job, told).map_err(EvalError::transport)
    }
}
