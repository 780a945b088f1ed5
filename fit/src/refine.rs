//! Refinement of a model to the optimum: the Levenberg-Marquardt run of `sepval-solve` over
//! the parameters of a [`ParamSpace`], asked as model candidates and told their normalised
//! residual vectors (every sample's position and attitude error divided by its noise sigma);
//! several refinements sharing each batch sent to the evaluator. One of several refinements
//! that fails on its own (its start or a derivative probe does not simulate) records why and
//! stops asking; the others go on (issue 21, item 8). Only what ends every refinement (a
//! signal, a transport that fails) ends them all.

use std::sync::Arc;

use sepval_common::evaluation::{Candidate, Evaluation, Evaluator, Job};
use sepval_solve::lm::{LmResult, LmRun, LmSettings};
use sepval_solve::run::{Ask, Progress, RunError, SearchError, Solver, run};

use crate::problem::{Evaluate, SAMPLE_BUDGET};
use crate::space::{Noise, ParamSpace, residual_vector};

/// A refinement of a model: Levenberg-Marquardt over the parameters of its space.
pub struct ModelLm {
    space: ParamSpace,
    job: Arc<Job>,
    lm: LmRun<Noise>,
    /// Why it failed, when it failed on its own in [`refine_together`].
    failure: Option<SearchError>,
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
        ModelLm {
            space,
            job,
            lm,
            failure: None,
        }
    }

    /// The parameter space.
    pub fn space(&self) -> &ParamSpace {
        &self.space
    }

    /// Why it failed on its own in [`refine_together`] (a start or a derivative probe that did
    /// not simulate), if it did: its [`ModelLm::finish`] is then not an optimum (its Jacobian
    /// may be missing) and must not be used as one.
    pub fn failure(&self) -> Option<&SearchError> {
        self.failure.as_ref()
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

/// A refinement of model candidates that [`refine_together`] can drive with others: a solver
/// asked for candidates and told their evaluations, which can fail on its own.
pub trait Refinement: Solver<Point = Candidate, Value = Evaluation> {
    /// Records why it failed on its own; it asks nothing more.
    fn record_failure(&mut self, reason: SearchError);
    /// Why it failed on its own, if it did.
    fn failure(&self) -> Option<&SearchError>;
}

impl Refinement for ModelLm {
    fn record_failure(&mut self, reason: SearchError) {
        self.failure = Some(reason);
    }

    fn failure(&self) -> Option<&SearchError> {
        self.failure.as_ref()
    }
}

/// Several refinements driven together: each ask joins the requests of every unfinished run
/// into one batch, so that the evaluators stay busy. A run whose own ask or tell fails with
/// [`RunError::Search`] records the reason and asks nothing more; any other error ends all.
struct Together<'a, R> {
    runs: &'a mut [R],
    owners: Vec<(usize, usize)>,
}

/// `Ok` of `result`, or `None` after recording a failure of `run` alone in it; other errors
/// are everyone's.
fn on_its_own<T, R: Refinement>(
    run: &mut R,
    result: Result<T, RunError>,
) -> Result<Option<T>, RunError> {
    match result {
        Ok(v) => Ok(Some(v)),
        Err(RunError::Search(reason)) => {
            run.record_failure(reason);
            Ok(None)
        }
        Err(e) => Err(e),
    }
}

impl<R: Refinement> Solver for Together<'_, R> {
    type Point = Candidate;
    type Value = Evaluation;

    fn ask(&mut self) -> Result<Option<Ask<Candidate>>, RunError> {
        let mut points = Vec::new();
        self.owners.clear();
        for (k, run) in self.runs.iter_mut().enumerate() {
            if run.failure().is_some() {
                continue;
            }
            let asked = run.ask();
            if let Some(Some(ask)) = on_its_own(run, asked)? {
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
            let run = &mut self.runs[k];
            let told = run.tell(out.by_ref().take(len).collect());
            on_its_own(run, told)?;
        }
        Ok(None)
    }
}

