//! Verification (`docs/discovery.md` section 11.5): each located entry refitted by output error
//! with the factors and the terms already in, the best on to convergence, its gain tested
//! against the current model, and its group of entries the data cannot tell from it.

use std::sync::Arc;

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::{Evaluator, Job};
use sepval_core::factors::FACTOR_COUNT;
use sepval_fit::refine::{ModelLm, refine_together};
use sepval_fit::space::{Noise, ParamSpace};
use sepval_solve::lm::LmSettings;

use super::locate::Located;
use super::picked::Picked;
use super::screen::Screening;
use super::search::{Search, Trail};
use crate::found::{Gain, GroupMember, Verified};
use crate::library::Entry;
use crate::{Fitted, Result, stepwise};

/// One located entry refitted with the model's factors and terms.
#[derive(Clone)]
pub(super) struct Refit {
    /// The entry.
    pub entry: Entry,
    /// The model with it.
    pub fitted: Fitted,
    /// Its index among the step's screened entries.
    pub index: usize,
}

impl Refit {
    /// How the step's record shows it.
    pub fn verified(&self) -> Verified {
        Verified {
            axis: self.entry.axis().name().to_string(),
            term: self.entry.formula(),
            chi2: self.fitted.lm.cost,
        }
    }
}

/// Where a refit of the factors and the terms of a [`Picked`] starts its last entry's
/// coefficients.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum LastEntry {
    /// At zero (an entry just tried: its linear estimate can overshoot).
    AtZero,
    /// At their values in the [`Picked`] (an entry already in).
    AsPicked,
}

/// The refinement of the factors of `current` and the terms of `with` together, by output
/// error, from `current`'s factors and the values of the terms in `with`, the last entry's
/// coefficients as `last` says.
pub(super) fn refit_run(
    job: &Arc<Job>,
    current: &Fitted,
    with: &Picked,
    last: LastEntry,
    noise: Noise,
    settings: &LmSettings,
) -> ModelLm {
    let terms = with.free_terms();
    let space = ParamSpace::with_terms(job.factor_table(), &EffectSet::NONE, &terms);
    let new_from = terms.len() - with.entries().last().map_or(0, |e| e.terms.len());
    let mut x0 = current.lm.x[..FACTOR_COUNT].to_vec();
    for (k, t) in terms.iter().enumerate() {
        let mut start = t.start();
        if k >= new_from && last == LastEntry::AtZero {
            start[0] = 0.0;
        }
        x0.extend(start);
    }
    ModelLm::new(space, Arc::clone(job), &x0, noise, settings.clone())
}

/// Each located entry refitted, for at most the screening's iterations, with `current`'s
/// factors and `now` (the entries in, at `current`'s values); best first. Each refit starts
/// from the current optimum with the new entry at zero (the linear estimate, which can
/// overshoot where the response is not linear, sets its bounds). A refit that does not simulate
/// is left out, recorded in `trail`.
pub(super) fn refit_candidates(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    current: &Fitted,
    now: &Picked,
    located: Vec<Located>,
    trail: &mut Trail,
) -> Result<Vec<Refit>> {
    let mut runs: Vec<ModelLm> = located
        .iter()
        .map(|l| {
            let with = now.with(l.entry.clone());
            refit_run(
                search.job,
                current,
                &with,
                LastEntry::AtZero,
                search.noise,
                &search.screening,
            )
        })
        .collect();
    refine_together(evaluator, &mut runs)?;
    let mut refits: Vec<Refit> = Vec::with_capacity(runs.len());
    for (l, run) in located.into_iter().zip(runs) {
        let space = run.space().clone();
        let failure = run.failure().map(ToString::to_string);
        let lm = run.finish();
        if let Some(reason) = failure {
            trail.skip(
                format!("discovery step {}", trail.steps.len() + 1),
                l.entry.label(),
                reason,
            );
            continue;
        }
        refits.push(Refit {
            entry: l.entry,
            fitted: Fitted {
                effects: EffectSet::NONE,
                terms: space.terms.clone(),
                lm,
            },
            index: l.index,
        });
    }
    refits.sort_by(|a, b| a.fitted.lm.cost.total_cmp(&b.fitted.lm.cost));
    Ok(refits)
}

/// The gain of `fitted` (the winner converged) over `current`.
pub(super) fn gain_over(search: &Search, current: &Fitted, fitted: &Fitted) -> Gain {
    let p_with = fitted.space(search.job).len();
    let q = p_with - current.space(search.job).len();
    Gain::of(current.lm.cost, fitted.lm.cost, q, p_with, search.m)
}

/// Why the step's winner does not enter.
pub(super) fn not_passing(step: usize, s: &Screening, refits: &[Refit], gain: &Gain) -> String {
    format!(
        "step {}: the regression's best entries ({}) do not pass once refitted by output error (best: {}, p = {:.2e}, threshold {:.1e}, BIC change {:+.1})",
        step + 1,
        refits
            .iter()
            .map(|r| r.entry.label())
            .collect::<Vec<_>>()
            .join("; "),
        refits[0].entry.label(),
        gain.p_value,
        s.threshold,
        gain.delta_bic
    )
}

/// What the step's record says of the entry that entered.
pub(super) fn accepted(entry: &Entry, gain: &Gain) -> String {
    format!(
        "{}: chi-square drop {:.1}, p = {:.2e}, BIC change {:+.1}",
        entry.label(),
        gain.chi2_drop,
        gain.p_value,
        gain.delta_bic
    )
}

/// The group of the winner (`refits[0]`, converged to `fitted`): entries the regression cannot
/// tell from it (|rho| >= 0.95 beyond the model's own sensitivities), and refitted rivals
/// within 2 of its chi-square. A member of the regression's group that was refitted and lost
/// by more than that is told apart by the data after all.
pub(super) fn group(s: &Screening, refits: &[Refit], fitted: &Fitted) -> Vec<GroupMember> {
    let (entry, lead) = (&refits[0].entry, refits[0].index);
    let entries = &s.entries;
    let lost = |g: &Entry| {
        refits
            .iter()
            .any(|r| r.entry.same_kind(g) && r.fitted.lm.cost - fitted.lm.cost >= 2.0)
    };
    let mut group: Vec<GroupMember> =
        stepwise::group(&s.linear.fixed, &s.lib_cols, &s.entry_cols, lead)
            .into_iter()
            .filter(|(g, _)| !entries[*g].same_kind(entry) && !lost(&entries[*g]))
            .map(|(g, rho)| GroupMember {
                axis: entries[g].axis().name().to_string(),
                family: entries[g].family().name().to_string(),
                term: entries[g].formula(),
                correlation: Some(rho),
            })
            .collect();
    for r in refits.iter().skip(1) {
        if r.fitted.lm.cost - fitted.lm.cost < 2.0
            && !group.iter().any(|g| g.term == r.entry.formula())
        {
            group.push(GroupMember {
                axis: r.entry.axis().name().to_string(),
                family: r.entry.family().name().to_string(),
                term: r.entry.formula(),
                correlation: None,
            });
        }
    }
    group.truncate(8);
    group
}
