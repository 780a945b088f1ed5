//! The clearance of the releases a fit or a diagnosis answers with (docs/geometry.md; docs/
//! envelope.md section 14.2): each release fitted simulated by the answer in this process
//! ([`simulate`]), the store's distance to the aircraft along it ([`trace`], the geometry's
//! swept distance), one [`ReleaseClearance`] per release for result.json and diagnosis.json,
//! and `clearance.csv` and `figures/clearance.png` written into the run's directory
//! ([`write()`]). A stage of the fit and the diagnosis ([`Stage`], their
//! [`ClearReleases`]): the binary gives it to them when `--aircraft` is given; the lines of
//! what they record are `ReleaseClearance::line`'s.

use std::path::Path;
use std::sync::Arc;

use sepval_common::evaluation::{Candidate, EvalError, Evaluator, InProcess, Job};
use sepval_common::scenario::Scenario;
use sepval_common::telemetry::Trajectory;
use sepval_core::cancel;
pub use sepval_geometry::GeometryError;
use sepval_geometry::{Pose, Trace};
use sepval_report::figures::{ClearanceSeries, clearance_figure};
use sepval_report::words::csv_text;
use sepval_report::{OutputError, Written};
use sepval_run::clearance::{ClearReleases, GeometryPaths, ReleaseClearance, StageError};

use crate::clearance::{ClearanceInputError, ClearanceSettings};

/// The releases' clearance that could not be computed or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReleasesError {
    /// The answer's simulation.
    #[error("the answer's trajectories")]
    Simulate(#[source] EvalError),
    /// The evaluator answered nothing.
    #[error("the answer does not simulate every release: no evaluation came back")]
    NoEvaluation,
    /// The answer's evaluation carries no trajectories: its outcome says why.
    #[error("the answer does not simulate every release: {outcome:?}")]
    NotFlown {
        /// The evaluation's outcome.
        outcome: sepval_common::evaluation::Outcome,
    },
    /// A release's clearance.
    #[error("the clearance of release {release}")]
    Trace {
        /// The release.
        release: String,
        /// Why.
        #[source]
        source: GeometryError,
    },
    /// The outputs.
    #[error(transparent)]
    Outputs(#[from] OutputError),
}

/// The clearance stage of a fit or a diagnosis (`--aircraft`): the releases flown by their
/// answer in this process on `threads` threads, their clearance found and written.
pub struct Stage {
    /// The geometry and the criterion.
    pub settings: ClearanceSettings,
    /// The threads that fly the releases.
    pub threads: usize,
}

impl Stage {
    /// The clearance stage of a fit or a diagnosis of releases at `scenario`'s store, with the
    /// geometry as given, flying them on `threads` threads; `None` without an aircraft.
    pub fn of(
        given: &GeometryPaths,
        scenario: &Scenario,
        threads: usize,
    ) -> Result<Option<Arc<dyn ClearReleases>>, ClearanceInputError> {
        let stage = ClearanceSettings::of(given, scenario)?.map(|settings| {
            let stage: Arc<dyn ClearReleases> = Arc::new(Stage { settings, threads });
            stage
        });
        Ok(stage)
    }
}

impl ClearReleases for Stage {
    fn releases(
        &self,
        job: &Arc<Job>,
        candidate: Candidate,
        out: &Path,
    ) -> Result<Vec<ReleaseClearance>, StageError> {
        let flown = simulate(job, candidate, self.threads)?;
        let of = of_releases(&self.settings, &flown)?;
        write(&self.settings, &flown, &of, out)?;
        Ok(of.into_iter().map(|(r, _)| r).collect())
    }
}

/// The clearance of one trajectory along its samples.
pub fn trace(c: &ClearanceSettings, traj: &Trajectory) -> Result<Trace, GeometryError> {
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
}

/// A trace in one line, verdict last.
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

/// Each release of `job` simulated by `candidate` in this process on `threads` threads, as
/// trajectories named by their release.
pub fn simulate(
    job: &Arc<Job>,
    candidate: Candidate,
    threads: usize,
) -> Result<Vec<(String, Trajectory)>, ReleasesError> {
    let mut evaluator = InProcess::new(Arc::clone(job), threads);
    let e = evaluator
        .evaluate(&[candidate], true)
        .map_err(ReleasesError::Simulate)?
        .pop()
        .ok_or(ReleasesError::NoEvaluation)?;
    let Some(samples) = e.samples else {
        return Err(ReleasesError::NotFlown { outcome: e.outcome });
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

/// The clearance of each release (`releases`: name and trajectory), its record and its trace.
pub fn of_releases(
    c: &ClearanceSettings,
    releases: &[(String, Trajectory)],
) -> Result<Vec<(ReleaseClearance, Trace)>, ReleasesError> {
    releases
        .iter()
        .map(|(name, traj)| {
            let t = trace(c, traj).map_err(|source| ReleasesError::Trace {
                release: name.clone(),
                source,
            })?;
            let record = ReleaseClearance {
                release: name.clone(),
                criterion_mm: 1e3 * c.criterion_m,
                min_clearance_mm: 1e3 * t.min.distance_m,
                t_min_s: t.t_min_s,
                store_part: c.geometry.store_part(t.min.store_part).to_string(),
                aircraft_part: c.geometry.aircraft_part(t.min.aircraft_part).to_string(),
                clears: t.min.distance_m >= c.criterion_m,
                free_flight_reached: t.free_flight_reached,
            };
            Ok((record, t))
        })
        .collect()
}

/// `out/clearance.csv` (`release, t_s, clearance_m`, one row per sample) and
/// `out/figures/clearance.png` of the releases and their clearance (`of`, from
/// [`of_releases`]), each written atomically, the cancellation flag asked before each.
pub fn write(
    c: &ClearanceSettings,
    releases: &[(String, Trajectory)],
    of: &[(ReleaseClearance, Trace)],
    out: &Path,
) -> Result<(), ReleasesError> {
    let mut csv = String::from("release,t_s,clearance_m\n");
    for ((name, traj), (_, t)) in releases.iter().zip(of) {
        let quoted = csv_text(name);
        for (ts, d) in traj.times_s.iter().zip(&t.distance_m) {
            csv.push_str(&format!("{quoted},{ts},{d}\n"));
        }
    }
    let mut w = Written::into(out);
    w.file("clearance.csv", csv.as_bytes())?;
    let figures = w.figures()?;
    let series: Vec<ClearanceSeries> = releases
        .iter()
        .zip(of)
        .map(|((name, traj), (_, t))| ClearanceSeries {
            label: name,
            t_s: &traj.times_s,
            clearance_m: &t.distance_m,
            free_from_s: traj.times_s.get(t.assessed_from).copied().unwrap_or(0.0),
            min_t_s: t.t_min_s,
            min_m: t.min.distance_m,
        })
        .collect();
    w.figure(figures.join("clearance.png"), |path| {
        clearance_figure(
            path,
            "Clearance to the aircraft along each release",
            &series,
            c.criterion_m,
        )
    })?;
    Ok(())
}
