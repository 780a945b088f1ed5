//! `sepval rerun`: a saved generation re-evaluated, replayed and checked bit for bit.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Result, bail};
use sepval_fit::checkpoint::Checkpoint;

use super::{evaluator_spec, inputs, notices};
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
    let (job, _) = inputs::job(
        data_paths,
        scenario_path.map(PathBuf::as_path),
        extension_path.map(PathBuf::as_path),
        given.outliers.or(recorded.outliers),
    )?;
    checkpoint.check_job(&job, &args.checkpoint)?;
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
