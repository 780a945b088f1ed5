//! `sepval rerun`: a saved generation re-evaluated and checked bit for bit.

use std::sync::Arc;

use anyhow::{Result, bail};
use sepval_coordinator::checkpoint::Checkpoint;

use super::{evaluator_spec, inputs, notices};
use crate::cli::RerunArgs;

/// Runs `sepval rerun`.
pub fn run(args: RerunArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let checkpoint = Checkpoint::load(&args.checkpoint)?;
    let (data_paths, scenario_path) = if args.data.is_empty() && args.scenario.is_none() {
        (
            checkpoint.inputs.data.clone(),
            checkpoint.inputs.scenario.clone(),
        )
    } else {
        (args.data.clone(), args.scenario.clone())
    };
    let (job, _) = inputs::job(&data_paths, scenario_path.as_deref())?;
    checkpoint.check_job(&job, &args.checkpoint)?;
    let mut evaluator = spec.start(Arc::new(job), notices())?;
    let mismatches =
        sepval_coordinator::rerun::rerun(&checkpoint, &args.checkpoint, evaluator.as_mut())?;
    let n = checkpoint.state.population.len();
    if mismatches.is_empty() {
        println!(
            "generation {}: all {n} members reproduce their goals bit for bit ({})",
            checkpoint.state.generation,
            evaluator.describe()
        );
        return Ok(());
    }
    for m in &mismatches {
        println!(
            "member {}: saved {:?}, rerun {:?}",
            m.member, m.saved, m.rerun
        );
    }
    bail!(
        "generation {}: {} of {n} members do not reproduce their goals bit for bit",
        checkpoint.state.generation,
        mismatches.len()
    )
}
