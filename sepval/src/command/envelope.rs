//! `sepval envelope`: the store's clearance to the aircraft predicted over a grid of flight
//! conditions from a fit or a diagnosis, mapped as a separation envelope; `--resume` goes on
//! with an interrupted sweep.

use std::path::Path;
use std::time::Instant;

use anyhow::{Result, bail};
use sepval_common::telemetry::outliers::Policy;
use sepval_envelope::grid::Axis;
use sepval_envelope::progress::{Progress, SweepInputs, claim_sweep, remove_progress};
use sepval_envelope::{EnvelopeFile, Prepared, prepare, sweep, write_outputs};
use sepval_fit::out_dir::{Input, Request, RunDir};
use sepval_plan::conditions::Quantity;
use sepval_predict::Source;

use super::{count, evaluator_spec, starter, tell};
use crate::cli::AxisArg;
use crate::cli::EnvelopeArgs;

/// Runs `sepval envelope`. Every input (the flags, the source, the geometry, the grid) is
/// checked before the output directory is claimed or a worker started.
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
        sweep: sweep_inputs,
        digest,
        named,
        provenance,
    } = prepare(&inputs, &axes, threads, &args.out, &mut tell())?;
    let read = inputs_read(&args, &sweep_inputs.source);
    let progress = Progress::new(digest, named, sweep_inputs.grid.len());
    let (run_dir, progress) = claim(&args, progress, &read)?;
    run_dir.prepare()?;
    let start = Instant::now();
    let mut start_evaluator = starter(&spec);
    let swept = sweep(
        &sweep_inputs,
        progress,
        &mut start_evaluator,
        &mut *crate::front::progress(),
    )?;
    let wall_s = start.elapsed().as_secs_f64();
    let criterion_mm = args.geometry.clearance_mm;
    let (file, summary) = EnvelopeFile::of(&sweep_inputs, swept, criterion_mm, provenance, wall_s);
    write_outputs(&sweep_inputs.grid, &file, &args.out)?;
    remove_progress(&args.out);
    crate::front::out(&file.terminal(&summary, &args.out));
    run_dir.commit();
    Ok(())
}

/// What the sweep reads, which its `--out` may not be, hold or lie inside: the source and the
/// files it records, the extension, the releases to validate and the geometry.
fn inputs_read(args: &EnvelopeArgs, source: &Source) -> Vec<Input> {
    let mut read = super::recorded_inputs(&args.from, &source.inputs, &source.held_out);
    read.extend(super::input_files("--extension", &args.extension));
    read.extend(super::input_files("--validate", &args.validate));
    read.extend(super::geometry_inputs(&args.geometry));
    read
}

/// Claims `--out` (fresh, cleared with --overwrite, or the interrupted sweep's with --resume,
/// whose progress must record the same inputs as `fresh`, the sweep not started) and returns
/// the progress to go on from.
fn claim(args: &EnvelopeArgs, fresh: Progress, read: &[Input]) -> Result<(RunDir, Progress)> {
    let (claim, progress, resume) =
        claim_sweep(&args.out, args.resume, args.overwrite.overwrite, fresh)?;
    let request = Request {
        command: "envelope",
        claim,
        inputs: read,
        resume,
    };
    Ok((super::claim_out(&args.out, request)?, progress))
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
