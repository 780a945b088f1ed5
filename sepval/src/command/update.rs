//! `sepval update`: the store's aerodynamic data updated from its releases, as corrections in
//! the scenario's own table forms kept only as far as they predict (docs/update.md).

use std::path::Path;
use std::sync::Arc;

use anyhow::{Result, bail};
use sepval_common::evaluation::Job;
use sepval_solve::run::ProgressObserver;
use sepval_update::{Update, UpdateOptions, update, write_outputs};

use super::sequence::{Evaluators, Run, Said, Writes, execute};
use super::{evaluator_spec, tell};
use crate::cli::{FactorNames, UpdateArgs};

/// Runs `sepval update`: the flags made a request (the releases and the settings read and
/// checked), then the command's sequence, each round's evaluator started in turn.
pub fn run(args: UpdateArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    super::several_jobs(&args.eval, "update", "one per round")?;
    let (options, job) = configure(&args)?;
    let mut read = super::model_inputs(&args.inputs);
    read.extend(super::input_files("--validate", &args.validate));
    let writes = Writes {
        out: args.out.clone(),
        command: "update",
        claim: super::fresh_or_overwrite(&args.overwrite),
        inputs: read,
        resume: None,
    };
    let job = Arc::new(job);
    execute(&spec, writes, None, Request { args, options, job })
}

/// An update asked for by the flags, configured.
struct Request {
    args: UpdateArgs,
    options: UpdateOptions,
    job: Arc<Job>,
}

impl Run for Request {
    type Found = Update;

    fn run(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        progress: &mut dyn ProgressObserver,
    ) -> Result<Update> {
        let job = Arc::clone(&self.job);
        Ok(update(&self.options, job, evaluators.each()?, progress)?)
    }

    fn write(&self, update: Update, out: &Path, _wall_s: f64) -> Result<Said> {
        write_outputs(&update, out)?;
        let mut summary = String::new();
        if self.args.daveml {
            let command = format!("sepval update --out {}", out.display());
            let data = self
                .args
                .inputs
                .data
                .iter()
                .map(|p| p.display().to_string());
            let path = sepval_update::daveml::write_daveml(&update, out, command, data.collect())?;
            summary.push_str(&format!("daveml:    {}\n", path.display()));
        }
        summary.push_str(&update.summary(out));
        Ok(Said::summary(summary))
    }
}

/// The flags as a validated configuration, and the job of the `--data` releases.
fn configure(args: &UpdateArgs) -> Result<(UpdateOptions, Job)> {
    if args.inputs.data.is_empty() {
        bail!(
            "--data FILE.csv is required (repeat it for each release): the releases that update the store's data"
        );
    }
    let releases = args.inputs.releases(&args.validate);
    let search = args.baseline.search();
    let free = args
        .free
        .as_ref()
        .map(|FactorNames(names)| names.as_slice());
    let (job, options) =
        UpdateOptions::configure(&releases, &search, free, &args.out, &mut tell())?;
    Ok((options, job))
}
