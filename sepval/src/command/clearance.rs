//! `--aircraft`, `--store-shape` and `--clearance-mm`: the geometry read and checked, and the
//! clearance of one trajectory (docs/geometry.md).

use std::path::Path;
use std::sync::Arc;

use anyhow::{Context, Result, bail};
use sepval_common::atomic_file::write_atomically;
use sepval_common::cancel;
use sepval_common::evaluation::{Candidate, Evaluator, InProcess, Job};
use sepval_common::scenario::Scenario;
use sepval_common::telemetry::Trajectory;
use sepval_fit::results::ReleaseClearance;
use sepval_geometry::{Body, Geometry, Pose, Role, Trace};
use sepval_predict::ClearanceSettings;
use sepval_report::figures::{ClearanceSeries, clearance_figure};

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
        .trace_until(&traj.times_s, &poses, c.free_after_m, &cancel::requested)
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

/// The clearance of each release's trajectory (`releases`: name, sample times and samples),
/// written to `out/clearance.csv` (`release, t_s, clearance_m`, one row per sample) and
/// `out/figures/clearance.png`, and returned as the records of result.json and diagnosis.json.
pub fn of_releases(
    c: &ClearanceSettings,
    releases: &[(String, Trajectory)],
    out: &Path,
) -> Result<Vec<ReleaseClearance>> {
    let mut records = Vec::with_capacity(releases.len());
    let mut traces = Vec::with_capacity(releases.len());
    let mut csv = String::from("release,t_s,clearance_m\n");
    for (name, traj) in releases {
        let t = trace(c, traj).with_context(|| format!("release {name}"))?;
        let quoted = if name.contains([',', '"']) {
            format!("\"{}\"", name.replace('"', "\"\""))
        } else {
            name.clone()
        };
        for (ts, d) in traj.times_s.iter().zip(&t.distance_m) {
            csv.push_str(&format!("{quoted},{ts},{d}\n"));
        }
        records.push(ReleaseClearance {
            release: name.clone(),
            criterion_mm: 1e3 * c.criterion_m,
            min_clearance_mm: 1e3 * t.min.distance_m,
            t_min_s: t.t_min_s,
            store_part: c.geometry.store_part(t.min.store_part).to_string(),
            aircraft_part: c.geometry.aircraft_part(t.min.aircraft_part).to_string(),
            clears: t.min.distance_m >= c.criterion_m,
            free_flight_reached: t.free_flight_reached,
        });
        traces.push(t);
    }
    write_atomically(&out.join("clearance.csv"), csv.as_bytes())?;
    let figures = out.join("figures");
    std::fs::create_dir_all(&figures)
        .with_context(|| format!("cannot create {}", figures.display()))?;
    let series: Vec<ClearanceSeries> = releases
        .iter()
        .zip(&traces)
        .map(|((name, traj), t)| ClearanceSeries {
            label: name,
            t_s: &traj.times_s,
            clearance_m: &t.distance_m,
            free_from_s: traj.times_s.get(t.assessed_from).copied().unwrap_or(0.0),
            min_t_s: t.t_min_s,
            min_m: t.min.distance_m,
        })
        .collect();
    clearance_figure(
        &figures.join("clearance.png"),
        "Clearance to the aircraft along each release",
        &series,
        c.criterion_m,
    )?;
    Ok(records)
}

/// Each release of `job` simulated by `candidate` in this process, as trajectories.
pub fn simulate_releases(
    job: &Arc<Job>,
    candidate: Candidate,
    threads: usize,
) -> Result<Vec<(String, Trajectory)>> {
    let mut evaluator = InProcess::new(Arc::clone(job), threads);
    let e = evaluator
        .evaluate(&[candidate], true)
        .context("the best trajectories")?
        .pop()
        .context("no evaluation")?;
    let Some(samples) = e.samples else {
        bail!(
            "the best model does not simulate every release: {:?}",
            e.outcome
        );
    };
    Ok(job
        .events()
        .iter()
        .zip(samples)
        .map(|(ev, s)| {
            let traj = Trajectory {
                times_s: ev.data.times_s.clone(),
                pos_m: s.iter().map(|o| o.pos_m).collect(),
                att_deg: s.iter().map(|o| o.att_deg).collect(),
                ..Trajectory::default()
            };
            (ev.name.clone(), traj)
        })
        .collect())
}

/// The clearance of the best trajectories of a fit or diagnosis in `out`, for `--aircraft`
/// given: rewrites `record` (result.json or diagnosis.json) with its `clearance` and prints
/// one line per release.
pub fn record_releases<T: serde::Serialize>(
    c: &ClearanceSettings,
    releases: &[(String, Trajectory)],
    out: &Path,
    file: &str,
    record: &mut T,
    set: impl FnOnce(&mut T, Vec<ReleaseClearance>),
) -> Result<()> {
    let records = of_releases(c, releases, out)?;
    for r in &records {
        say!(
            "clearance: {}: smallest {:.1} mm at t = {:.3} s ({} / {}): {}",
            r.release,
            r.min_clearance_mm,
            r.t_min_s,
            r.store_part,
            r.aircraft_part,
            if r.clears { "clears" } else { "does not clear" }
        );
    }
    set(record, records);
    sepval_fit::record::write_record(&out.join(file), record)?;
    Ok(())
}
