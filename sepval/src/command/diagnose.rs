//! `sepval diagnose`: what the simulation still gets wrong after a fit, and why.

use std::sync::Arc;

use anyhow::Result;
use sepval_common::evaluation::Job;
use sepval_diagnose::{DiagnoseOptions, diagnose};
use sepval_fit::out_dir::Request;

use super::{clearance, evaluator_spec, notices, tell};
use crate::cli::DiagnoseArgs;

/// Runs `sepval diagnose`. The output directory is claimed (locked and checked) before anything
/// runs, so that no worker starts for a refused `--out`, and cleared (`--overwrite`) only once
/// every input is checked and the workers run: a refusal deletes nothing.
pub fn run(args: DiagnoseArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    // The output directory, before anything runs (no worker is started for a refused --out).
    let mut read = super::model_inputs(&args.inputs);
    read.extend(super::input_files("--validate", &args.validate));
    read.extend(super::geometry_inputs(&args.geometry));
    let run_dir = super::claim_out(
        &args.out,
        Request {
            command: "diagnose",
            claim: super::fresh_or_overwrite(&args.overwrite),
            inputs: &read,
            resume: None,
        },
    )?;
    let DiagnoseConfig { job, options } = configure(&args)?;
    let base = job.events()[0].simulator.scenario().clone();
    let geometry = clearance::settings(&args.geometry, &base)?;
    let mut evaluator = spec.start(Arc::new(job), notices())?;
    run_dir.prepare()?;
    let mut d = diagnose(&options, evaluator.as_mut(), &mut *crate::front::progress())?;
    if let Some(c) = &geometry {
        // The answer's trajectories: its model rebuilt as predict rebuilds it.
        let job = evaluator.job();
        let answer = sepval_predict::releases::diagnosis_answer(&d, &args.out, job)?;
        let threads = super::count("--threads", args.eval.threads)?;
        let flown = (job, answer, threads);
        clearance::record_releases(c, flown, &args.out, "diagnosis.json", &mut d, |d, v| {
            d.clearance = Some(v)
        })?;
    }
    crate::front::out(&sepval_diagnose::summary(&d, &args.out));
    run_dir.commit();
    // Tables left by the fitted runs, as simulate and fit report them (--strict-tables refused
    // them after the baseline fit, before any other work).
    for l in &d.tables_left {
        note!("warning: {l}");
    }
    Ok(())
}

/// A diagnosis as the flags ask for it, validated.
struct DiagnoseConfig {
    /// The job of the `--data` files.
    job: Job,
    /// The options of the diagnosis: its baseline fit, refinements and `--validate` releases.
    options: DiagnoseOptions,
}

/// The flags as a validated configuration.
fn configure(args: &DiagnoseArgs) -> Result<DiagnoseConfig> {
    let releases = args.inputs.releases(&args.validate);
    let search = args.baseline.search();
    let (job, options) =
        DiagnoseOptions::configure(&releases, &search, args.out.clone(), &mut tell())?;
    let options = DiagnoseOptions {
        strict_tables: args.tables.strict_tables,
        ..options
    };
    Ok(DiagnoseConfig { job, options })
}
