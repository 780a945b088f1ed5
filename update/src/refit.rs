//! One output-error refit of an update (docs/update.md section 15.4): Levenberg-Marquardt over
//! an [`UpdateSpace`], its residual vector the normalised residuals of the samples it is fitted
//! to (a [`Mask`]: the releases of a fold, or the first part of one release) followed by the
//! smoothness penalty's rows L v (each correction's weighted by its lambda). Several refits share each batch
//! (`sepval_fit::refine::refine_together`).

use std::sync::Arc;

use sepval_common::evaluation::{Candidate, Evaluation, Job};
use sepval_common::goals::{Goals, residual};
use sepval_common::propagator::Observation;
use sepval_fit::problem::SAMPLE_BUDGET;
use sepval_fit::refine::Refinement;
use sepval_fit::space::{Noise, goals_of};
use sepval_solve::lm::{LmResult, LmRun, LmSettings, Measure};
use sepval_solve::run::{Ask, Progress, RunError, SearchError, Solver};

use crate::space::UpdateSpace;

/// The samples a refit is fitted to, or measured on: per event, the time span included
/// (`None`: the event is left out).
#[derive(Debug, Clone, PartialEq)]
pub struct Mask(pub Vec<Option<(f64, f64)>>);

impl Mask {
    /// Every sample of `events` events.
    pub fn all(events: usize) -> Mask {
        Mask(vec![Some((f64::NEG_INFINITY, f64::INFINITY)); events])
    }

    /// Every sample but those of event `left_out`.
    pub fn without(events: usize, left_out: usize) -> Mask {
        let mut m = Mask::all(events);
        m.0[left_out] = None;
        m
    }

    /// Event `only` alone.
    pub fn only(events: usize, only: usize) -> Mask {
        let mut m = Mask(vec![None; events]);
        m.0[only] = Some((f64::NEG_INFINITY, f64::INFINITY));
        m
    }

    /// The normalised residuals (6 per sample included) of `samples` against `job`'s data.
    pub fn residuals(&self, job: &Job, samples: &[Vec<Observation>], noise: Noise) -> Vec<f64> {
        let mut r = Vec::new();
        for ((e, sim), span) in job.events().iter().zip(samples).zip(&self.0) {
            let Some((lo, hi)) = *span else {
                continue;
            };
            for (k, o) in sim.iter().enumerate() {
                let t = e.data.times_s[k];
                if t < lo || t > hi {
                    continue;
                }
                let (p, a) = residual(o, &e.data.pos_m[k], &e.data.att_deg[k]);
                r.extend(p.iter().map(|v| v / noise.pos_m));
                r.extend(a.iter().map(|v| v / noise.att_deg));
            }
        }
        r
    }
}

/// The goals of a residual vector whose first `data_rows` rows are the samples' and the rest
/// the penalty's.
#[derive(Debug, Clone, Copy)]
pub struct Penalised {
    /// The noise levels.
    pub noise: Noise,
    /// Rows of the samples.
    pub data_rows: usize,
}

impl Measure for Penalised {
    fn goals(&self, r: &[f64]) -> Goals {
        goals_of(&r[..self.data_rows.min(r.len())], self.noise)
    }
}

/// One refit.
pub struct UpdateLm {
    space: Arc<UpdateSpace>,
    job: Arc<Job>,
    mask: Mask,
    lm: LmRun<Penalised>,
    failure: Option<SearchError>,
}

impl UpdateLm {
    /// A refit of `space` from `x0` on the samples of `mask`.
    pub fn new(
        space: Arc<UpdateSpace>,
        job: Arc<Job>,
        mask: Mask,
        x0: &[f64],
        noise: Noise,
        settings: LmSettings,
    ) -> UpdateLm {
        let samples: usize = job
            .events()
            .iter()
            .zip(&mask.0)
            .filter(|(_, m)| m.is_some())
            .map(|(e, m)| {
                let (lo, hi) = m.unwrap_or_default();
                e.data
                    .times_s
                    .iter()
                    .filter(|t| **t >= lo && **t <= hi)
                    .count()
            })
            .sum();
        let measure = Penalised {
            noise,
            data_rows: 6 * samples,
        };
        let part = (SAMPLE_BUDGET / job.sample_count().max(1)).max(1);
        let lm = LmRun::new(space.params.clone(), x0, measure, settings, part);
        UpdateLm {
            space,
            job,
            mask,
            lm,
            failure: None,
        }
    }

    /// The space.
    pub fn space(&self) -> &Arc<UpdateSpace> {
        &self.space
    }

    /// The result: its rows are the samples' (first [`Penalised::data_rows`]) and the
    /// penalty's.
    pub fn finish(self) -> Result<(LmResult, Penalised), RunError> {
        if let Some(f) = self.failure {
            return Err(RunError::Search(f));
        }
        let measure = *self.lm.measure();
        Ok((self.lm.finish(), measure))
    }
}

impl Solver for UpdateLm {
    type Point = Candidate;
    type Value = Evaluation;

    fn ask(&mut self) -> Result<Option<Ask<Candidate>>, RunError> {
        let Some(points) = self.lm.request() else {
            return Ok(None);
        };
        Ok(Some(Ask {
            points: points.iter().map(|x| self.space.candidate(x)).collect(),
            with_samples: true,
        }))
    }

    fn tell(&mut self, evaluations: Vec<Evaluation>) -> Result<Option<Progress>, RunError> {
        let noise = self.lm.measure().noise;
        let points = self.lm.request().unwrap_or_default();
        let residuals = evaluations
            .into_iter()
            .zip(points)
            .map(|(e, x)| {
                e.samples.map(|s| {
                    let mut r = self.mask.residuals(&self.job, &s, noise);
                    r.extend(self.space.penalty_rows(&x));
                    r
                })
            })
            .collect();
        self.lm.tell(residuals)
    }
}

impl Refinement for UpdateLm {
    fn record_failure(&mut self, reason: SearchError) {
        self.failure = Some(reason);
    }

    fn failure(&self) -> Option<&SearchError> {
        self.failure.as_ref()
    }
}
