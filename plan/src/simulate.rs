//! The simulation of a plan: every model and every one of its parameter steps at the releases
//! flown and at every candidate condition, through any [`Evaluator`] (the plan never knows how
//! the batches travel), reduced to what the separation and the information need.
//!
//! The evaluator's job ([`plan_job`]) holds the releases flown (their own scenarios and sample
//! times) followed by one event per condition: the first release's scenario flown at the
//! condition, sampled at the first release's times (its "data" are zeros and never compared
//! with anything). A candidate runs through every event, so one batch gives a model at every
//! condition. Batches go in parts of at most [`SAMPLE_BUDGET`] samples; each part's
//! trajectories are reduced to normalised sensitivity columns and dropped before the next part
//! is asked. A model's columns are reduced to its normal equations per event once its last
//! part is in: what stays is, per model and event, the p x p matrix J^T J, and per other model
//! J^T d and d^T d, d the other model's trajectory minus this one's over the noise.
//!
//! A candidate that diverges (docs/model.md section 3: the store tumbles) or fails in one
//! event runs no further, so it is re-run event by event in this process (the same bits: an
//! evaluation is a pure function of the job and the candidate), and only the events where it
//! diverged are lost.

use std::sync::Arc;

use nalgebra::{DMatrix, DVector};
use sepval_common::evaluation::{
    Candidate, Counted, EvalError, Evaluation, Evaluator, Event, Job, Outcome,
};
use sepval_common::goals::residual;
use sepval_common::propagator::Observation;
use sepval_common::telemetry::Trajectory;
use sepval_fit::problem::SAMPLE_BUDGET;
use sepval_fit::space::Noise;
use sepval_solve::run::{Progress, ProgressObserver};

use crate::conditions::Conditions;
use crate::models::{Models, PlanModel};

/// The normalised sensitivity columns one plan holds at once are refused beyond this \[bytes\]
/// (one model's: parameters x events x 6 x samples doubles).
pub const MAX_COLUMN_BYTES: usize = 1 << 30;

/// A simulation that could not be run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SimulateError {
    /// The evaluator failed or was interrupted.
    #[error("the simulations of the plan")]
    Eval(#[from] EvalError),
    /// The job of the conditions could not be made.
    #[error("the job of the conditions: {0}")]
    Job(#[from] sepval_common::evaluation::JobError),
    /// A model that does not simulate the releases it was fitted to.
    #[error("{model} does not simulate the release flown `{event}`: {reason}")]
    Flown {
        /// The model.
        model: String,
        /// The release.
        event: String,
        /// Why.
        reason: Missing,
    },
    /// Too many conditions or samples to hold the sensitivities.
    #[error(
        "the sensitivities of {parameters} parameters at {events} releases of {samples} samples need {bytes} bytes, above {MAX_COLUMN_BYTES}: give fewer --points or shorter ranges"
    )]
    TooLarge {
        /// Parameters of the largest model.
        parameters: usize,
        /// Events (flown and planned).
        events: usize,
        /// Samples per planned release.
        samples: usize,
        /// Bytes needed.
        bytes: usize,
    },
}

/// The job of a plan: the releases flown, then one event per condition.
pub fn plan_job(flown: &Job, conditions: &Conditions) -> Result<Job, SimulateError> {
    let first = &flown.events()[0];
    let base = first.simulator.scenario();
    let mut events: Vec<Event> = flown.events().to_vec();
    let times = first.data.times_s.clone();
    for k in 0..conditions.list.len() {
        let scenario = conditions.scenario(base, k);
        events.push(Event {
            name: format!("condition {}", k + 1),
            simulator: sepval_common::simulation::Simulator::new(&scenario),
            data: Trajectory {
                pos_m: vec![[0.0; 3]; times.len()],
                att_deg: vec![[0.0; 3]; times.len()],
                times_s: times.clone(),
                ..Trajectory::default()
            },
        });
    }
    Ok(Job::new(events)?)
}

/// Checks that the sensitivities of the largest model fit [`MAX_COLUMN_BYTES`].
pub fn check_size(models: &Models, job: &Job) -> Result<(), SimulateError> {
    let parameters = models
        .list
        .iter()
        .map(PlanModel::parameters)
        .max()
        .unwrap_or(0);
    let samples = job.events().last().map_or(0, |e| e.data.len());
    let bytes = parameters
        .saturating_mul(job.sample_count())
        .saturating_mul(6 * 8);
    if bytes > MAX_COLUMN_BYTES {
        return Err(SimulateError::TooLarge {
            parameters,
            events: job.events().len(),
            samples,
            bytes,
        });
    }
    Ok(())
}

