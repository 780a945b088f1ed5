//! `sepval rerun`: a saved generation re-evaluated, replayed and checked bit for bit.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Result, bail};
use sepval_fit::checkpoint::{Checkpoint, CheckpointError};
use sepval_fit::inputs;

use super::{evaluator_spec, notices, tell};
use crate::cli::RerunArgs;

/// Runs `sepval rerun`.
pub fn run(args: RerunArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let checkpoint = Checkpoint::load(&args.checkpoint)?;
    // Each input not given is the one the checkpoint records, independently of the others.
    let given = &args.inputs;
    let recorded = &checkpoint.inputs;
    let data_paths = if given.data.is_empty() {
        &recorded.data
    } else {
        &given.data
    };
    let scenario_path = given.model.scenario.as_ref().or(recorded.scenario.as_ref());
    let extension_path = given
        .model
        .extension
        .as_ref()
        .or(recorded.extension.as_ref());
    let policy = given.outliers.or(recorded.outliers);
    let (job, _) = inputs::job(
        data_paths,
        scenario_path.map(PathBuf::as_path),
        extension_path.map(PathBuf::as_path),
        policy,
        &mut tell(),
    )?;
    if let Err(e) = checkpoint.check_job(&job, &args.checkpoint) {
        // A scenario that differs only by the extension given: say so, not "another scenario".
        if let (Some(x), CheckpointError::OtherJob { .. }) = (&given.model.extension, &e) {
            let recorded_x = recorded.extension.as_deref();
            let same_but_extension = job.data_sha256() == checkpoint.data_sha256
                && inputs::job(
                    data_paths,
                    scenario_path.map(PathBuf::as_path),
                    recorded_x,
                    policy,
                    &mut |_| {},
                )
                .is_ok_and(|(j, _)| j.scenario_sha256() == checkpoint.scenario_sha256);
            if same_but_extension {
                bail!(
                    "checkpoint {} was made with another extension: --extension {} is not {}; give that extension file, or leave --extension out to use the recorded one",
                    args.checkpoint.display(),
                    x.display(),
                    recorded_x.map_or(
                        "none (the checkpoint was made without an extension)".into(),
                        |p| { format!("the one it was made with ({})", p.display()) }
                    )
                );
            }
        }
        return Err(e.into());
    }
    let mut evaluator = spec.start(Arc::new(job), notices())?;
    let report = sepval_fit::rerun::check(&checkpoint, &args.checkpoint, evaluator.as_mut())?;
    say!("{} ({})", report.checked(), evaluator.describe());
    if report.reproduces() {
        say!(
            "generation {}: all {} population and {} archive members reproduce their goals bit \
             for bit",
            report.generation,
            report.population,
            report.archive
        );
        return Ok(());
    }
    for m in &report.mismatches {
        say!("{m}");
    }
    bail!(
        "checkpoint {} does not reproduce: {}",
        args.checkpoint.display(),
        report.failures()
    )
}
