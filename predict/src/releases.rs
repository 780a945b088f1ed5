//! The clearance of the releases a fit or a diagnosis answers with (docs/geometry.md; docs/
//! envelope.md section 14.2): each release fitted simulated by the answer in this process
//! ([`simulate`]), the store's distance to the aircraft along it ([`trace`], the geometry's
//! swept distance), one [`ReleaseClearance`] per release for result.json and diagnosis.json,
//! and `clearance.csv` and `figures/clearance.png` written into the run's directory
//! ([`write()`]). A stage of the fit and the diagnosis: the binary only asks for it when
//! `--aircraft` is given and prints its lines ([`line()`]).

use std::path::Path;
use std::sync::Arc;

use sepval_common::evaluation::{Candidate, EvalError, Evaluator, InProcess, Job};
use sepval_common::telemetry::Trajectory;
use sepval_core::cancel;
use sepval_diagnose::Diagnosis;
use sepval_fit::results::ReleaseClearance;
pub use sepval_geometry::GeometryError;
use sepval_geometry::{Pose, Trace};
use sepval_report::figures::{ClearanceSeries, clearance_figure};
use sepval_report::words::csv_text;
use sepval_report::{OutputError, Written};

use crate::clearance::ClearanceSettings;
use crate::ensemble::{Ensemble, EnsembleError};
use crate::source::{Source, SourceError};

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
    /// The answer of a diagnosis, rebuilt.
    #[error("the answer of the diagnosis")]
    Answer(#[source] Box<AnswerError>),
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

/// Why a diagnosis's answer could not be rebuilt.
#[derive(Debug, thiserror::Error)]
pub enum AnswerError {
    /// Its record, as a prediction reads it.
    #[error(transparent)]
    Source(#[from] SourceError),
    /// Its model.
    #[error(transparent)]
    Ensemble(#[from] EnsembleError),
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

/// The candidate of a diagnosis's answer (`d`, written to `dir`), rebuilt as a prediction
/// rebuilds it from diagnosis.json, for the job it was diagnosed on.
pub fn diagnosis_answer(d: &Diagnosis, dir: &Path, job: &Job) -> Result<Candidate, ReleasesError> {
    let answer = || -> Result<Candidate, AnswerError> {
        let source = Source::of_diagnosis(d.clone(), dir)?;
        Ok(Ensemble::of(&source, job.factor_table())?
            .answer()
            .candidate)
    };
    answer().map_err(|e| ReleasesError::Answer(Box::new(e)))
}

/// A release's clearance in one line, as the fit and the diagnosis print it.
pub fn line(r: &ReleaseClearance) -> String {
    format!(
        "{}: smallest {:.1} mm at t = {:.3} s ({} / {}): {}",
        r.release,
        r.min_clearance_mm,
        r.t_min_s,
        r.store_part,
        r.aircraft_part,
        if r.clears { "clears" } else { "does not clear" }
    )
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
