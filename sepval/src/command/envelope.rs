//! `sepval envelope`: the store's clearance to the aircraft predicted over a grid of flight
//! conditions from a fit or a diagnosis, mapped as a separation envelope; `--resume` goes on
//! with an interrupted sweep.

use anyhow::Result;
use sepval_common::telemetry::outliers::Policy;
use sepval_envelope::command::{EnvelopeRequest, request};

use super::{count, evaluator_spec, execute, tell};
use crate::cli::EnvelopeArgs;

/// Runs `sepval envelope`: the flags made a request (the source, the geometry, the grid and
/// the progress of an interrupted sweep read and checked), then the command's sequence, each
/// condition's evaluator started in turn.
pub fn run(args: EnvelopeArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    super::several_jobs(&args.eval, "envelope", "one per condition")?;
    let r = EnvelopeRequest {
        threads: count("--threads", args.eval.threads)?,
        geometry: super::geometry(&args.geometry),
        axes: (args.grid.given().into_iter())
            .map(|(q, a)| (q.flag(), a.text.clone(), a.axis))
            .collect(),
        outliers_drop: args.outliers.policy() == Policy::Drop,
        from: args.from,
        extension: args.extension,
        validate: args.validate,
        samples: args.samples,
        seed: args.seed,
        out: args.out,
        resume: args.resume,
        overwrite: args.overwrite.overwrite,
    };
    let (writes, run) = request(r, &mut tell()).map_err(anyhow::Error::from_boxed)?;
    execute(&spec, writes, run)
}