/// Drives several refinements together: each round, the requests of all unfinished runs go to
/// the evaluator as one batch. A run that fails on its own is left with its reason
/// ([`ModelLm::failure`]) while the others go on; an interruption or a failed transport ends
/// them all with the error.
pub fn refine_together<R: Refinement>(
    evaluator: &mut dyn Evaluator,
    runs: &mut [R],
) -> Result<(), RunError> {
    let mut together = Together {
        runs,
        owners: Vec::new(),
    };
    run(&mut together, &mut Evaluate(evaluator), &mut [])
}

#[cfg(test)]
mod tests {
    use sepval_common::evaluation::{EvalError, InProcess, Outcome};
    use sepval_common::scenario::Scenario;
    use sepval_common::synthetic::default_flight_test;
    use sepval_core::factors::{FACTOR_COUNT, Factors};

    use super::*;

    /// The start of the run that fails: `fwdfac` here, the other factors at the truth.
    const FAILING_FWDFAC: f64 = 0.4;

    /// Evaluates in process, except that the candidates just above [`FAILING_FWDFAC`] (the
    /// derivative probe of `fwdfac` from that start) do not simulate, and that with `broken`
    /// the transport fails outright.
    struct FailingProbe {
        inner: InProcess,
        broken: bool,
    }

    impl Evaluator for FailingProbe {
        fn evaluate(
            &mut self,
            batch: &[Candidate],
            with_samples: bool,
        ) -> Result<Vec<Evaluation>, EvalError> {
            if self.broken {
                return Err(EvalError::transport("every worker is gone"));
            }
            let mut out = self.inner.evaluate(batch, with_samples)?;
            for (c, e) in batch.iter().zip(&mut out) {
                let d = c.factors.0[0] - FAILING_FWDFAC;
                if d > 0.0 && d < 1e-3 {
                    *e = Evaluation::from(Outcome::Failed {
                        reason: "probe refused".into(),
                    });
                }
            }
            Ok(out)
        }

        fn job(&self) -> &Arc<Job> {
            self.inner.job()
        }

        fn describe(&self) -> String {
            "inproc with a failing probe".into()
        }
    }

    /// Two refinements of the default flight test: from the truth, and from the truth with
    /// `fwdfac` at [`FAILING_FWDFAC`].
    fn runs(job: &Arc<Job>) -> Vec<ModelLm> {
        let space = ParamSpace::new(job.factor_table(), &sepval_common::effects::EffectSet::NONE);
        let noise = Noise {
            pos_m: 0.003,
            att_deg: 0.1,
        };
        let settings = LmSettings {
            max_iterations: 3,
            ..LmSettings::default()
        };
        let truth = Factors::TRUTH.0.to_vec();
        let mut off = truth.clone();
        off[0] = FAILING_FWDFAC;
        [truth, off]
            .iter()
            .map(|x0| ModelLm::new(space.clone(), Arc::clone(job), x0, noise, settings.clone()))
            .collect()
    }

    fn job() -> Arc<Job> {
        Arc::new(Job::single(
            "default",
            &Scenario::embedded_default(),
            default_flight_test(),
        ))
    }

    #[test]
    fn a_refinement_that_fails_is_recorded_and_the_others_go_on() {
        let job = job();
        let mut evaluator = FailingProbe {
            inner: InProcess::new(Arc::clone(&job), 2),
            broken: false,
        };
        let mut runs = runs(&job);
        refine_together(&mut evaluator, &mut runs).unwrap();
        assert!(runs[0].failure().is_none());
        assert_eq!(
            runs[1].failure().map(ToString::to_string).as_deref(),
            Some("the derivative probe of fwdfac did not simulate")
        );
        let [good, _] = <[ModelLm; 2]>::try_from(runs).ok().unwrap();
        let lm = good.finish();
        assert!(lm.cost.is_finite());
        assert_eq!(lm.stop, "iteration limit");
        assert_eq!(lm.jacobian.ncols(), FACTOR_COUNT);
    }

    #[test]
    fn a_failed_transport_still_ends_every_refinement() {
        let job = job();
        let mut evaluator = FailingProbe {
            inner: InProcess::new(Arc::clone(&job), 2),
            broken: true,
        };
        let mut runs = runs(&job);
        let e = refine_together(&mut evaluator, &mut runs).unwrap_err();
        assert!(matches!(e, RunError::Eval(_)), "{e}");
        assert!(runs.iter().all(|r| r.failure().is_none()));
    }
}
