//! `--aircraft`, `--store-shape` and `--clearance-mm`: the geometry read and checked by
//! [`ClearanceSettings::read`] (docs/geometry.md); for a fit and a diagnosis, the stage that
//! finds their releases' clearance before they seal their record ([`stage`],
//! [`sepval_predict::releases::Stage`]), and its lines from the record ([`lines`]).

use std::sync::Arc;

use anyhow::Result;
use sepval_common::scenario::Scenario;
use sepval_predict::{ClearanceSettings, releases};
use sepval_run::clearance::{ClearReleases, ReleaseClearance};

use crate::cli::GeometryArgs;

/// The clearance settings of the flags for the store of `scenario`, `None` without
/// `--aircraft` ([`ClearanceSettings::read`]).
pub fn settings(args: &GeometryArgs, scenario: &Scenario) -> Result<Option<ClearanceSettings>> {
    let Some(aircraft) = &args.aircraft else {
        return Ok(None);
    };
    let store_shape = args.store_shape.as_deref();
    let c = ClearanceSettings::read(aircraft, store_shape, args.clearance_mm, scenario)?;
    Ok(Some(c))
}

/// The clearance stage of a fit or a diagnosis of releases at `scenario`'s store, flying them
/// on `threads` threads; `None` without `--aircraft`.
pub fn stage(
    args: &GeometryArgs,
    scenario: &Scenario,
    threads: usize,
) -> Result<Option<Arc<dyn ClearReleases>>> {
    let stage = settings(args, scenario)?.map(|settings| {
        let stage: Arc<dyn ClearReleases> = Arc::new(releases::Stage { settings, threads });
        stage
    });
    Ok(stage)
}

/// One line per release of what a record holds of their clearance.
pub fn lines(records: Option<&Vec<ReleaseClearance>>) -> String {
    let line = |r| format!("clearance: {}\n", releases::line(r));
    records.into_iter().flatten().map(line).collect()
}
