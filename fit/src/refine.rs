//! Refinement of a model to the optimum: the Levenberg-Marquardt run of `sepval-solve` over
//! the parameters of a [`ParamSpace`], asked as model candidates and told their normalised
//! residual vectors (every sample's position and attitude error divided by its noise sigma);
//! several refinements sharing each batch sent to the evaluator.

use std::sync::Arc;

use sepval_common::evaluation::{Candidate, Evaluation, Evaluator, Job};
use sepval_solve::lm::{LmResult, LmRun, LmSettings};
use sepval_solve::run::{Ask, Progress, RunError, Solver, run};

use crate::problem::{Evaluate, SAMPLE_BUDGET};
use crate::space::{Noise, ParamSpace, residual_vector};

/// A refinement of a model: Levenberg-Marquardt over the parameters of its space.
pub struct ModelLm {
    space: ParamSpace,
    job: Arc<Job>,
    lm: LmRun<Noise>,
}

impl ModelLm {
    /// A refinement of `x0` (projected onto the bounds) in `space`, on the data of `job`.
    /// Each stage's points go in parts within [`SAMPLE_BUDGET`] samples, each part's
    /// trajectories reduced to residuals and dropped before the next part is asked.
    pub fn new(
        space: ParamSpace,
        job: Arc<Job>,
        x0: &[f64],
        noise: Noise,
        settings: LmSettings,
    ) -> Self {
        let part = (SAMPLE_BUDGET / job.sample_count().max(1)).max(1);
        let lm = LmRun::new(space.params.clone(), x0, noise, settings, part);
        ModelLm { space, job, lm }
    }

    /// The parameter space.
    pub fn space(&self) -> &ParamSpace {
        &self.space
    }

    /// The result (once it asks for nothing more).
    pub fn finish(self) -> LmResult {
        self.lm.finish()
    }
}

impl Solver for ModelLm {
    type Point = Candidate;
    type Value = Evaluation;

    fn ask(&mut self) -> Result<Option<Ask<Candidate>>, RunError> {
        let Some(points) = self.lm.request() else {
            return Ok(None);
        };
        Ok(Some(Ask {
            points: points
                .iter()
                .map(|x| self.space.candidate(x))
                .collect::<Result<_, _>>()?,
            with_samples: true,
        }))
    }

    fn tell(&mut self, evaluations: Vec<Evaluation>) -> Result<Option<Progress>, RunError> {
        let noise = *self.lm.measure();
        let residuals = evaluations
            .into_iter()
            .map(|e| e.samples.map(|s| residual_vector(&self.job, &s, noise)))
            .collect();
        self.lm.tell(residuals)
    }
}

/// Several refinements driven together: each ask joins the requests of every unfinished run
/// into one batch, so that the evaluators stay busy.
struct Together<'a> {
    runs: &'a mut [ModelLm],
    owners: Vec<(usize, usize)>,
}

impl Solver for Together<'_> {
    type Point = Candidate;
    type Value = Evaluation;

    fn ask(&mut self) -> Result<Option<Ask<Candidate>>, RunError> {
        let mut points = Vec::new();
        self.owners.clear();
        for (k, run) in self.runs.iter_mut().enumerate() {
            if let Some(ask) = run.ask()? {
                self.owners.push((k, ask.points.len()));
                points.extend(ask.points);
            }
        }
        Ok((!points.is_empty()).then_some(Ask {
            points,
            with_samples: true,
        }))
    }

    fn tell(&mut self, evaluations: Vec<Evaluation>) -> Result<Option<Progress>, RunError> {
        let mut out = evaluations.into_iter();
        for &(k, len) in &self.owners {
            self.runs[k].tell(out.by_ref().take(len).collect())?;
        }
        Ok(None)
    }
}

/// Drives several refinements together: each round, the requests of all unfinished runs go to
/// the evaluator as one batch.
pub fn refine_together(
    evaluator: &mut dyn Evaluator,
    runs: &mut [ModelLm],
) -> Result<(), RunError> {
    let mut together = Together {
        runs,
        owners: Vec::new(),
    };
    run(&mut together, &mut Evaluate(evaluator), &mut [])
}
