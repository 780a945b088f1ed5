//! The solvers of `sepval-solve` asked and told as model candidates: the evaluation of a batch
//! of candidates by any [`Evaluator`] (threads of this process, or worker processes), and a
//! search over decoded factor values presented as a search over candidates.

use sepval_common::evaluation::{Candidate, Evaluation, Evaluator, Outcome};
use sepval_core::factors::{FACTOR_COUNT, Factors};
use sepval_solve::run::{Ask, Problem, Progress, RunError, Solver};

use crate::space::ParamSpace;

/// Factors from a slice of (at least) 17 values.
pub fn factors_of(values: &[f64]) -> Factors {
    let mut f = [0.0; FACTOR_COUNT];
    f.copy_from_slice(&values[..FACTOR_COUNT]);
    Factors(f)
}

/// Most simulated samples one batch brings back (about 100 MB as observations): a batch that
/// asks for more is evaluated in parts, so that long telemetry records do not multiply into
/// gigabytes (the default event's 201 samples allow 9 950 candidates a batch).
pub const SAMPLE_BUDGET: usize = 2_000_000;

/// Model candidates evaluated by an [`Evaluator`] (threads of this process, or workers); a
/// batch whose samples exceed [`SAMPLE_BUDGET`] goes in parts.
pub struct Evaluate<'a>(pub &'a mut dyn Evaluator);

impl Problem<Candidate, Evaluation> for Evaluate<'_> {
    fn evaluate(
        &mut self,
        points: &[Candidate],
        with_samples: bool,
    ) -> Result<Vec<Evaluation>, RunError> {
        let per = self.0.job().sample_count().max(1);
        let part = (SAMPLE_BUDGET / per).max(1);
        if !with_samples || points.len() <= part {
            return Ok(self.0.evaluate(points, with_samples)?);
        }
        let mut out = Vec::with_capacity(points.len());
        for chunk in points.chunks(part) {
            out.extend(self.0.evaluate(chunk, true)?);
        }
        Ok(out)
    }
}

/// A search over decoded parameter values (the genetic algorithm, the hill climber), asked
/// and told as model candidates of `space`.
pub struct OnModel<S> {
    /// The search.
    pub inner: S,
    /// What its values mean.
    pub space: ParamSpace,
}

impl<S: Solver<Point = Vec<f64>, Value = Outcome>> OnModel<S> {
    /// The candidates of a search's ask.
    pub fn candidates(space: &ParamSpace, ask: Ask<Vec<f64>>) -> Result<Ask<Candidate>, RunError> {
        Ok(Ask {
            points: ask
                .points
                .iter()
                .map(|v| space.candidate(v))
                .collect::<Result<_, _>>()?,
            with_samples: ask.with_samples,
        })
    }
}

impl<S: Solver<Point = Vec<f64>, Value = Outcome>> Solver for OnModel<S> {
    type Point = Candidate;
    type Value = Evaluation;

    fn ask(&mut self) -> Result<Option<Ask<Candidate>>, RunError> {
        match self.inner.ask()? {
            Some(ask) => Ok(Some(Self::candidates(&self.space, ask)?)),
            None => Ok(None),
        }
    }

    fn tell(&mut self, evaluations: Vec<Evaluation>) -> Result<Option<Progress>, RunError> {
        self.inner
            .tell(evaluations.into_iter().map(|e| e.outcome).collect())
    }
}
