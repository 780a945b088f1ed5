//! `sepval envelope` as a run of the one sequence ([`sepval_run::sequence`]): the sweep as the
//! flags ask for it ([`EnvelopeRequest`]) read and checked with the progress of an interrupted
//! sweep ([`request`]), then each condition predicted with its own evaluator, the record written
//! and what it says.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use sepval_common::evaluation::Job;
use sepval_run::clearance::GeometryPaths;
use sepval_run::inputs::Tell;
use sepval_run::out_dir::{Input, recorded_inputs};
use sepval_run::sequence::{Evaluators, Run, RunError, Said, Writes};
use sepval_solve::run::ProgressObserver;

use crate::grid::Axis;
use crate::progress::{Progress, SweepInputs, claim_sweep, remove_progress};
use crate::{EnvelopeFile, Prepared, Provenance, Sweep, Swept, prepare, sweep, write_outputs};

/// An envelope as the flags ask for it: paths and numbers, nothing read yet.
pub struct EnvelopeRequest {
    /// The fit or diagnosis swept (`--from`).
    pub from: PathBuf,
    /// The geometry; its aircraft is required.
    pub geometry: GeometryPaths,
    /// The extension terms (`--extension`), else the source's.
    pub extension: Option<PathBuf>,
    /// Held-out releases that calibrate the model-form band (`--validate`).
    pub validate: Vec<PathBuf>,
    /// The axes swept, in the order of `[flight]`: each one's flag, its `LO:HI:N` as typed,
    /// and its values.
    pub axes: Vec<(&'static str, String, Axis)>,
    /// Samples per condition.
    pub samples: usize,
    /// The seed of every draw.
    pub seed: u64,
    /// Whether rows holding outliers are dropped.
    pub outliers_drop: bool,
    /// Threads of this process for a condition that runs in it.
    pub threads: usize,
    /// `--out`.
    pub out: PathBuf,
    /// `--resume`: go on with the interrupted sweep in `--out`.
    pub resume: bool,
    /// `--overwrite`.
    pub overwrite: bool,
}

/// Why an envelope's request is refused before anything is read (or, a defect, run twice).
#[derive(Debug, thiserror::Error)]
pub enum EnvelopeRequestError {
    /// No aircraft.
    #[error(
        "--aircraft FILE is required: the aircraft's geometry (e.g. examples/geometry/aircraft.toml)"
    )]
    NoAircraft,
    /// No axis.
    #[error(
        "give at least one axis to sweep: --mach, --altitude-m, --alpha-deg, --beta-deg or --gamma-deg, each LO:HI:N"
    )]
    NoAxis,
    /// The sweep asked to run again (a defect: the sequence runs a run once).
    #[error("the sweep runs once")]
    RanTwice,
}

/// An envelope prepared, with the progress it goes on from.
pub struct EnvelopeRun {
    criterion_mm: f64,
    sweep: Sweep,
    progress: Option<Progress>,
    provenance: Provenance,
}

/// The request read and checked (the source, the geometry, the grid, the progress of an
/// interrupted sweep); where the sweep writes.
pub fn request(r: EnvelopeRequest, tell: Tell) -> Result<(Writes, EnvelopeRun), RunError> {
    let aircraft = r
        .geometry
        .aircraft
        .clone()
        .ok_or(EnvelopeRequestError::NoAircraft)?;
    if r.axes.is_empty() {
        return Err(EnvelopeRequestError::NoAxis.into());
    }
    let inputs = SweepInputs {
        from: &r.from,
        aircraft: &aircraft,
        store_shape: r.geometry.store_shape.as_deref(),
        extension: r.extension.as_deref(),
        validate: &r.validate,
        axes: r.axes.iter().map(|(f, t, _)| (*f, t.clone())).collect(),
        samples: r.samples,
        seed: r.seed,
        clearance_mm: r.geometry.clearance_mm,
        outliers_drop: r.outliers_drop,
    };
    let axes: Vec<Axis> = r.axes.iter().map(|(_, _, a)| *a).collect();
    let Prepared {
        sweep,
        digest,
        named,
        provenance,
    } = prepare(&inputs, &axes, r.threads, &r.out, tell)?;
    let source = &sweep.source;
    let mut read = recorded_inputs(&r.from, &source.inputs, &source.held_out);
    read.extend(Input::files("--extension", &r.extension));
    read.extend(Input::files("--validate", &r.validate));
    read.extend(r.geometry.inputs());
    let fresh = Progress::new(digest, named, sweep.grid.len());
    let (claim, progress, resume) = claim_sweep(&r.out, r.resume, r.overwrite, fresh)?;
    let writes = Writes {
        out: r.out,
        command: "envelope",
        claim,
        inputs: read,
        resume,
    };
    let run = EnvelopeRun {
        criterion_mm: r.geometry.clearance_mm,
        sweep,
        progress: Some(progress),
        provenance,
    };
    Ok((writes, run))
}

impl Run for EnvelopeRun {
    type Found = Swept;

    fn job(&self) -> Option<Arc<Job>> {
        None
    }

    fn run(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        progress: &mut dyn ProgressObserver,
    ) -> Result<Swept, RunError> {
        let from = self.progress.take().ok_or(EnvelopeRequestError::RanTwice)?;
        Ok(sweep(&self.sweep, from, evaluators.each()?, progress)?)
    }

    fn write(&self, swept: Swept, out: &Path, wall_s: f64) -> Result<Said, RunError> {
        let (sweep, criterion_mm) = (&self.sweep, self.criterion_mm);
        let provenance = self.provenance.clone();
        let (file, summary) = EnvelopeFile::of(sweep, swept, criterion_mm, provenance, wall_s);
        write_outputs(&sweep.grid, &file, out)?;
        remove_progress(out);
        Ok(Said::summary(file.terminal(&summary, out)))
    }
}
