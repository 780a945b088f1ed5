//! The batch evaluation interface between a search and the simulations.
//!
//! A search (genetic algorithm, hill climber, Levenberg-Marquardt, diagnosis) sees evaluations
//! only through [`Evaluator`]: a batch of [`Candidate`]s (17 factors plus the values of a model
//! variant's effects) in, one typed [`Evaluation`] per candidate out, in order. How the batch
//! travels (a thread pool here, shared memory to worker processes elsewhere) is invisible to
//! the search, and every evaluator gives bit-identical outcomes: an evaluation is a pure
//! function of the job and the candidate.
//!
//! A [`Job`] is what every evaluator needs once: the events (scenario and measured data of each
//! release of the store). Goals are pooled over all samples of all events (docs/model.md section 5).

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use sha2::{Digest, Sha256};

use crate::correction::CorrectionValues;
use crate::effects::EffectSet;
use crate::extension::TermSet;
use crate::goals::{GoalAccumulator, GoalSums};
use crate::model::{ModelError, RunSetup};
use crate::propagator::{LANES, Observation, propagate_lanes};
use crate::scenario::{Scenario, hex_sha256};
use crate::simulation::Simulator;
use crate::telemetry::Trajectory;
use sepval_core::factors::{FactorTable, Factors};
pub use sepval_core::outcome::{EvalError, MAX_REASON_BYTES, Outcome};

/// One release: its scenario and its measured trajectory.
#[derive(Debug, Clone)]
pub struct Event {
    /// Name for reports (the data file, usually).
    pub name: String,
    /// The scenario, set up.
    pub simulator: Simulator,
    /// The measured trajectory.
    pub data: Trajectory,
}

/// Errors building a job.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum JobError {
    /// No events.
    #[error("a job needs at least one event (measured trajectory)")]
    NoEvents,
    /// An event beyond the limits of one run (`sepval_core::limits`).
    #[error("event `{event}`: {error}")]
    Limit {
        /// The event.
        event: String,
        /// The limit.
        error: sepval_core::limits::LimitError,
    },
    /// Events whose scenarios have different factor tables.
    #[error(
        "event `{event}` has a different factor table from event `{first}`: the 17 factors are shared, so their bounds and bits must be too"
    )]
    FactorTables {
        /// The first event.
        first: String,
        /// The differing event.
        event: String,
    },
}

/// Text written straight into a SHA-256.
struct HashWriter(Sha256);

impl std::fmt::Write for HashWriter {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.0.update(s.as_bytes());
        Ok(())
    }
}

/// Everything an evaluator needs once: the events of a fit.
#[derive(Debug, Clone)]
pub struct Job {
    events: Vec<Event>,
    data_sha256: String,
    scenario_sha256: String,
}

impl Job {
    /// A job of `events` (at least one; all with the same factor table).
    pub fn new(events: Vec<Event>) -> Result<Job, JobError> {
        let first = events.first().ok_or(JobError::NoEvents)?;
        for e in &events[1..] {
            if e.simulator.scenario().factors != first.simulator.scenario().factors {
                return Err(JobError::FactorTables {
                    first: first.name.clone(),
                    event: e.name.clone(),
                });
            }
        }
        let mut samples = 0usize;
        for e in &events {
            let limit = |error| JobError::Limit {
                event: e.name.clone(),
                error,
            };
            // The run integrates up to the last sample (the carriage state before release).
            let span = e.data.times_s.last().copied().unwrap_or(0.0).max(0.0);
            let dt = e.simulator.scenario().integrator.dt_s;
            sepval_core::limits::check_steps(span, dt).map_err(limit)?;
            samples += e.data.len();
            if samples > sepval_core::limits::MAX_SAMPLES {
                return Err(limit(sepval_core::limits::LimitError::Samples {
                    samples: samples as f64,
                }));
            }
        }
        // SHA-256 of each event's samples as CSV (without comments), events separated by
        // U+001E, written into the hash line by line (never held whole in memory).
        let mut data = HashWriter(Sha256::new());
        let mut scen = String::new();
        for e in &events {
            e.data.write_csv_rows(&mut data);
            data.0.update("\u{1e}".as_bytes());
            scen.push_str(&e.simulator.scenario().content_hash());
            scen.push('\u{1e}');
        }
        Ok(Job {
            data_sha256: data
                .0
                .finalize()
                .iter()
                .map(|b| format!("{b:02x}"))
                .collect(),
            scenario_sha256: hex_sha256(scen.as_bytes()),
            events,
        })
    }

