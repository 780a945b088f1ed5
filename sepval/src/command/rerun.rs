//! `sepval rerun`: a saved generation re-evaluated, replayed and checked bit for bit.

use std::sync::Arc;

use anyhow::{Result, bail};
use sepval_fit::checkpoint::Checkpoint;
use sepval_fit::rerun;
use sepval_fit::resume::InputPaths;

use super::{evaluator_spec, notices, tell};
use crate::cli::RerunArgs;

/// Runs `sepval rerun`.
pub fn run(args: RerunArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let checkpoint = Checkpoint::load(&args.checkpoint)?;
    let given = InputPaths {
        data: args.inputs.data.clone(),
        scenario: args.inputs.model.scenario.clone(),
        extension: args.inputs.model.extension.clone(),
    };
    let outliers = args.inputs.outliers.given();
    let job = rerun::job(&checkpoint, &args.checkpoint, &given, outliers, &mut tell())?;
    let mut evaluator = spec.start(Arc::new(job), notices())?;
    let report = rerun::check(&checkpoint, &args.checkpoint, evaluator.as_mut())?;
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
