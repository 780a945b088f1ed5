//! `sepval update`: the store's aerodynamic data updated from its releases, as corrections in
//! the scenario's own table forms kept only as far as they predict (docs/update.md).

use std::sync::Arc;

use anyhow::{Result, bail};
use sepval_common::evaluation::Job;
use sepval_run::out_dir::Input;
use sepval_run::sequence::Writes;
use sepval_update::UpdateOptions;
use sepval_update::command::UpdateRun;

use super::{evaluator_spec, execute, tell};
use crate::cli::{FactorNames, UpdateArgs};

/// Runs `sepval update`: the flags made a request (the releases and the settings read and
/// checked), then the command's sequence, each round's evaluator started in turn.
pub fn run(args: UpdateArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    super::several_jobs(&args.eval, "update", "one per round")?;
    let (options, job) = configure(&args)?;
    let mut read = super::model_inputs(&args.inputs);
    read.extend(Input::files("--validate", &args.validate));
    let writes = Writes::new(
        args.out.clone(),
        "update",
        super::fresh_or_overwrite(&args.overwrite),
        read,
    );
    let data = args.inputs.data.iter().map(|p| p.display().to_string());
    let run = UpdateRun {
        job: Arc::new(job),
        options,
        daveml: args.daveml.then(|| data.collect()),
    };
    execute(&spec, writes, run)
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