    /// A job of one event.
    pub fn single(name: &str, scenario: &Scenario, data: Trajectory) -> Job {
        Job::new(vec![Event {
            name: name.to_string(),
            simulator: Simulator::new(scenario),
            data,
        }])
        .expect("one event is a valid job")
    }

    /// The events.
    pub fn events(&self) -> &[Event] {
        &self.events
    }

    /// The factor table shared by all events.
    pub fn factor_table(&self) -> &FactorTable {
        &self.events[0].simulator.scenario().factors
    }

    /// SHA-256 of the measured data (sample values of every event, in order).
    pub fn data_sha256(&self) -> &str {
        &self.data_sha256
    }

    /// SHA-256 of the scenarios (content hashes of every event's scenario, in order).
    pub fn scenario_sha256(&self) -> &str {
        &self.scenario_sha256
    }

    /// Total number of samples over all events.
    pub fn sample_count(&self) -> usize {
        self.events.iter().map(|e| e.data.len()).sum()
    }

    /// Evaluates one candidate (goals pooled over all events).
    pub fn evaluate(&self, c: &Candidate) -> Evaluation {
        self.evaluate_batch(std::slice::from_ref(c), false)
            .remove(0)
    }

    /// Evaluates one candidate and keeps the simulated samples of every event.
    pub fn evaluate_with_samples(&self, c: &Candidate) -> Evaluation {
        self.evaluate_batch(std::slice::from_ref(c), true).remove(0)
    }

    /// Evaluates `batch` (goals pooled over all events; with `keep`, the simulated samples of
    /// every event too), one evaluation per candidate, in order. Candidates run [`LANES`] at a
    /// time through the lane propagator ([`propagate_lanes`]), event after event (a candidate
    /// that fails or diverges in one event runs no further), so evaluation `i` has the bits of
    /// the evaluation of `batch[i]` alone.
    pub fn evaluate_batch(&self, batch: &[Candidate], keep: bool) -> Vec<Evaluation> {
        let mut sums = vec![GoalSums::default(); batch.len()];
        let mut samples: Vec<Vec<Vec<Observation>>> = vec![Vec::new(); batch.len()];
        let mut ended: Vec<Option<Evaluation>> = vec![None; batch.len()];
        for (k, event) in self.events.iter().enumerate() {
            // The candidates still running, and their runs of this event.
            let mut live: Vec<usize> = Vec::with_capacity(batch.len());
            let mut live_runs: Vec<RunSetup> = Vec::with_capacity(batch.len());
            for (i, c) in batch.iter().enumerate() {
                if ended[i].is_some() {
                    continue;
                }
                match c.run_setup(&event.simulator) {
                    Ok(run) => {
                        live.push(i);
                        live_runs.push(run);
                    }
                    Err(e) => ended[i] = Some(Outcome::failed(e.to_string()).into()),
                }
            }
            let model = event.simulator.model();
            let data = &event.data;
            for (group, runs) in live.chunks(LANES).zip(live_runs.chunks(LANES)) {
                let results = if keep {
                    let mut sinks: Vec<Vec<Observation>> = runs
                        .iter()
                        .map(|_| Vec::with_capacity(data.len()))
                        .collect();
                    let results = propagate_lanes(model, runs, &data.times_s, &mut sinks);
                    for ((&i, r), obs) in group.iter().zip(&results).zip(sinks) {
                        if r.is_ok() {
                            for (j, o) in obs.iter().enumerate() {
                                sums[i].add(o, &data.pos_m[j], &data.att_deg[j]);
                            }
                            samples[i].push(obs);
                        }
                    }
                    results
                } else {
                    let mut sinks: Vec<GoalAccumulator> =
                        runs.iter().map(|_| GoalAccumulator::new(data)).collect();
                    let results = propagate_lanes(model, runs, &data.times_s, &mut sinks);
                    for (&i, acc) in group.iter().zip(&sinks) {
                        sums[i].merge(&acc.sums);
                    }
                    results
                };
                for (&i, r) in group.iter().zip(results) {
                    if let Err(d) = r {
                        ended[i] = Some(
                            Outcome::Diverged {
                                t_s: d.t_s,
                                event: k,
                            }
                            .into(),
                        );
                    }
                }
            }
        }
        ended
            .into_iter()
            .zip(sums)
            .zip(samples)
            .map(|((ended, sums), samples)| {
                ended.unwrap_or_else(|| finished(&sums, keep.then_some(samples)))
            })
            .collect()
    }
}

