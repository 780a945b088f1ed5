//! `--aircraft`, `--store-shape` and `--clearance-mm`: the geometry read and checked
//! (docs/geometry.md), and the clearance of a fit's or a diagnosis's releases asked of
//! [`sepval_predict::releases`] and said.

use std::path::Path;
use std::sync::Arc;

use anyhow::{Context, Result, bail};
use sepval_common::evaluation::{Candidate, Job};
use sepval_common::scenario::Scenario;
use sepval_core::cancel;
use sepval_fit::results::ReleaseClearance;
use sepval_geometry::{Body, Geometry, Role};
use sepval_predict::{ClearanceSettings, releases};

use crate::cli::GeometryArgs;

/// The largest criterion accepted \[mm\] (10 m: anything beyond is a unit mistake).
const MAX_CRITERION_MM: f64 = 10_000.0;

/// The clearance settings of the flags for the store of `scenario`, `None` without
/// `--aircraft`.
pub fn settings(args: &GeometryArgs, scenario: &Scenario) -> Result<Option<ClearanceSettings>> {
    let Some(aircraft) = &args.aircraft else {
        return Ok(None);
    };
    let mm = args.clearance_mm;
    if !(0.0..=MAX_CRITERION_MM).contains(&mm) {
        bail!("--clearance-mm {mm}: expected a number of millimetres from 0 to {MAX_CRITERION_MM}");
    }
    let geometry = geometry(aircraft, args.store_shape.as_deref(), scenario)?;
    Ok(Some(ClearanceSettings {
        geometry: Arc::new(geometry),
        criterion_m: 1e-3 * mm,
        free_after_m: scenario.store.stroke_m,
    }))
}

/// The store (`store_shape`, or the scenario's default) and the aircraft, checked at carriage.
pub fn geometry(
    aircraft: &Path,
    store_shape: Option<&Path>,
    scenario: &Scenario,
) -> Result<Geometry> {
    let stop = &cancel::requested;
    let plane = Body::read_until(aircraft, Role::Aircraft, stop)
        .with_context(|| format!("--aircraft {}", aircraft.display()))?;
    let store = match store_shape {
        Some(p) => Body::read_until(p, Role::Store, stop)
            .with_context(|| format!("--store-shape {}", p.display()))?,
        None => Body::default_store(scenario.store.diameter_m)
            .context("the default store shape, made of the scenario's store.diameter_m")?,
    };
    Geometry::new_until(store, plane, stop).with_context(|| {
        format!(
            "--aircraft {} with the store {}",
            aircraft.display(),
            store_shape.map_or("of the scenario (default shape)".into(), |p| p
                .display()
                .to_string())
        )
    })
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
