//! `sepval predict`: a release not flown, with its bands, from a fit or a diagnosis; with
//! `--data`, the post-flight check of a flown release against them.

use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result};
use sepval_fit::inputs;
use sepval_fit::out_dir::Request;
use sepval_predict::{
    Flown, Settings, SourceInputs, predict, prediction_file, prepare, source_inputs, write_outputs,
};

use super::{clearance, count, evaluator_spec, input_files, notices, tell};
use crate::cli::PredictArgs;

/// Runs `sepval predict`. Every input (the flags, the source, its releases, the condition, the
/// flown release) is checked before the output directory is claimed or a worker started, so a
/// refusal writes nothing; the directory is cleared (`--overwrite`) only once the prediction
/// is made, just before its files are written.
pub fn run(args: PredictArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let settings = Settings {
        samples: args.samples,
        level: args.level,
        seed: args.seed,
        with_noise: args.with_noise,
        threads: count("--threads", args.eval.threads)?,
    };
    settings.check()?;
    let policy = args.outliers.policy();
    let SourceInputs {
        source,
        fitted,
        held_out,
    } = source_inputs(
        &args.from,
        args.extension.as_deref(),
        &args.validate,
        policy,
        &mut tell(),
    )?;
    let mut read = super::recorded_inputs(&args.from, &source.inputs, &source.held_out);
    read.extend(input_files("--scenario", [&args.scenario]));
    read.extend(input_files("--extension", &args.extension));
    read.extend(input_files("--data", &args.data));
    read.extend(input_files("--validate", &args.validate));
    read.extend(super::geometry_inputs(&args.geometry));
    let extension = args.extension.clone().or(source.inputs.extension.clone());
    let condition = inputs::scenario(Some(&args.scenario), extension.as_deref())
        .with_context(|| format!("--scenario {}", args.scenario.display()))?;
    sepval_predict::check_condition(fitted.events()[0].simulator.scenario(), &condition)
        .with_context(|| format!("--scenario {}", args.scenario.display()))?;
    let flown = match &args.data {
        Some(path) => {
            let scenario_name = format!("--scenario {}", args.scenario.display());
            let at = (scenario_name.as_str(), &condition);
            Some(Flown::read(path, at, policy, &mut tell())?)
        }
        None => None,
    };
    let clearance = clearance::settings(&args.geometry, &condition)?;
    let prepared = prepare(source, fitted, condition, held_out, flown, settings)?;
    let prepared = match clearance {
        Some(c) => prepared.with_clearance(c),
        None => prepared,
    };
    let run_dir = super::claim_out(
        &args.out,
        Request {
            command: "predict",
            claim: super::fresh_or_overwrite(&args.overwrite),
            inputs: &read,
            resume: None,
        },
    )?;
    let start = Instant::now();
    let mut evaluator = spec.start(Arc::new(prepared.job.clone()), notices())?;
    let found = predict(
        &prepared,
        evaluator.as_mut(),
        &mut *crate::front::progress(),
    )?;
    drop(evaluator);
    let file = prediction_file(&prepared, &found, &args.from, start.elapsed().as_secs_f64());
    // Cleared (--overwrite) only now: a run stopped while it computed leaves the earlier one.
    run_dir.prepare()?;
    write_outputs(&found, &file, &args.out)?;
    crate::front::out(&sepval_predict::summary(&file, &args.out));
    run_dir.commit();
    Ok(())
}