/// What a model's run at one event reduces to.
#[derive(Debug, Clone)]
pub struct EventNormal {
    /// J^T J of its normalised, range-scaled sensitivities.
    pub gram: DMatrix<f64>,
    /// Per model (by index; `None` for itself and where that model did not run): J^T d and
    /// d^T d, d = (that model - this one) / sigma.
    pub cross: Vec<Option<(DVector<f64>, f64)>>,
}

/// One model at every event.
#[derive(Debug, Clone)]
pub struct ModelRuns {
    /// Its trajectory at each event, or why it has none (diverged, failed).
    pub nominal: Vec<Result<Vec<Observation>, Missing>>,
    /// Its normal equations at each event, or why they are missing (a step diverged).
    pub normal: Vec<Result<EventNormal, Missing>>,
}

/// Every model at every event.
#[derive(Debug, Clone)]
pub struct Simulated {
    /// Per model, in the order of [`Models::list`].
    pub runs: Vec<ModelRuns>,
    /// Events flown (the first events of the job).
    pub flown: usize,
    /// Samples of each event.
    pub samples: Vec<usize>,
    /// Simulations run.
    pub evaluations: u64,
}

/// Runs every model and its steps through `evaluator` (whose job is [`plan_job`]'s) and reduces
/// them; `noise` normalises the differences.
pub fn simulate(
    models: &Models,
    flown: usize,
    noise: Noise,
    evaluator: &mut dyn Evaluator,
    progress: &mut dyn ProgressObserver,
) -> Result<Simulated, SimulateError> {
    let job = evaluator.job().clone();
    let part = (SAMPLE_BUDGET / job.sample_count().max(1)).max(1);
    let parts_of = |n: usize| n.div_ceil(part);
    let steps = parts_of(models.list.len())
        + models
            .list
            .iter()
            .map(|m| parts_of(m.parameters()))
            .sum::<usize>();
    let mut runner = Runner {
        job: &job,
        evaluator: Counted::new(evaluator),
        progress,
        part,
        step: 0,
        steps,
        reruns: 0,
    };
    runner.progress.start("plan", Some(steps));
    let nominals: Vec<Candidate> = models.list.iter().map(|m| m.candidate).collect();
    let nominal = runner.run(&nominals)?;
    for (m, runs) in models.list.iter().zip(&nominal) {
        for (e, r) in job.events()[..flown].iter().zip(runs) {
            if let Err(reason) = r {
                return Err(SimulateError::Flown {
                    model: m.name.clone(),
                    event: e.name.clone(),
                    reason: reason.clone(),
                });
            }
        }
    }
    let mut runs = Vec::with_capacity(models.list.len());
    for (i, m) in models.list.iter().enumerate() {
        let columns = runner.columns(m, &nominal[i], noise)?;
        let normal = reduce(i, &columns, &nominal, noise);
        runs.push(ModelRuns {
            nominal: Vec::new(),
            normal,
        });
    }
    for (r, n) in runs.iter_mut().zip(nominal) {
        r.nominal = n;
    }
    runner.progress.finish();
    Ok(Simulated {
        runs,
        flown,
        samples: job.events().iter().map(|e| e.data.len()).collect(),
        evaluations: runner.evaluations(),
    })
}

/// Runs candidates in parts and keeps each one's samples per event.
struct Runner<'a> {
    job: &'a Arc<Job>,
    /// The evaluator, counting the simulations it is asked for.
    evaluator: Counted<'a>,
    progress: &'a mut dyn ProgressObserver,
    part: usize,
    step: usize,
    steps: usize,
    /// Events re-run one by one in this process (a run that did not finish).
    reruns: u64,
}

/// Per event, the samples of a run or why there are none.
type EventSamples = Vec<Result<Vec<Observation>, Missing>>;
/// Per event, a model's sensitivity columns or why there are none.
type EventColumns = Vec<Result<Vec<Vec<f64>>, Missing>>;

/// Why a model's run, its sensitivities or a condition's numbers are missing (the plan says
/// so for the condition).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Missing {
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
    /// The run of a parameter's step.
    #[error("a step of {parameter}: {why}")]
    Step {
        /// The parameter stepped.
        parameter: String,
        /// Why its run is missing.
        why: Box<Missing>,
    },
    /// A model's numbers.
    #[error("{model}: {why}")]
    Model {
        /// The model (`the answer`, a rival's name).
        model: String,
        /// Why they are missing.
        why: Box<Missing>,
    },
    /// A model that did not run at the condition.
    #[error("{model} did not run")]
    DidNotRun {
        /// The model.
        model: String,
    },
}

