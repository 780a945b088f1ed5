//! Kept only as far as they predict (docs/update.md section 15.5): the folds of the
//! cross-validation over releases, refits of many spaces at once, and what each fold's refit
//! predicts on the samples it was not fitted to.

use std::sync::Arc;

use sepval_common::evaluation::{Evaluator, Job};
use sepval_common::goals::Goals;
use sepval_fit::refine::refine_together;
use sepval_fit::space::{Noise, goals_of};
use sepval_solve::lm::{LmResult, LmSettings};

use crate::refit::{Mask, Penalised, UpdateLm};
use crate::space::UpdateSpace;
use crate::{Result, UpdateError};

/// With one release, the fraction of its span (from its first sample) fitted; the rest is
/// predicted.
pub const SPLIT_FRACTION: f64 = 0.6;

/// One fold: the samples fitted and the samples predicted.
#[derive(Debug, Clone)]
pub struct Fold {
    /// What is predicted, in words (the release left out, or the last part of the one release).
    pub held_out: String,
    /// The samples fitted.
    pub fit: Mask,
    /// The samples predicted.
    pub test: Mask,
}

/// The folds of `job`: each release left out in turn, or, with one release, its first
/// [`SPLIT_FRACTION`] fitted and the rest predicted. Returns the folds and how they were made.
pub fn folds(job: &Job) -> (Vec<Fold>, String) {
    let n = job.events().len();
    if n >= 2 {
        let folds = (0..n)
            .map(|e| Fold {
                held_out: job.events()[e].name.clone(),
                fit: Mask::without(n, e),
                test: Mask::only(n, e),
            })
            .collect();
        return (folds, "leave one release out".into());
    }
    let t = &job.events()[0].data.times_s;
    let (t0, t1) = (t[0].max(0.0), t[t.len() - 1]);
    let split = t0 + SPLIT_FRACTION * (t1 - t0);
    let fold = Fold {
        held_out: format!("{} after t = {split:.3} s", job.events()[0].name),
        fit: Mask(vec![Some((f64::NEG_INFINITY, split))]),
        test: Mask(vec![Some((split, f64::INFINITY))]),
    };
    (
        vec![fold],
        format!(
            "a split in time: the first {:.0} % of the release fitted, the rest predicted",
            100.0 * SPLIT_FRACTION
        ),
    )
}

/// One refit to run: its space, the samples and the start.
pub struct RefitSpec {
    /// The space.
    pub space: Arc<UpdateSpace>,
    /// The samples fitted.
    pub mask: Mask,
    /// The start.
    pub x0: Vec<f64>,
}

/// A finished refit.
#[derive(Debug, Clone)]
pub struct Refitted {
    /// Its result (rows: the samples', then the penalty's).
    pub lm: LmResult,
    /// The measure of its rows.
    pub measure: Penalised,
}

impl Refitted {
    /// The chi-square of its samples (without the penalty).
    pub fn data_chi2(&self) -> f64 {
        self.lm.residuals[..self.measure.data_rows]
            .iter()
            .map(|r| r * r)
            .sum()
    }
}

/// Runs `specs` together on the evaluator; every refit must end (a refit that fails ends the
/// update with its reason).
pub fn refit_all(
    evaluator: &mut dyn Evaluator,
    specs: Vec<RefitSpec>,
    noise: Noise,
    settings: &LmSettings,
) -> Result<Vec<Refitted>> {
    let job = Arc::clone(evaluator.job());
    let mut runs: Vec<UpdateLm> = specs
        .into_iter()
        .map(|s| {
            UpdateLm::new(
                s.space,
                Arc::clone(&job),
                s.mask,
                &s.x0,
                noise,
                settings.clone(),
            )
        })
        .collect();
    refine_together(evaluator, &mut runs)?;
    runs.into_iter()
        .map(|r| {
            let (lm, measure) = r.finish().map_err(UpdateError::from)?;
            Ok(Refitted { lm, measure })
        })
        .collect()
}

/// What a refit predicts on samples it was not fitted to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// The chi-square of the samples predicted (normalised residuals squared, summed).
    pub chi2: f64,
    /// Their goals.
    pub goals: Goals,
}

/// The predictions of each (space, parameters, samples) on the evaluator, in one batch; a
/// prediction that does not simulate has an infinite chi-square and goals.
pub fn predict_all(
    evaluator: &mut dyn Evaluator,
    items: &[(&UpdateSpace, &[f64], &Mask)],
    noise: Noise,
) -> Result<Vec<Prediction>> {
    let job = Arc::clone(evaluator.job());
    let batch: Vec<_> = items.iter().map(|(s, x, _)| s.candidate(x)).collect();
    let out = evaluator.evaluate(&batch, true)?;
    Ok(out
        .into_iter()
        .zip(items)
        .map(|(e, (_, _, mask))| match e.samples {
            Some(s) => {
                let r = mask.residuals(&job, &s, noise);
                Prediction {
                    chi2: r.iter().map(|v| v * v).sum(),
                    goals: goals_of(&r, noise),
                }
            }
            None => Prediction {
                chi2: f64::INFINITY,
                goals: Goals {
                    j_pos_m: f64::INFINITY,
                    j_att_deg: f64::INFINITY,
                },
            },
        })
        .collect())
}
