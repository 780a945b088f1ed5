//! Discovery's output-error refits (docs/model.md section 11.5): a candidate model's refit from
//! the current optimum, F-to-remove by refitting each term out in turn, and the increments the
//! found terms give along the fitted trajectory.

use std::sync::Arc;

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::{Evaluator, Job};
use sepval_common::extension::Axis;
use sepval_common::factors::FACTOR_COUNT;

use super::discover::{Curves, candidate_of, found_terms_before, free_terms};
use super::library::{self, Entry, Sample};
use super::{Fitted, Result};
use sepval_fit::refine::{ModelLm, refine_together};
use sepval_fit::space::{FreeTerm, Noise, ParamSpace};
use sepval_solve::lm::LmSettings;

/// The refinement of the factors of `current` and the terms of `with` together, by output
/// error, from `current`'s factors, the values of the terms already in and the last entry's
/// coefficients at zero.
pub(super) fn refit_run(
    job: &Arc<Job>,
    current: &Fitted,
    with: &[Entry],
    noise: Noise,
    settings: &LmSettings,
) -> ModelLm {
    let terms = free_terms(with);
    let space = ParamSpace::with_terms(job.factor_table(), &EffectSet::NONE, &terms);
    let new_from = terms.len() - with.last().map_or(0, |e| e.terms.len());
    let mut x0 = current.lm.x[..FACTOR_COUNT].to_vec();
    for (k, t) in terms.iter().enumerate() {
        x0.push(if k < new_from {
            t.term.coefficient
        } else {
            0.0
        });
        if t.locator.is_some() {
            x0.push(t.term.locator[0]);
        }
    }
    ModelLm::new(space, Arc::clone(job), &x0, noise, settings.clone())
}

/// For each entry of `fitted` (made of `picked`), the refit without it, from `fitted`'s
/// optimum; all refits share each batch.
pub(super) fn leave_one_out(
    evaluator: &mut dyn Evaluator,
    job: &Arc<Job>,
    fitted: &Fitted,
    picked: &[Entry],
    noise: Noise,
    settings: &LmSettings,
) -> Result<Vec<Fitted>> {
    // Parameter positions of each free term.
    let mut positions = Vec::new();
    let mut i = FACTOR_COUNT;
    for t in &fitted.terms {
        let n = 1 + usize::from(t.locator.is_some());
        positions.push(i..i + n);
        i += n;
    }
    let mut runs = Vec::new();
    let mut kept_terms = Vec::new();
    for k in 0..picked.len() {
        let from = found_terms_before(picked, k);
        let to = from + picked[k].terms.len();
        let terms: Vec<FreeTerm> = fitted
            .terms
            .iter()
            .enumerate()
            .filter(|(j, _)| *j < from || *j >= to)
            .map(|(_, t)| *t)
            .collect();
        let mut x0 = fitted.lm.x[..FACTOR_COUNT].to_vec();
        for (j, range) in positions.iter().enumerate() {
            if j < from || j >= to {
                x0.extend(&fitted.lm.x[range.clone()]);
            }
        }
        let space = ParamSpace::with_terms(job.factor_table(), &EffectSet::NONE, &terms);
        runs.push(ModelLm::new(
            space,
            Arc::clone(job),
            &x0,
            noise,
            settings.clone(),
        ));
        kept_terms.push(terms);
    }
    refine_together(evaluator, &mut runs)?;
    Ok(runs
        .into_iter()
        .zip(kept_terms)
        .map(|(run, terms)| Fitted {
            effects: EffectSet::NONE,
            terms,
            lm: run.finish(),
        })
        .collect())
}

/// Per event and axis, the increment the extension's terms give along its fitted trajectory:
/// (times \[s\], values), the ejector's while the forward foot strokes.
pub(super) fn model_increments(job: &Job, fitted: &Fitted) -> Result<Curves> {
    let c = candidate_of(job, fitted)?;
    let history = library::flow_history(job, &c);
    Ok(history
        .iter()
        .map(|samples| {
            Axis::ALL
                .iter()
                .map(|&axis| {
                    let pick = |s: &Sample| -> Option<f64> {
                        if axis == Axis::Ejector {
                            (s.sigma[0] < 1.0).then(|| {
                                c.terms
                                    .iter()
                                    .filter(|t| t.axis == axis)
                                    .map(|t| {
                                        t.coefficient * t.ejector_value(s.input.t_s, s.sigma[0])
                                    })
                                    .sum()
                            })
                        } else {
                            Some(c.terms.aero_increments(&s.input)[axis.index()])
                        }
                    };
                    samples
                        .iter()
                        .filter_map(|s| pick(s).map(|v| (s.input.t_s, v)))
                        .unzip()
                })
                .collect()
        })
        .collect())
}
