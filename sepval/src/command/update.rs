//! `sepval update`: the store's aerodynamic data updated from its releases, as corrections in
//! the scenario's own table forms kept only as far as they predict (docs/update.md).

use std::sync::Arc;

use anyhow::{Result, bail};
use sepval_common::evaluation::Job;
use sepval_fit::out_dir::Request;
use sepval_update::{UpdateOptions, update, write_outputs};

use super::{evaluator_spec, starter, tell};
use crate::cli::{FactorNames, UpdateArgs};

/// Runs `sepval update`. Every input is checked before the output directory is claimed or a
/// worker started; a refusal deletes nothing.
pub fn run(args: UpdateArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    super::several_jobs(&args.eval, "update", "one per round")?;
    let (options, job) = configure(&args)?;
    let mut read = super::model_inputs(&args.inputs);
    read.extend(super::input_files("--validate", &args.validate));
    let run_dir = super::claim_out(
        &args.out,
        Request {
            command: "update",
            claim: super::fresh_or_overwrite(&args.overwrite),
            inputs: &read,
            resume: None,
        },
    )?;
    run_dir.prepare()?;
    let mut start = starter(&spec);
    let u = update(
        &options,
        Arc::new(job),
        &mut start,
        &mut *crate::front::progress(),
    )?;
    write_outputs(&u, &args.out)?;
    if args.daveml {
        let command = format!("sepval update --out {}", args.out.display());
        let data = args.inputs.data.iter().map(|p| p.display().to_string());
        let path = sepval_update::daveml::write_daveml(&u, &args.out, command, data.collect())?;
        say!("daveml:    {}", path.display());
    }
    run_dir.commit();
    crate::front::out(&u.summary(&args.out));
    Ok(())
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
