//! One loop for every search: a [`Solver`] asks for points and is told their evaluations; the
//! loop ([`run`]) evaluates each request through a [`Problem`] and shows every completed step
//! (a generation, an iteration) to [`Observer`]s, which write checkpoints, draw progress or stop
//! the search. It also stops, with [`RunError::Interrupted`], when a signal asks the process to.
//!
//! The split follows argmin (S. Kroboth, `argmin` 0.10, `core/{problem,solver,executor}.rs`):
//! what is evaluated (the problem, whose batch evaluation is where the in-process thread pool or
//! the worker processes plug in), one step of the algorithm (the solver, state in and state
//! out), the loop, and the side effects (observers). The genetic algorithm, the hill climber
//! and the Levenberg-Marquardt refinement are solvers over parameter vectors; the fit
//! (`sepval-fit`) wraps them as solvers over model candidates, and composes them (a genetic
//! search that tries refinements as it goes, several refinements sharing each batch).

use sepval_core::cancel;
use sepval_core::outcome::EvalError;

/// Points to evaluate, as one batch.
#[derive(Debug, Clone, PartialEq)]
pub struct Ask<P> {
    /// The points.
    pub points: Vec<P>,
    /// Whether each value must carry the evaluation's whole output (for a simulation, its
    /// samples: a refinement's residuals are made from them), not only its goals.
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
    #[error(transparent)]
    Search(SearchError),
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

/// Why a search cannot go on, though the evaluator can: the search's own failure, which a
/// caller running several searches together may record against that one and go on with the
/// others.
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum SearchError {
    /// The problem answered another number of values than the points asked.
    #[error("{answered} evaluations for {asked} points")]
    Answers {
        /// The values given.
        answered: usize,
        /// The points asked.
        asked: usize,
    },
    /// A solver told values it did not ask for, or after it finished (a defect of its
    /// caller): what happened.
    #[error("{0}")]
    Protocol(&'static str),
    /// A refinement's start that does not simulate.
    #[error("the refinement's start does not simulate (diverged or invalid)")]
    StartDiverged,
    /// A finite-difference probe of one parameter that does not simulate.
    #[error("the derivative probe of {parameter} did not simulate")]
    ProbeDiverged {
        /// The parameter probed.
        parameter: String,
    },
    /// A search whose population has no member that finished its simulation.
    #[error("no finished member to refine")]
    NoFinishedMember,
    /// The search cannot make its next step from its state (a GA's saved state that does
    /// not fit its settings): the search's own error.
    #[error(transparent)]
    State(std::sync::Arc<dyn std::error::Error + Send + Sync>),
    /// A point of the search that is not a valid model (an effect's value, an extension term
    /// out of its range): the model's own error.
    #[error(transparent)]
    Point(std::sync::Arc<dyn std::error::Error + Send + Sync>),
}

impl From<SearchError> for RunError {
    fn from(e: SearchError) -> Self {
        RunError::Search(e)
    }
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
    /// What it evaluates: parameter vectors, or (wrapped by the fit) model candidates.
    type Point;
    /// What it is told of each point: a search's outcome, a refinement's residual vector, or
    /// (wrapped by the fit) a model evaluation.
    type Value;

    /// The next batch to evaluate, or `None` when the search is finished.
    fn ask(&mut self) -> Result<Option<Ask<Self::Point>>, RunError>;

    /// The values of the last batch, in order. Returns the progress when a step (a
    /// generation, an iteration) completed with them.
    fn tell(&mut self, values: Vec<Self::Value>) -> Result<Option<Progress>, RunError>;
}

/// What a search evaluates: a batch of points to one value each, in order.
pub trait Problem<P, V> {
    /// Evaluates `points` (`with_samples`: see [`Ask::with_samples`]).
    fn evaluate(&mut self, points: &[P], with_samples: bool) -> Result<Vec<V>, RunError>;
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
    problem: &mut dyn Problem<S::Point, S::Value>,
    observers: &mut [&mut dyn Observer<S>],
) -> Result<(), RunError> {
    loop {
        cancel::check()?;
        let Some(ask) = solver.ask()? else {
            return Ok(());
        };
        let evaluations = problem.evaluate(&ask.points, ask.with_samples)?;
        if evaluations.len() != ask.points.len() {
            return Err(RunError::Search(SearchError::Answers {
                answered: evaluations.len(),
                asked: ask.points.len(),
            }));
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
