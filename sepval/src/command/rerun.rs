//! `sepval rerun`: a saved generation re-evaluated, replayed and checked bit for bit.

use std::sync::Arc;

use anyhow::{Result, bail};
use sepval_fit::checkpoint::Checkpoint;

use super::{evaluator_spec, inputs, notices};
use crate::cli::RerunArgs;

/// Runs `sepval rerun`.
pub fn run(args: RerunArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let checkpoint = Checkpoint::load(&args.checkpoint)?;
    let (data_paths, scenario_path, extension_path) =
        if args.data.is_empty() && args.scenario.is_none() && args.extension.is_none() {
            (
                checkpoint.inputs.data.clone(),
                checkpoint.inputs.scenario.clone(),
                checkpoint.inputs.extension.clone(),
            )
        } else {
            (
                args.data.clone(),
                args.scenario.clone(),
                args.extension.clone(),
            )
        };
    let (job, _) = inputs::job(
        &data_paths,
        scenario_path.as_deref(),
        extension_path.as_deref(),
    )?;
    checkpoint.check_job(&job, &args.checkpoint)?;
    let mut evaluator = spec.start(Arc::new(job), notices())?;
    let report = sepval_fit::rerun::check(&checkpoint, &args.checkpoint, evaluator.as_mut())?;
    println!("{} ({})", report.checked(), evaluator.describe());
    if report.reproduces() {
        println!(
            "generation {}: all {} population and {} archive members reproduce their goals bit \
             for bit",
            report.generation, report.population, report.archive
        );
        return Ok(());
    }
    for m in &report.mismatches {
        println!("{m}");
    }
    bail!(
        "checkpoint {} does not reproduce: {}",
        args.checkpoint.display(),
        report.failures()
    )
}
