//! Stage 0, **prepare**: a sweep asked for ([`SweepInputs`], the flags as given, and the axes
//! parsed) read and checked before anything runs or is written: the prediction's settings,
//! the source and its releases, the grid about the source's scenario, the geometry, and the
//! digest of every input that the progress file and the record keep.

use std::collections::BTreeMap;
use std::path::Path;

use sepval_common::telemetry::outliers::Policy;
use sepval_predict::{ClearanceSettings, Settings, SourceInputs, source_inputs};

use crate::grid::{Axis, Grid, GridError};
use crate::progress::{DigestError, SweepInputs, progress_path};
use crate::record::Provenance;
use crate::sweep::Sweep;

/// A sweep that cannot be prepared. Nothing was written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PrepareError {
    /// The samples refused.
    #[error(transparent)]
    Settings(#[from] sepval_predict::ConditionError),
    /// The source (`--from`), its releases or those held out.
    #[error(transparent)]
    Source(#[from] sepval_predict::source::SourceInputsError),
    /// The grid.
    #[error(transparent)]
    Grid(#[from] GridError),
    /// The geometry.
    #[error(transparent)]
    Clearance(#[from] sepval_predict::clearance::ClearanceInputError),
    /// An input that cannot be read for its digest.
    #[error(transparent)]
    Digest(#[from] DigestError),
}

/// A sweep read and checked: what it runs, and what its progress and record say of it.
pub struct Prepared {
    /// What the sweep runs.
    pub sweep: Sweep,
    /// The SHA-256 of its inputs, as its progress file and record keep it.
    pub digest: String,
    /// Each input by name: a file's SHA-256, a setting's value.
    pub named: BTreeMap<String, String>,
    /// Where it came from, as its record keeps it.
    pub provenance: Provenance,
}

/// Prepares the sweep `inputs` ask for over `axes` (the same axes as `inputs.axes`, parsed),
/// its conditions predicted on `threads` threads of this process where they run in it, its
/// progress saved in `out`; what the releases' screening leaves out is told to `tell`.
pub fn prepare(
    inputs: &SweepInputs,
    axes: &[Axis],
    threads: usize,
    out: &Path,
    tell: sepval_run::inputs::Tell,
) -> Result<Prepared, PrepareError> {
    let settings = Settings {
        samples: inputs.samples,
        level: 0.95,
        seed: inputs.seed,
        with_noise: false,
        threads,
    };
    settings.check()?;
    let policy = if inputs.outliers_drop {
        Policy::Drop
    } else {
        Policy::Refuse
    };
    let SourceInputs {
        source,
        fitted,
        held_out,
    } = source_inputs(inputs.from, inputs.extension, inputs.validate, policy, tell)?;
    let base = fitted.events()[0].simulator.scenario().clone();
    let grid = Grid::of(&base, axes)?;
    let clearance = ClearanceSettings::read(
        inputs.aircraft,
        inputs.store_shape,
        inputs.clearance_mm,
        &base,
    )?;
    let (digest, named) = inputs.digest()?;
    let provenance = Provenance {
        samples: inputs.samples,
        seed: inputs.seed,
        inputs_sha256: digest.clone(),
        from: inputs.from.display().to_string(),
        aircraft: inputs.aircraft.display().to_string(),
        store_shape: inputs
            .store_shape
            .map_or("default".into(), |p| p.display().to_string()),
    };
    let sweep = Sweep {
        source,
        fitted,
        held_out,
        settings,
        grid,
        clearance,
        progress_path: progress_path(out),
    };
    Ok(Prepared {
        sweep,
        digest,
        named,
        provenance,
    })
}