/// The evaluation of a candidate that ran through every event: its pooled goals, or a failure
/// if they are not finite.
fn finished(sums: &GoalSums, samples: Option<Vec<Vec<Observation>>>) -> Evaluation {
    let g = sums.goals();
    if !(g.j_pos_m.is_finite() && g.j_att_deg.is_finite()) {
        // Residuals beyond f64 (a run far outside the data): a failed run, never a
        // number that files would write as null.
        return Evaluation::from(Outcome::failed(format!(
            "the goals are not finite numbers (J_pos = {} m, J_att = {} deg)",
            g.j_pos_m, g.j_att_deg
        )));
    }
    Evaluation {
        outcome: Outcome::Goals {
            j_pos_m: g.j_pos_m,
            j_att_deg: g.j_att_deg,
        },
        samples,
    }
}

/// One point of a search: the 17 factors, the effects of the model variant with their
/// parameter values, and extension terms (docs/discovery.md) beyond the scenario's.
/// `Copy`, fixed size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// The factors.
    pub factors: Factors,
    /// The active effects and their values (empty for the baseline model).
    pub effects: EffectSet,
    /// Extension terms of this candidate (the scenario's own apply too).
    pub terms: TermSet,
    /// The values of the scenario's corrections (docs/update.md; none: every
    /// correction 0).
    pub corrections: CorrectionValues,
}

impl Candidate {
    /// A baseline-model candidate.
    pub fn baseline(factors: Factors) -> Self {
        Candidate {
            factors,
            effects: EffectSet::NONE,
            terms: TermSet::NONE,
            corrections: CorrectionValues::NONE,
        }
    }

    /// A candidate of a model variant with catalogue effects.
    pub fn with_effects(factors: Factors, effects: EffectSet) -> Self {
        Candidate {
            factors,
            effects,
            terms: TermSet::NONE,
            corrections: CorrectionValues::NONE,
        }
    }

    /// Its run of `sim`'s scenario: factors, effects, terms and correction values applied.
    pub fn run_setup(&self, sim: &Simulator) -> Result<RunSetup, ModelError> {
        RunSetup::with_corrections(
            sim.model(),
            &self.factors,
            &self.effects,
            &self.terms,
            &self.corrections,
        )
    }
}

/// The result of evaluating one candidate.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// The outcome.
    pub outcome: Outcome,
    /// The simulated samples of each event, when asked for and the run finished.
    pub samples: Option<Vec<Vec<Observation>>>,
}

impl From<Outcome> for Evaluation {
    fn from(outcome: Outcome) -> Self {
        Evaluation {
            outcome,
            samples: None,
        }
    }
}

/// Starts an evaluator for a job: how a pipeline that runs several jobs (an envelope's
/// conditions, an update's two rounds, a campaign's conditions and releases) asks the caller
/// for each one's evaluator, whatever the transport.
pub type StartEvaluator<'a> =
    dyn FnMut(std::sync::Arc<Job>) -> Result<Box<dyn Evaluator>, EvalError> + 'a;

/// An evaluator that counts the candidates it evaluates: how a pipeline knows how many
/// simulations it ran, from the one place they all pass through, whatever its stages.
pub struct Counted<'a> {
    inner: &'a mut dyn Evaluator,
    count: u64,
    simulations: u64,
}

