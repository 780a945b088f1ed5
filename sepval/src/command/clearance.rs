//! `--aircraft`, `--store-shape` and `--clearance-mm`: the geometry read and checked by
//! [`ClearanceSettings::read`] (docs/geometry.md), and the clearance of a fit's or a
//! diagnosis's releases asked of [`sepval_predict::releases`] and said.

use std::path::Path;
use std::sync::Arc;

use anyhow::Result;
use sepval_common::evaluation::{Candidate, Job};
use sepval_common::scenario::Scenario;
use sepval_fit::results::ReleaseClearance;
use sepval_predict::{ClearanceSettings, releases};

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

/// The clearance of the answer's trajectories of a fit or diagnosis in `out`, for
/// `--aircraft` given ([`sepval_predict::releases`]): `candidate` flies each release of `job`
/// on `threads` threads; clearance.csv and figures/clearance.png are written, `record`
/// (result.json or diagnosis.json, named `file`) is rewritten with its `clearance`, and one
/// line per release is printed.
pub fn record_releases<T: serde::Serialize>(
    c: &ClearanceSettings,
    (job, candidate, threads): (&Arc<Job>, Candidate, usize),
    out: &Path,
    file: &str,
    record: &mut T,
    set: impl FnOnce(&mut T, Vec<ReleaseClearance>),
) -> Result<()> {
    let flown = releases::simulate(job, candidate, threads)?;
    let of = releases::of_releases(c, &flown)?;
    releases::write(c, &flown, &of, out)?;
    let records: Vec<ReleaseClearance> = of.into_iter().map(|(r, _)| r).collect();
    for r in &records {
        say!("clearance: {}", releases::line(r));
    }
    set(record, records);
    sepval_fit::record::write_record(&out.join(file), record)?;
    Ok(())
}
