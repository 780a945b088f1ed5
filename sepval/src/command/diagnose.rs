//! `sepval diagnose`: what the simulation still gets wrong after a fit, and why.

use std::path::Path;
use std::sync::Arc;

use anyhow::Result;
use sepval_diagnose::{DiagnoseOptions, Diagnosis, diagnose};
use sepval_solve::run::ProgressObserver;

use super::sequence::{Evaluators, Run, Said, Writes, execute};
use super::{clearance, evaluator_spec, tell};
use crate::cli::DiagnoseArgs;

/// Runs `sepval diagnose`: the flags made a request (the releases, the extension, the settings
/// and the geometry read and checked), then the command's sequence. The diagnosis writes its
/// files as it goes (the baseline fit's checkpoints, the figures, diagnosis.json).
pub fn run(args: DiagnoseArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let mut read = super::model_inputs(&args.inputs);
    read.extend(super::input_files("--validate", &args.validate));
    read.extend(super::geometry_inputs(&args.geometry));
    let writes = Writes {
        out: args.out.clone(),
        command: "diagnose",
        claim: super::fresh_or_overwrite(&args.overwrite),
        inputs: read,
        resume: None,
    };
    let releases = args.inputs.releases(&args.validate);
    let search = args.baseline.search();
    let (job, options) =
        DiagnoseOptions::configure(&releases, &search, args.out.clone(), &mut tell())?;
    let base = job.events()[0].simulator.scenario();
    let threads = super::count("--threads", args.eval.threads)?;
    let options = DiagnoseOptions {
        strict_tables: args.tables.strict_tables,
        clearance: clearance::stage(&args.geometry, base, threads)?,
        after: args.after.clone(),
        plan: args.plan.clone(),
        ..options
    };
    execute(&spec, writes, Some(Arc::new(job)), Request { options })
}

/// A diagnosis asked for by the flags, configured.
struct Request {
    options: DiagnoseOptions,
}

impl Run for Request {
    type Found = Diagnosis;

    fn run(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        progress: &mut dyn ProgressObserver,
    ) -> Result<Diagnosis> {
        Ok(diagnose(&self.options, evaluators.one()?, progress)?)
    }

    /// The diagnosis wrote its files as it went. The tables left by its fitted runs are told
    /// as simulate and fit tell them (`--strict-tables` refused them after the baseline fit,
    /// before any other work).
    fn write(&self, d: Diagnosis, out: &Path, _wall_s: f64) -> Result<Said> {
        let mut summary = clearance::lines(d.clearance.as_ref());
        summary.push_str(&sepval_diagnose::summary(&d, out));
        let warnings = d.tables_left;
        Ok(Said { summary, warnings })
    }
}