impl<'a> Counted<'a> {
    /// `inner`, counted from 0.
    pub fn new(inner: &'a mut dyn Evaluator) -> Self {
        Counted {
            inner,
            count: 0,
            simulations: 0,
        }
    }

    /// The candidates evaluated so far (one simulation each, over every event of the job).
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The simulations asked for so far: each candidate flies every event of the job.
    pub fn simulations(&self) -> u64 {
        self.simulations
    }
}

impl Evaluator for Counted<'_> {
    fn evaluate(
        &mut self,
        batch: &[Candidate],
        with_samples: bool,
    ) -> Result<Vec<Evaluation>, EvalError> {
        let out = self.inner.evaluate(batch, with_samples)?;
        self.count += batch.len() as u64;
        self.simulations += (batch.len() * self.inner.job().events().len()) as u64;
        Ok(out)
    }

    fn job(&self) -> &Arc<Job> {
        self.inner.job()
    }

    fn describe(&self) -> String {
        self.inner.describe()
    }
}

/// Evaluates batches of candidates for one job.
pub trait Evaluator {
    /// Evaluates `batch` and returns one evaluation per candidate, in order. With
    /// `with_samples`, finished runs also return their simulated samples.
    fn evaluate(
        &mut self,
        batch: &[Candidate],
        with_samples: bool,
    ) -> Result<Vec<Evaluation>, EvalError>;

    /// The job (shared: evaluators and searches hold one copy of the data).
    fn job(&self) -> &Arc<Job>;

    /// A short description for reports ("inproc, 2 threads").
    fn describe(&self) -> String;
}

/// The in-process evaluator: a batch is shared among `threads` threads of this process.
pub struct InProcess {
    job: Arc<Job>,
    threads: usize,
}

impl InProcess {
    /// An evaluator on `threads` threads (at least one).
    pub fn new(job: Arc<Job>, threads: usize) -> Self {
        InProcess {
            job,
            threads: threads.max(1),
        }
    }
}

impl Evaluator for InProcess {
    fn evaluate(
        &mut self,
        batch: &[Candidate],
        with_samples: bool,
    ) -> Result<Vec<Evaluation>, EvalError> {
        let job = &*self.job;
        // Chunks of LANES consecutive candidates, each run as one lane batch.
        let chunks: Vec<&[Candidate]> = batch.chunks(LANES).collect();
        let threads = self.threads.min(chunks.len());
        if threads <= 1 {
            let mut out = Vec::with_capacity(batch.len());
            for chunk in chunks {
                sepval_core::cancel::check().map_err(|_| EvalError::Interrupted)?;
                out.extend(job.evaluate_batch(chunk, with_samples));
            }
            return Ok(out);
        }
        // Threads take the next chunk until the batch is done; each chunk's results go to its
        // own slot, so the order (and every bit) is independent of the thread count.
        let next = AtomicUsize::new(0);
        let mut slots: Vec<Option<Vec<Evaluation>>> = vec![None; chunks.len()];
        let results: Vec<Vec<(usize, Vec<Evaluation>)>> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..threads)
                .map(|_| {
                    s.spawn(|| {
                        let mut mine = Vec::new();
                        loop {
                            let i = next.fetch_add(1, Ordering::Relaxed);
                            if i >= chunks.len() || sepval_core::cancel::requested() {
                                break mine;
                            }
                            mine.push((i, job.evaluate_batch(chunks[i], with_samples)));
                        }
                    })
                })
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("evaluation threads do not panic"))
                .collect()
        });
        sepval_core::cancel::check().map_err(|_| EvalError::Interrupted)?;
        for (i, e) in results.into_iter().flatten() {
            slots[i] = Some(e);
        }
        Ok(slots
            .into_iter()
            .flat_map(|e| e.expect("every chunk was evaluated"))
            .collect())
    }

    fn job(&self) -> &Arc<Job> {
        &self.job
    }

    fn describe(&self) -> String {
        format!("inproc, {} thread(s)", self.threads)
    }
}
