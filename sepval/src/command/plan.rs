//! `sepval plan`: the next release to fly, from a diagnosis.

use std::path::Path;
use std::sync::Arc;

use anyhow::Result;
use sepval_plan::{Plan, Prepared, Range, plan, plan_file, prepare, read_from};
use sepval_solve::run::ProgressObserver;

use super::sequence::{Evaluators, Run, Said, Writes, execute};
use super::{evaluator_spec, tell};
use crate::cli::PlanArgs;

/// Runs `sepval plan`: the flags made a request (the diagnosis, its releases and the ranges
/// against its scenario read and checked), then the command's sequence.
pub fn run(args: PlanArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let ranges = ranges(&args);
    let (diagnosis, flown) = read_from(&args.from, &mut tell())?;
    let read = sepval_run::out_dir::recorded_inputs(&args.from, &diagnosis.inputs, &[]);
    let prepared = prepare(diagnosis, &flown, &ranges, args.points)?;
    let writes = Writes {
        out: args.out.clone(),
        command: "plan",
        claim: super::fresh_or_overwrite(&args.overwrite),
        inputs: read,
        resume: None,
    };
    let job = Arc::new(prepared.job.clone());
    execute(&spec, writes, Some(job), Request { args, prepared })
}

/// A plan asked for by the flags, prepared.
struct Request {
    args: PlanArgs,
    prepared: Prepared,
}

impl Run for Request {
    type Found = Plan;

    fn run(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        progress: &mut dyn ProgressObserver,
    ) -> Result<Plan> {
        Ok(plan(&self.prepared, evaluators.one()?, progress)?)
    }

    fn write(&self, found: Plan, out: &Path, wall_s: f64) -> Result<Said> {
        let file = plan_file(&self.prepared, &found, &self.args.from, wall_s);
        sepval_plan::write_outputs(&self.prepared, &found, &file, out)?;
        Ok(Said::summary(sepval_plan::summary(&file, out)))
    }
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
