//! `sepval plan`: the next release to fly, from a diagnosis.

use anyhow::Result;
use sepval_plan::command::{PlanRequest, request};

use super::{evaluator_spec, execute, tell};
use crate::cli::PlanArgs;

/// Runs `sepval plan`: the flags made a request (the diagnosis, its releases and the ranges
/// against its scenario read and checked), then the command's sequence.
pub fn run(args: PlanArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let condition_flags = [
        args.mach,
        args.altitude_m,
        args.alpha_deg,
        args.beta_deg,
        args.gamma_deg,
    ];
    let r = PlanRequest {
        from: args.from,
        // The ranges given (parsed by clap), in the order of `[flight]`.
        ranges: condition_flags.into_iter().flatten().collect(),
        points: args.points,
        claim: super::fresh_or_overwrite(&args.overwrite),
        out: args.out,
    };
    let (writes, run) = request(r, &mut tell())?;
    execute(&spec, writes, run)
}
