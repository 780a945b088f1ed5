//! `sepval envelope`: the store's clearance to the aircraft predicted over a grid of flight
//! conditions from a fit or a diagnosis, mapped as a separation envelope; `--resume` goes on
//! with an interrupted sweep.

use std::path::Path;

use anyhow::{Context, Result, bail};
use sepval_common::telemetry::outliers::Policy;
use sepval_envelope::grid::Axis;
use sepval_envelope::progress::{Progress, SweepInputs, claim_sweep, remove_progress};
use sepval_envelope::{
    EnvelopeFile, Prepared, Provenance, Sweep, Swept, prepare, sweep, write_outputs,
};
use sepval_plan::conditions::Quantity;
use sepval_predict::Source;
use sepval_run::out_dir::Input;
use sepval_solve::run::ProgressObserver;

use super::sequence::{Evaluators, Run, Said, Writes, execute};
use super::{count, evaluator_spec, tell};
use crate::cli::AxisArg;
use crate::cli::EnvelopeArgs;

/// Runs `sepval envelope`: the flags made a request (the source, the geometry, the grid and
/// the progress of an interrupted sweep read and checked), then the command's sequence, each
/// condition's evaluator started in turn.
pub fn run(args: EnvelopeArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    super::several_jobs(&args.eval, "envelope", "one per condition")?;
    let threads = count("--threads", args.eval.threads)?;
    let Some(aircraft) = args.geometry.aircraft.clone() else {
        bail!(
            "--aircraft FILE is required: the aircraft's geometry (e.g. examples/geometry/aircraft.toml)"
        );
    };
    let given = args.grid.given();
    if given.is_empty() {
        bail!(
            "give at least one axis to sweep: --mach, --altitude-m, --alpha-deg, --beta-deg or --gamma-deg, each LO:HI:N"
        );
    }
    let axes: Vec<Axis> = given.iter().map(|(_, a)| a.axis).collect();
    let inputs = sweep_inputs(&args, &aircraft, &given);
    let Prepared {
        sweep,
        digest,
        named,
        provenance,
    } = prepare(&inputs, &axes, threads, &args.out, &mut tell())?;
    let read = inputs_read(&args, &sweep.source);
    let fresh = Progress::new(digest, named, sweep.grid.len());
    let (claim, progress, resume) =
        claim_sweep(&args.out, args.resume, args.overwrite.overwrite, fresh)?;
    let writes = Writes {
        out: args.out.clone(),
        command: "envelope",
        claim,
        inputs: read,
        resume,
    };
    let request = Request {
        criterion_mm: args.geometry.clearance_mm,
        sweep,
        progress: Some(progress),
        provenance,
    };
    execute(&spec, writes, None, request)
}

/// An envelope asked for by the flags, prepared, with the progress it goes on from.
struct Request {
    criterion_mm: f64,
    sweep: Sweep,
    progress: Option<Progress>,
    provenance: Provenance,
}

impl Run for Request {
    type Found = Swept;

    fn run(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        progress: &mut dyn ProgressObserver,
    ) -> Result<Swept> {
        let from = self.progress.take().context("the sweep runs once")?;
        Ok(sweep(&self.sweep, from, evaluators.each()?, progress)?)
    }

    fn write(&self, swept: Swept, out: &Path, wall_s: f64) -> Result<Said> {
        let (sweep, criterion_mm) = (&self.sweep, self.criterion_mm);
        let provenance = self.provenance.clone();
        let (file, summary) = EnvelopeFile::of(sweep, swept, criterion_mm, provenance, wall_s);
        write_outputs(&sweep.grid, &file, out)?;
        remove_progress(out);
        Ok(Said::summary(file.terminal(&summary, out)))
    }
}

/// What the sweep reads, which its `--out` may not be, hold or lie inside: the source and the
/// files it records, the extension, the releases to validate and the geometry.
fn inputs_read(args: &EnvelopeArgs, source: &Source) -> Vec<Input> {
    let mut read =
        sepval_run::out_dir::recorded_inputs(&args.from, &source.inputs, &source.held_out);
    read.extend(super::input_files("--extension", &args.extension));
    read.extend(super::input_files("--validate", &args.validate));
    read.extend(super::geometry_inputs(&args.geometry));
    read
}

/// What decides the envelope, as its progress file records it.
fn sweep_inputs<'a>(
    args: &'a EnvelopeArgs,
    aircraft: &'a Path,
    axes: &[(Quantity, &AxisArg)],
) -> SweepInputs<'a> {
    SweepInputs {
        from: &args.from,
        aircraft,
        store_shape: args.geometry.store_shape.as_deref(),
        extension: args.extension.as_deref(),
        validate: &args.validate,
        axes: axes
            .iter()
            .map(|(q, a)| (q.flag(), a.text.clone()))
            .collect(),
        samples: args.samples,
        seed: args.seed,
        clearance_mm: args.geometry.clearance_mm,
        outliers_drop: args.outliers.policy() == Policy::Drop,
    }
}
