//! `sepval predict`: a release not flown, with its bands, from a fit or a diagnosis; with
//! `--data`, the post-flight check of a flown release against them.

use anyhow::Result;
use sepval_predict::Settings;
use sepval_predict::command::{PredictRequest, request};

use super::{count, evaluator_spec, execute, tell};
use crate::cli::PredictArgs;

/// Runs `sepval predict`: the flags made a request (every input read and checked: the source,
/// its releases, the condition, the flown release), then the command's sequence.
pub fn run(args: PredictArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let settings = Settings {
        samples: args.samples,
        level: args.level,
        seed: args.seed,
        with_noise: args.with_noise,
        threads: count("--threads", args.eval.threads)?,
    };
    let r = PredictRequest {
        policy: args.outliers.policy(),
        geometry: super::geometry(&args.geometry),
        claim: super::fresh_or_overwrite(&args.overwrite),
        from: args.from,
        scenario: args.scenario,
        extension: args.extension,
        data: args.data,
        validate: args.validate,
        settings,
        out: args.out,
    };
    let (writes, run) = request(r, &mut tell()).map_err(anyhow::Error::from_boxed)?;
    execute(&spec, writes, run)
}
