//! `sepval plan`: the next release to fly, from a diagnosis.

use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result};
use sepval_fit::out_dir::Request;
use sepval_plan::{Range, plan, plan_file, prepare, read_diagnosis, write_outputs};

use super::{evaluator_spec, notices, tell};
use crate::cli::PlanArgs;

/// Runs `sepval plan`. Every input (the flags, the diagnosis, its releases, the ranges against
/// its scenario) is checked before the output directory is claimed or a worker started, so a
/// refusal writes nothing; the directory is cleared (`--overwrite`) only once the plan is made.
pub fn run(args: PlanArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let ranges = ranges(&args);
    let diagnosis = read_diagnosis(&args.from)?;
    let record = diagnosis.inputs.clone();
    let (flown, _) = sepval_fit::inputs::job(
        &record.data,
        record.scenario.as_deref(),
        record.extension.as_deref(),
        record.outliers,
        &mut tell(),
    )
    .with_context(|| {
        format!(
            "--from {}: the releases the diagnosis was made from",
            args.from.display()
        )
    })?;
    let read = super::recorded_inputs(&args.from, &record, &[]);
    let prepared = prepare(diagnosis, &flown, &ranges, args.points)?;
    let run_dir = super::claim_out(
        &args.out,
        Request {
            command: "plan",
            claim: super::fresh_or_overwrite(&args.overwrite),
            inputs: &read,
            resume: None,
        },
    )?;
    let start = Instant::now();
    let mut evaluator = spec.start(Arc::new(prepared.job.clone()), notices())?;
    let found = plan(
        &prepared,
        evaluator.as_mut(),
        &mut *crate::front::progress(),
    )?;
    drop(evaluator);
    let file = plan_file(&prepared, &found, &args.from, start.elapsed().as_secs_f64());
    // Cleared (--overwrite) only now: a run stopped while it computed leaves the earlier one.
    run_dir.prepare()?;
    write_outputs(&prepared, &found, &file, &args.out)?;
    crate::front::out(&sepval_plan::summary(&file, &args.out));
    run_dir.commit();
    Ok(())
}

/// The ranges of the five condition flags given (parsed by clap), in the order of `[flight]`.
fn ranges(args: &PlanArgs) -> Vec<Range> {
    [
        &args.mach,
        &args.altitude_m,
        &args.alpha_deg,
        &args.beta_deg,
        &args.gamma_deg,
    ]
    .into_iter()
    .flatten()
    .cloned()
    .collect()
}
