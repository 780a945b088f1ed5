//! One loop for every search: a [`Solver`] asks for points and is told their evaluations; the
//! loop ([`run`]) evaluates each request through a [`Problem`] and shows every completed step
//! (a generation, an iteration) to [`Observer`]s, which write checkpoints, draw progress or stop
//! the search. It also stops, with [`RunError::Interrupted`], when a signal asks the process to.
//!
//! The split follows argmin (S. Kroboth, `argmin` 0.10, `core/{problem,solver,executor}.rs`):
//! what is evaluated (the problem, whose batch evaluation is where the in-process thread pool or
//! the worker processes plug in), one step of the algorithm (the solver, state in and state
//! out), the loop, and the side effects (observers). The genetic algorithm, the hill climber
//! and the Levenberg-Marquardt refinement are solvers; so are the compositions a fit makes of
//! them (a genetic search that tries refinements as it goes, several refinements sharing each
//! batch).

use sepval_common::cancel;
use sepval_common::evaluation::{Candidate, EvalError, Evaluation, Evaluator};

/// Points to evaluate, as one batch.
#[derive(Debug, Clone, PartialEq)]
pub struct Ask<P> {
    /// The points.
    pub points: Vec<P>,
    /// Whether finished runs should return their simulated samples.
    pub with_samples: bool,
}

/// Where a search is after a completed step.
#[derive(Debug, Clone, PartialEq)]
pub struct Progress {
    /// Steps done (generations, iterations).
    pub step: usize,
    /// Steps planned, when known.
    pub steps: Option<usize>,
    /// Simulations run so far by this search.
    pub evaluations: u64,
    /// The best goals so far: J_pos \[m\], J_att \[deg\].
    pub best: [f64; 2],
}

/// What an observer wants after a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Control {
    /// Go on.
    Continue,
    /// Stop the search now (its state is complete and valid).
    Stop,
}

/// Errors of a search.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RunError {
    /// The evaluations could not be run (the transport failed).
    #[error(transparent)]
    Eval(EvalError),
    /// A signal asked the process to stop.
    #[error("interrupted by a signal")]
    Interrupted,
    /// The search cannot go on (a start that does not simulate, a state that does not fit).
    #[error("{0}")]
    Search(String),
    /// An observer failed (a checkpoint that cannot be written).
    #[error("{what}")]
    Observer {
        /// What failed.
        what: String,
        /// Why.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

impl From<EvalError> for RunError {
    fn from(e: EvalError) -> Self {
        match e {
            EvalError::Interrupted => RunError::Interrupted,
            other => RunError::Eval(other),
        }
    }
}

impl From<cancel::Cancelled> for RunError {
    fn from(_: cancel::Cancelled) -> Self {
        RunError::Interrupted
    }
}

/// A search as ask-and-tell.
pub trait Solver {
    /// What it evaluates: decoded parameter vectors, or model candidates.
    type Point;

    /// The next batch to evaluate, or `None` when the search is finished.
    fn ask(&mut self) -> Result<Option<Ask<Self::Point>>, RunError>;

    /// The evaluations of the last batch, in order. Returns the progress when a step (a
    /// generation, an iteration) completed with them.
    fn tell(&mut self, evaluations: Vec<Evaluation>) -> Result<Option<Progress>, RunError>;
}

/// What a search evaluates: a batch of points to one evaluation each, in order.
pub trait Problem<P> {
    /// Evaluates `points`.
    fn evaluate(&mut self, points: &[P], with_samples: bool) -> Result<Vec<Evaluation>, EvalError>;
}

/// Most simulated samples one batch brings back (about 100 MB as observations): a batch that
/// asks for more is evaluated in parts, so that long telemetry records do not multiply into
/// gigabytes (the default event's 201 samples allow 9 950 candidates a batch).
pub const SAMPLE_BUDGET: usize = 2_000_000;

/// Model candidates evaluated by an [`Evaluator`] (threads of this process, or workers); a
/// batch whose samples exceed [`SAMPLE_BUDGET`] goes in parts.
pub struct Evaluate<'a>(pub &'a mut dyn Evaluator);

impl Problem<Candidate> for Evaluate<'_> {
    fn evaluate(
        &mut self,
        points: &[Candidate],
        with_samples: bool,
    ) -> Result<Vec<Evaluation>, EvalError> {
        let per = self.0.job().sample_count().max(1);
        let part = (SAMPLE_BUDGET / per).max(1);
        if !with_samples || points.len() <= part {
            return self.0.evaluate(points, with_samples);
        }
        let mut out = Vec::with_capacity(points.len());
        for chunk in points.chunks(part) {
            out.extend(self.0.evaluate(chunk, true)?);
        }
        Ok(out)
    }
}

/// Sees a solver after each completed step.
pub trait Observer<S: ?Sized> {
    /// Called after each completed step.
    fn observe(&mut self, solver: &S, progress: &Progress) -> Result<Control, RunError>;
}

/// Sees only the progress of any search (a progress bar).
pub trait ProgressObserver {
    /// A search started: `label` names it ("ga", "hill+lm"), `steps` its planned steps.
    fn start(&mut self, label: &str, steps: Option<usize>);
    /// A step completed.
    fn progress(&mut self, progress: &Progress);
    /// The search ended.
    fn finish(&mut self);
}

/// A [`ProgressObserver`] that shows nothing.
pub struct NoProgress;

impl ProgressObserver for NoProgress {
    fn start(&mut self, _: &str, _: Option<usize>) {}
    fn progress(&mut self, _: &Progress) {}
    fn finish(&mut self) {}
}

/// A [`ProgressObserver`] as an observer of any search.
pub struct ShowProgress<'a>(pub &'a mut dyn ProgressObserver);

impl<S: ?Sized> Observer<S> for ShowProgress<'_> {
    fn observe(&mut self, _: &S, progress: &Progress) -> Result<Control, RunError> {
        self.0.progress(progress);
        Ok(Control::Continue)
    }
}

/// Runs `solver` on `problem` until it is finished or an observer stops it.
pub fn run<S: Solver>(
    solver: &mut S,
    problem: &mut dyn Problem<S::Point>,
    observers: &mut [&mut dyn Observer<S>],
) -> Result<(), RunError> {
    loop {
        cancel::check()?;
        let Some(ask) = solver.ask()? else {
            return Ok(());
        };
        let evaluations = problem.evaluate(&ask.points, ask.with_samples)?;
        if evaluations.len() != ask.points.len() {
            return Err(RunError::Search(format!(
                "{} evaluations for {} points",
                evaluations.len(),
                ask.points.len()
            )));
        }
        if let Some(progress) = solver.tell(evaluations)? {
            let mut stop = false;
            for o in observers.iter_mut() {
                stop |= o.observe(solver, &progress)? == Control::Stop;
            }
            if stop {
                return Ok(());
            }
        }
    }
}
