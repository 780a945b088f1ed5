//! `sepval predict`: a release not flown, with its bands, from a fit or a diagnosis; with
//! `--data`, the post-flight check of a flown release against them.

use std::path::Path;
use std::sync::Arc;

use anyhow::{Context, Result};
use sepval_predict::{
    Flown, Prediction, Prepared, Settings, SourceInputs, predict, prediction_file, prepare,
    source_inputs, write_outputs,
};
use sepval_run::inputs;
use sepval_solve::run::ProgressObserver;

use super::sequence::{Evaluators, Run, Said, Writes, execute};
use super::{clearance, count, evaluator_spec, input_files, tell};
use crate::cli::PredictArgs;

/// Runs `sepval predict`: the flags made a request (every input read and checked: the source,
/// its releases, the condition, the flown release), then the command's sequence.
pub fn run(args: PredictArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let (writes, request) = request(args)?;
    let job = Arc::new(request.prepared.job.clone());
    execute(&spec, writes, Some(job), request)
}

/// A prediction asked for by the flags, prepared.
struct Request {
    args: PredictArgs,
    prepared: Prepared,
}

/// The flags and what they name, read and checked; where the prediction writes.
fn request(args: PredictArgs) -> Result<(Writes, Request)> {
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
    let mut read =
        sepval_run::out_dir::recorded_inputs(&args.from, &source.inputs, &source.held_out);
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
    let writes = Writes {
        out: args.out.clone(),
        command: "predict",
        claim: super::fresh_or_overwrite(&args.overwrite),
        inputs: read,
        resume: None,
    };
    Ok((writes, Request { args, prepared }))
}

impl Run for Request {
    type Found = Prediction;

    fn run(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        progress: &mut dyn ProgressObserver,
    ) -> Result<Prediction> {
        Ok(predict(&self.prepared, evaluators.one()?, progress)?)
    }

    fn write(&self, found: Prediction, out: &Path, wall_s: f64) -> Result<Said> {
        let file = prediction_file(&self.prepared, &found, &self.args.from, wall_s);
        write_outputs(&found, &file, out)?;
        Ok(Said::summary(sepval_predict::summary(&file, out)))
    }
}