impl Runner<'_> {
    /// The simulations run: the evaluator's, and the events re-run in this process.
    fn evaluations(&self) -> u64 {
        self.evaluator.simulations() + self.reruns
    }

    /// The samples of each candidate at each event.
    fn run(&mut self, batch: &[Candidate]) -> Result<Vec<EventSamples>, SimulateError> {
        let mut out = Vec::with_capacity(batch.len());
        for chunk in batch.chunks(self.part) {
            out.extend(self.run_part(chunk)?);
        }
        Ok(out)
    }

    fn run_part(&mut self, chunk: &[Candidate]) -> Result<Vec<EventSamples>, SimulateError> {
        let evaluations = self.evaluator.evaluate(chunk, true)?;
        let mut out = Vec::with_capacity(chunk.len());
        for (c, e) in chunk.iter().zip(evaluations) {
            out.push(self.per_event(c, e)?);
        }
        self.step += 1;
        self.progress.progress(&Progress {
            step: self.step,
            steps: Some(self.steps),
            evaluations: self.evaluations(),
            best: [f64::NAN; 2],
        });
        Ok(out)
    }

    /// The samples of one evaluation per event; a run that did not finish is re-run event by
    /// event in this process.
    fn per_event(&mut self, c: &Candidate, e: Evaluation) -> Result<EventSamples, SimulateError> {
        if let Some(samples) = e.samples {
            return Ok(samples.into_iter().map(Ok).collect());
        }
        let mut out = Vec::with_capacity(self.job.events().len());
        for event in self.job.events() {
            sepval_core::cancel::check().map_err(|_| EvalError::Interrupted)?;
            let one = Job::new(vec![event.clone()])?;
            let ev = one.evaluate_with_samples(c);
            self.reruns += 1;
            out.push(match (ev.outcome, ev.samples) {
                (_, Some(mut s)) => Ok(s.remove(0)),
                (Outcome::Diverged { t_s, .. }, None) => Err(Missing::Diverged { t_s }),
                (Outcome::Failed { reason }, None) => Err(Missing::Failed { reason }),
                (Outcome::Goals { .. }, None) => Err(Missing::NoSamples),
            });
        }
        Ok(out)
    }

    /// The normalised, range-scaled sensitivity columns of `m` per event (`None` where a
    /// step did not run): column j is (y(x + h_j e_j) - y(x)) / h_j x range_j / sigma.
    fn columns(
        &mut self,
        m: &PlanModel,
        nominal: &EventSamples,
        noise: Noise,
    ) -> Result<EventColumns, SimulateError> {
        let probes = m.probes();
        let mut columns: EventColumns = nominal
            .iter()
            .map(|n| match n {
                Ok(_) => Ok(Vec::with_capacity(m.parameters())),
                Err(r) => Err(r.clone()),
            })
            .collect();
        let mut j = 0;
        for chunk in probes[1..].chunks(self.part) {
            for stepped in self.run_part(chunk)? {
                let scale = m.space.params.range(j) / m.steps[j];
                for ((col, s), y) in columns.iter_mut().zip(stepped).zip(nominal) {
                    let (Ok(cols), Ok(y)) = (col.as_mut(), y.as_ref()) else {
                        continue;
                    };
                    match s {
                        Ok(s) => cols.push(difference(&s, y, noise, scale)),
                        Err(r) => {
                            *col = Err(Missing::Step {
                                parameter: m.space.params.names[j].clone(),
                                why: Box::new(r),
                            });
                        }
                    }
                }
                j += 1;
            }
        }
        Ok(columns)
    }
}

/// (a - b) / sigma x `scale`, sample by sample: x, y, z over the position noise, roll, pitch,
/// yaw (wrapped) over the attitude noise.
pub fn difference(a: &[Observation], b: &[Observation], noise: Noise, scale: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(6 * a.len());
    for (oa, ob) in a.iter().zip(b) {
        let (p, t) = residual(oa, &ob.pos_m, &ob.att_deg);
        out.extend(p.iter().map(|v| v / noise.pos_m * scale));
        out.extend(t.iter().map(|v| v / noise.att_deg * scale));
    }
    out
}

/// Model `i`'s normal equations at each event from its columns and every model's trajectory.
fn reduce(
    i: usize,
    columns: &EventColumns,
    nominal: &[EventSamples],
    noise: Noise,
) -> Vec<Result<EventNormal, Missing>> {
    columns
        .iter()
        .enumerate()
        .map(|(e, cols)| {
            let cols = cols.as_ref().map_err(Clone::clone)?;
            let p = cols.len();
            let gram = DMatrix::from_fn(p, p, |r, c| dot(&cols[r], &cols[c]));
            let own = nominal[i][e].as_ref().map_err(Clone::clone)?;
            let cross = nominal
                .iter()
                .enumerate()
                .map(|(a, runs)| {
                    let other = runs[e].as_ref().ok().filter(|_| a != i)?;
                    let d = difference(other, own, noise, 1.0);
                    let rhs = DVector::from_iterator(p, cols.iter().map(|c| dot(c, &d)));
                    Some((rhs, dot(&d, &d)))
                })
                .collect();
            Ok(EventNormal { gram, cross })
        })
        .collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
