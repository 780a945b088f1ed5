//! F-to-remove (`docs/discovery.md` section 11.5): every entry of a model refitted out in turn from
//! the model's optimum (all refits sharing each batch); an entry whose removal is no longer
//! significant leaves, and each entry's gain is what its removal costs. A refit without an
//! entry that does not simulate is left out (recorded in the trail): that entry stays, and its
//! gain is the extension's whole gain.

use std::sync::Arc;

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::Evaluator;
use sepval_core::factors::FACTOR_COUNT;
use sepval_fit::refine::{ModelLm, refine_together};
use sepval_fit::space::{FreeTerm, ParamSpace};

use super::picked::Picked;
use super::search::{Search, Selection, Trail};
use crate::found::Gain;
use crate::{ALPHA, DiagnoseError, Fitted, Result};

/// For each entry of `fitted` (made of `picked`), the refit without it, from `fitted`'s
/// optimum; all refits share each batch. `None` for a refit that did not simulate (recorded in
/// `trail`).
pub(super) fn leave_one_out(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    fitted: &Fitted,
    picked: &Picked,
    trail: &mut Trail,
) -> Result<Vec<Option<Fitted>>> {
    let (job, noise, settings) = (search.job, search.noise, search.settings);
    let layout = picked.params(&fitted.terms);
    let mut runs = Vec::new();
    let mut kept_terms = Vec::new();
    for out in &layout {
        let kept = || layout.iter().filter(|e| e.terms != out.terms);
        let terms: Vec<FreeTerm> = kept()
            .flat_map(|e| fitted.terms[e.terms.clone()].iter().copied())
            .collect();
        let mut x0 = fitted.lm.x[..FACTOR_COUNT].to_vec();
        for range in kept().flat_map(|e| e.params.iter()) {
            x0.extend(&fitted.lm.x[range.clone()]);
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
    let mut out = Vec::with_capacity(runs.len());
    for ((run, terms), entry) in runs.into_iter().zip(kept_terms).zip(picked.entries()) {
        let failure = run.failure().map(ToString::to_string);
        let lm = run.finish();
        match failure {
            Some(reason) => {
                trail.skip(
                    "F-to-remove".into(),
                    format!("the model without {}", entry.label()),
                    reason,
                );
                out.push(None);
            }
            None => out.push(Some(Fitted {
                effects: EffectSet::NONE,
                terms,
                lm,
            })),
        }
    }
    Ok(out)
}

/// F-to-remove after an entry entered `sel`: the entry whose removal is least significant
/// leaves when that removal is not significant at all.
pub(super) fn f_to_remove(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    mut sel: Selection,
    trail: &mut Trail,
) -> Result<Selection> {
    if sel.picked.len() <= 1 {
        return Ok(sel);
    }
    let job = search.job;
    let mut without = leave_one_out(evaluator, search, &sel.current, &sel.picked, trail)?;
    let p_with = sel.current.space(job).len();
    let mut weakest: Option<(usize, f64)> = None;
    for (k, f) in without.iter().enumerate() {
        let Some(f) = f else { continue };
        let q = p_with - f.space(job).len();
        let g = Gain::of(f.lm.cost, sel.current.lm.cost, q, p_with, search.m);
        if !g.significant(ALPHA) && weakest.is_none_or(|(_, d)| g.chi2_drop < d) {
            weakest = Some((k, g.chi2_drop));
        }
    }
    if let Some((k, _)) = weakest {
        let entries = sel.picked.entries();
        trail.notes.push(format!(
            "{} left again: once {} was in, removing it was not significant",
            entries[k].label(),
            entries[entries.len() - 1].label(),
        ));
        sel.picked.remove(k);
        sel.groups.remove(k);
        sel.near.remove(k);
        sel.current = without.swap_remove(k).ok_or(DiagnoseError::MissingRefit)?;
        sel.without = None;
    } else {
        sel.without = Some(without);
    }
    Ok(sel)
}

/// Each entry's gain in `fitted` (made of `picked`): with several, what removing it costs; with
/// one, `total`, the extension's gain over the baseline. `made`: the refits of `fitted` without
/// each entry when F-to-remove already made them (otherwise they are made here).
pub(super) fn entry_gains(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    fitted: &Fitted,
    picked: &Picked,
    total: &Gain,
    made: Option<Vec<Option<Fitted>>>,
    trail: &mut Trail,
) -> Result<Vec<Gain>> {
    if picked.len() <= 1 {
        return Ok(vec![total.clone()]);
    }
    let job = search.job;
    let p_with = fitted.space(job).len();
    let without = match made {
        Some(without) if without.len() == picked.len() => without,
        _ => leave_one_out(evaluator, search, fitted, picked, trail)?,
    };
    Ok(without
        .iter()
        .map(|f| match f {
            Some(f) => Gain::of(
                f.lm.cost,
                fitted.lm.cost,
                p_with - f.space(job).len(),
                p_with,
                search.m,
            ),
            None => total.clone(),
        })
        .collect())
}
