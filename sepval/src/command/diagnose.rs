//! `sepval diagnose`: what the simulation still gets wrong after a fit, and why.

use std::sync::Arc;

use anyhow::Result;
use sepval_diagnose::DiagnoseOptions;
use sepval_diagnose::command::DiagnoseRun;
use sepval_predict::releases::Stage;
use sepval_run::out_dir::Input;
use sepval_run::sequence::Writes;

use super::{evaluator_spec, execute, tell};
use crate::cli::DiagnoseArgs;

/// Runs `sepval diagnose`: the flags made a request (the releases, the extension, the settings
/// and the geometry read and checked), then the command's sequence.
pub fn run(args: DiagnoseArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let geometry = super::geometry(&args.geometry);
    let mut read = super::model_inputs(&args.inputs);
    read.extend(Input::files("--validate", &args.validate));
    read.extend(geometry.inputs());
    read.extend(args.after.iter().map(|d| Input::directory("--after", d)));
    read.extend(args.plan.iter().map(|d| Input::directory("--plan", d)));
    let claim = super::fresh_or_overwrite(&args.overwrite);
    let writes = Writes::new(args.out.clone(), "diagnose", claim, read);
    let releases = args.inputs.releases(&args.validate);
    let search = args.baseline.search();
    let (job, options) =
        DiagnoseOptions::configure(&releases, &search, args.out.clone(), &mut tell())?;
    let base = job.events()[0].simulator.scenario();
    let threads = super::count("--threads", args.eval.threads)?;
    let options = DiagnoseOptions {
        strict_tables: args.tables.strict_tables,
        clearance: Stage::of(&geometry, base, threads)?,
        after: args.after,
        plan: args.plan,
        ..options
    };
    let job = Arc::new(job);
    execute(&spec, writes, DiagnoseRun { job, options })
}
