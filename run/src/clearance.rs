//! The clearance to the aircraft of a record's releases (`--aircraft`, docs/envelope.md section
//! 14.2): what result.json and diagnosis.json record of it, and the stage that finds it
//! ([`ClearReleases`]), asked by the fit and the diagnosis before their record is sealed, so
//! that a record is written once. The stage is the prediction's (`sepval_predict::releases`,
//! which knows the geometry); the pipelines below it only call it. [`GeometryPaths`] is the
//! geometry as given, before it is read.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use sepval_common::evaluation::{Candidate, Job};
use serde::{Deserialize, Serialize};

use crate::out_dir::Input;

/// The clearance of one release's trajectory (docs/envelope.md section 14.2), as result.json and
/// diagnosis.json record it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReleaseClearance {
    /// The release.
    pub release: String,
    /// The criterion \[mm\].
    pub criterion_mm: f64,
    /// The smallest clearance once the store has moved the ejector's stroke \[mm\].
    pub min_clearance_mm: f64,
    /// Its time \[s\].
    pub t_min_s: f64,
    /// The store's part that comes closest.
    pub store_part: String,
    /// The aircraft's part it comes closest to.
    pub aircraft_part: String,
    /// Whether the smallest clearance keeps the criterion.
    pub clears: bool,
    /// Whether the store moved the stroke within the record (else every sample counts).
    pub free_flight_reached: bool,
}

/// The geometry a run's clearance is found with, as given (`--aircraft`, `--store-shape`,
/// `--clearance-mm`; read and checked by `sepval_predict::ClearanceSettings`).
#[derive(Debug, Clone, Default)]
pub struct GeometryPaths {
    /// The aircraft's geometry; without it, no clearance is found.
    pub aircraft: Option<PathBuf>,
    /// The store's shape (else a body of revolution of the scenario's diameter).
    pub store_shape: Option<PathBuf>,
    /// The clearance criterion \[mm\].
    pub clearance_mm: f64,
}

impl GeometryPaths {
    /// Its files, as inputs of the run.
    pub fn inputs(&self) -> Vec<Input> {
        let mut out = Input::files("--aircraft", &self.aircraft);
        out.extend(Input::files("--store-shape", &self.store_shape));
        out
    }
}

impl ReleaseClearance {
    /// The release's clearance in one line, as the fit and the diagnosis print it.
    pub fn line(&self) -> String {
        format!(
            "{}: smallest {:.1} mm at t = {:.3} s ({} / {}): {}",
            self.release,
            self.min_clearance_mm,
            self.t_min_s,
            self.store_part,
            self.aircraft_part,
            if self.clears {
                "clears"
            } else {
                "does not clear"
            }
        )
    }
}

/// One line per release of what a record holds of their clearance (`clearance: ...`), as the
/// fit's and the diagnosis's summaries begin.
pub fn lines(records: Option<&Vec<ReleaseClearance>>) -> String {
    let line = |r: &ReleaseClearance| format!("clearance: {}\n", r.line());
    records.into_iter().flatten().map(line).collect()
}

/// Why the clearance of the releases could not be found: the stage's own error, kept whole
/// (its cause chain) for the command to show.
pub type StageError = Box<dyn std::error::Error + Send + Sync>;

/// The clearance of each release of a job flown by one model: its trajectories simulated,
/// their clearance found, `clearance.csv` and `figures/clearance.png` written into the run's
/// directory, and one [`ReleaseClearance`] returned per release, in the job's order.
pub trait ClearReleases: Send + Sync {
    /// The releases of `job` flown by `candidate`, their files written into `out`.
    fn releases(
        &self,
        job: &Arc<Job>,
        candidate: Candidate,
        out: &Path,
    ) -> Result<Vec<ReleaseClearance>, StageError>;
}
