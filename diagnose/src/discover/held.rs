//! The locator a verification holds, estimated once its entry has entered
//! (`docs/discovery.md` section 11.5): a gust's length and an oscillation's frequency stay at
//! the library's values while entries compete (each would otherwise pay a parameter it may not
//! earn), then the entry that entered has it freed, the model refitted to convergence, and the
//! freed locator kept only when the BIC falls. Otherwise the library's value stays and the
//! report says the data do not determine it.

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::Evaluator;
use sepval_common::extension::Family;
use sepval_fit::refine::refine_together;

use super::picked::{Picked, has_held_locator};
use super::search::{Search, Trail};
use super::verify::{LastEntry, gain_over, refit_run};
use crate::{Fitted, Result};

/// `fitted` (made of `picked`, at its values) with the last entry's held locator estimated
/// too, when that earns its parameter; `fitted` and `picked` unchanged otherwise.
pub(super) fn free_held_locator(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    fitted: Fitted,
    picked: Picked,
    trail: &mut Trail,
) -> Result<(Fitted, Picked)> {
    let Some(k) = picked.len().checked_sub(1) else {
        return Ok((fitted, picked));
    };
    let entry = picked.entries()[k].clone();
    if !has_held_locator(&entry) {
        return Ok((fitted, picked));
    }
    let freed = picked.with_held_free(k);
    let job = search.job;
    let mut runs = [refit_run(
        job,
        &fitted,
        &freed,
        LastEntry::AsPicked,
        search.noise,
        search.settings,
    )];
    refine_together(evaluator, &mut runs)?;
    let [run] = runs;
    let terms = run.space().terms.clone();
    let failure = run.failure().map(ToString::to_string);
    let lm = run.finish();
    let what = match entry.family() {
        Family::Wind => "its length",
        _ => "its frequency",
    };
    if let Some(reason) = failure {
        trail.skip(
            "held locator".into(),
            format!("{} with {what} free", entry.label()),
            reason,
        );
        return Ok((fitted, picked));
    }
    let with = Fitted {
        effects: EffectSet::NONE,
        terms,
        lm,
    };
    let gain = gain_over(search, &fitted, &with);
    if gain.delta_bic < 0.0 {
        trail.notes.push(format!(
            "{}: {what} estimated too (chi-square drop {:.1}, BIC change {:+.1})",
            entry.label(),
            gain.chi2_drop,
            gain.delta_bic
        ));
        let picked = freed.at(job, &with)?;
        Ok((with, picked))
    } else {
        trail.notes.push(format!(
            "{}: {what} held at the library's (estimating it too changes the chi-square by {:.1}, BIC change {:+.1}: the data do not determine it)",
            entry.label(),
            -gain.chi2_drop,
            gain.delta_bic
        ));
        Ok((fitted, picked))
    }
}
