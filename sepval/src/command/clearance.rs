//! `--aircraft`, `--store-shape` and `--clearance-mm`: the geometry read and checked, and the
//! clearance of one trajectory (docs/geometry.md).

use std::path::Path;
use std::sync::Arc;

use anyhow::{Context, Result, bail};
use sepval_common::scenario::Scenario;
use sepval_common::telemetry::Trajectory;
use sepval_geometry::{Body, Geometry, Pose, Role, Trace};
use sepval_predict::ClearanceSettings;

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
    let plane = Body::read(aircraft, Role::Aircraft)
        .with_context(|| format!("--aircraft {}", aircraft.display()))?;
    let store = match store_shape {
        Some(p) => {
            Body::read(p, Role::Store).with_context(|| format!("--store-shape {}", p.display()))?
        }
        None => Body::default_store(scenario.store.diameter_m)
            .context("the default store shape of the scenario")?,
    };
    Geometry::new(store, plane).with_context(|| {
        format!(
            "--aircraft {} with the store {}",
            aircraft.display(),
            store_shape.map_or("of the scenario (default shape)".into(), |p| p
                .display()
                .to_string())
        )
    })
}

/// The clearance of `traj` along its samples.
pub fn trace(c: &ClearanceSettings, traj: &Trajectory) -> Result<Trace> {
    let poses: Vec<Pose> = traj
        .pos_m
        .iter()
        .zip(&traj.att_deg)
        .map(|(p, a)| Pose {
            position_m: *p,
            euler_deg: *a,
        })
        .collect();
    c.geometry
        .trace(&traj.times_s, &poses, c.free_after_m)
        .context("the clearance of the trajectory")
}

/// The clearance of a trace in one line.
pub fn words(c: &ClearanceSettings, t: &Trace) -> String {
    let g = &c.geometry;
    let criterion_mm = 1e3 * c.criterion_m;
    let verdict = if t.min.distance_m >= c.criterion_m {
        format!("clears the {criterion_mm} mm criterion")
    } else if t.min.distance_m > 0.0 {
        format!("below the {criterion_mm} mm criterion")
    } else {
        "the store touches the aircraft".to_string()
    };
    format!(
        "smallest clearance {:.1} mm at t = {:.3} s, between the store's {} and the aircraft's {}: {verdict}",
        1e3 * t.min.distance_m,
        t.t_min_s,
        g.store_part(t.min.store_part),
        g.aircraft_part(t.min.aircraft_part)
    )
}
