//! The simulation of a prediction (docs/prediction.md section 13.3): every sample through any
//! [`Evaluator`] (the prediction never knows how the batches travel: in process, iceoryx2
//! workers or zenoh), in parts of at most [`SAMPLE_BUDGET`] simulated samples, each part's
//! trajectories reduced at once to the band's time points ([`Grid`]: every sample of a release
//! of up to [`MAX_BAND_POINTS`] samples, every k-th of a longer one, the last always) and
//! dropped, so a prediction holds samples x points x 6 doubles whatever the record's length.
//! The angles of each trajectory are made continuous along time (each point is the one before
//! plus the wrapped difference), so that a roll or yaw crossing 180 deg does not split a band.
//! A sample that diverges (the store tumbles, docs/model.md section 3) or fails has no
//! trajectory; it is counted and left out of the bands.

use sepval_common::evaluation::{
    Candidate, Counted, EvalError, Evaluator, Event, Job, JobError, Outcome,
};
use sepval_common::frames::wrap_deg;
use sepval_common::propagator::Observation;
use sepval_common::scenario::Scenario;
use sepval_common::simulation::Simulator;
use sepval_common::telemetry::Trajectory;
use sepval_fit::problem::SAMPLE_BUDGET;
use sepval_solve::run::{Progress, ProgressObserver};

/// The most time points of a band (a longer release is thinned to every k-th sample).
pub const MAX_BAND_POINTS: usize = 2001;

/// A simulation that could not be run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SimulateError {
    /// The evaluator failed or was interrupted.
    #[error("the simulations of the prediction")]
    Eval(#[from] EvalError),
    /// The job could not be made.
    #[error("the release to predict: {0}")]
    Job(#[from] JobError),
}

/// The time points of the bands: indices into the release's samples and their times.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Sample indices, increasing, the last sample included.
    pub indices: Vec<usize>,
    /// Their times \[s\].
    pub t_s: Vec<f64>,
}

impl Grid {
    /// The band points of a release sampled at `times_s`.
    pub fn of(times_s: &[f64]) -> Grid {
        let n = times_s.len();
        let step = n.div_ceil(MAX_BAND_POINTS).max(1);
        let mut indices: Vec<usize> = (0..n).step_by(step).collect();
        if n > 0 && indices.last() != Some(&(n - 1)) {
            indices.push(n - 1);
        }
        Grid {
            t_s: indices.iter().map(|&i| times_s[i]).collect(),
            indices,
        }
    }

    /// Its number of points.
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    /// Whether it has no points.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }
}

/// The job of one release at `scenario`, sampled at `times_s` (its "data" are zeros, compared
/// with nothing), named `name`.
pub fn release_job(scenario: &Scenario, times_s: &[f64], name: &str) -> Result<Job, JobError> {
    Job::new(vec![Event {
        name: name.to_string(),
        simulator: Simulator::new(scenario),
        data: Trajectory {
            pos_m: vec![[0.0; 3]; times_s.len()],
            att_deg: vec![[0.0; 3]; times_s.len()],
            times_s: times_s.to_vec(),
            ..Trajectory::default()
        },
    }])
}

/// One trajectory at the grid's points: x, y, z \[m\], roll, pitch, yaw \[deg\] (angles
/// continuous along time).
pub type GridTrajectory = Vec<[f64; 6]>;

/// Why a candidate has no trajectory.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum NoTrajectory {
    /// The store tumbled.
    #[error("diverged at t = {t_s:.3} s (the store tumbles)")]
    Diverged {
        /// When \[s\].
        t_s: f64,
    },
    /// The run failed: the outcome's reason (the simulator's words, carried as text in every
    /// evaluation's outcome).
    #[error("{reason}")]
    Failed {
        /// The outcome's reason.
        reason: String,
    },
    /// An evaluation without samples.
    #[error("no samples")]
    NoSamples,
    /// No evaluation at all.
    #[error("no run")]
    NoRun,
}

/// The runs of a list of candidates at the first event of a job.
#[derive(Debug, Clone, Default)]
pub struct Runs {
    /// Per candidate, its trajectory at the grid, or why it has none.
    pub trajectories: Vec<Result<GridTrajectory, NoTrajectory>>,
    /// Simulations run.
    pub evaluations: u64,
}

impl Runs {
    /// How many did not finish.
    pub fn failed(&self) -> usize {
        self.trajectories.iter().filter(|t| t.is_err()).count()
    }
}

/// Runs `n` candidates (`candidate(i)` for i in 0..n) through `evaluator`, in parts, each
/// reduced to `grid` before the next is asked; `progress` hears one step per part.
pub fn run_candidates(
    evaluator: &mut dyn Evaluator,
    n: usize,
    candidate: &dyn Fn(usize) -> Candidate,
    grid: &Grid,
    progress: &mut dyn ProgressObserver,
) -> Result<Runs, SimulateError> {
    let samples = evaluator.job().sample_count().max(1);
    let part = (SAMPLE_BUDGET / samples).max(1);
    let steps = n.div_ceil(part);
    let mut evaluator = Counted::new(evaluator);
    let mut runs = Runs {
        trajectories: Vec::with_capacity(n),
        evaluations: 0,
    };
    for (step, start) in (0..n).step_by(part).enumerate() {
        let batch: Vec<Candidate> = (start..(start + part).min(n)).map(candidate).collect();
        let evaluations = evaluator.evaluate(&batch, true)?;
        runs.evaluations = evaluator.count();
        for e in evaluations {
            runs.trajectories.push(match (e.samples, e.outcome) {
                (Some(s), _) => Ok(on_grid(&s[0], grid)),
                (None, Outcome::Diverged { t_s, .. }) => Err(NoTrajectory::Diverged { t_s }),
                (None, Outcome::Failed { reason }) => Err(NoTrajectory::Failed { reason }),
                (None, Outcome::Goals { .. }) => Err(NoTrajectory::NoSamples),
            });
        }
        progress.progress(&Progress {
            step: step + 1,
            steps: Some(steps),
            evaluations: runs.evaluations,
            best: [f64::NAN; 2],
        });
    }
    Ok(runs)
}

/// A simulated trajectory at the grid's points, angles continuous.
pub fn on_grid(samples: &[Observation], grid: &Grid) -> GridTrajectory {
    let mut out: GridTrajectory = Vec::with_capacity(grid.len());
    for &i in &grid.indices {
        let o = &samples[i];
        out.push([
            o.pos_m[0],
            o.pos_m[1],
            o.pos_m[2],
            o.att_deg[0],
            o.att_deg[1],
            o.att_deg[2],
        ]);
    }
    unwrap_angles(&mut out);
    out
}

/// Measured data at the grid's points, angles continuous.
pub fn data_on_grid(data: &Trajectory, grid: &Grid) -> GridTrajectory {
    let mut out: GridTrajectory = grid
        .indices
        .iter()
        .map(|&i| {
            let (p, a) = (data.pos_m[i], data.att_deg[i]);
            [p[0], p[1], p[2], a[0], a[1], a[2]]
        })
        .collect();
    unwrap_angles(&mut out);
    out
}

/// Makes each angle continuous along time: each point is the one before plus the wrapped
/// difference.
fn unwrap_angles(points: &mut [[f64; 6]]) {
    for k in 1..points.len() {
        let before = points[k - 1];
        for (v, b) in points[k][3..].iter_mut().zip(&before[3..]) {
            *v = b + wrap_deg(*v - b);
        }
    }
}
