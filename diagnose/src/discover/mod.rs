//! Discovery beyond the catalogue: what force and moment the fitted baseline lacks, which terms
//! of a documented library explain it, and what the model extended by them gains
//! (`docs/discovery.md`).
//!
//! 1. **Sensitivities.** The fitted baseline is simulated with each reconstruction window, then
//!    with each library term, added at a small probe coefficient; the change of the normalised
//!    residuals per unit coefficient is each term's column (`probe`: in parts within a sample
//!    budget, each part reduced to its columns at once). Long records use a subset of their
//!    samples here.
//! 2. **Reconstruction** (`reconstruct`): per event, the coefficient increments dCA ... dCn and
//!    the ejector increment as time histories with bands, from the window columns by a
//!    regularised output-error estimate.
//! 3. **Selection** (`stepwise`): stepwise regression of the residuals on the library's columns
//!    with the factors' sensitivities always in (what a factor change absorbs is no finding),
//!    F-to-enter and F-to-remove at 1 % family-wise and the predicted square error; correlated
//!    entries are reported as one group.
//! 4. **Locators.** Each selected term's locator (step time, frequency, decay length) is refined
//!    on a grid eight times finer than the library's, around the selected one; a moment axis's
//!    own damping has its refit's bounds raised to reach the model's damping (`damping`).
//! 5. **Verification.** The baseline's 17 factors and the selected terms' coefficients (and the
//!    step times and decay lengths) are refitted together by output error on every sample
//!    (the real trajectory fit, not the regression), each candidate for at most
//!    `VERIFY_ITERATIONS`, the best on to convergence. An entry is kept when its F test against
//!    the current model (the previous step's) passes at 1 % divided by the number of library
//!    entries screened in that step, and its BIC is lower; with several terms, each is refitted
//!    out in turn, and a term whose removal is not significant leaves. The gain over the
//!    baseline is reported, not tested again.
//!
//! The sensitivities are linear about the fit: they screen, the refit decides. A refit that
//! does not simulate is reported as skipped and left out. When the model already holds
//! [`MAX_TERMS`] extension terms (the scenario's and `--extension`'s), no term can be added:
//! discovery does not run, and says so (issue 21, item 10).
//!
//! In code, one step is `screen` (1 to 3), `locate` (4), `verify` (5) and `remove`
//! (F-to-remove); `picked` keeps the entries in and where their parameters sit; `naming` turns
//! the final model into the found terms.

use std::sync::Arc;

use sepval_common::evaluation::{Evaluator, Job};
use sepval_common::extension::MAX_TERMS;
use sepval_core::factors::FACTOR_COUNT;
use sepval_fit::space::Noise;
use sepval_solve::lm::LmSettings;

use crate::catalogue::converge;
use crate::found::{Discovery, Found, Gain};
use crate::reconstruct::Reconstruction;
use crate::{Fitted, Result, stepwise};
use picked::Picked;
pub(crate) use reach::Yardstick;
use search::{Search, Selection, Trail};
use verify::Refit;

pub(crate) mod carried;
mod classes;
mod damping;
mod exchange;
mod held;
mod locate;
mod located;
mod mimic;
mod naming;
mod picked;
mod reach;
mod remove;
mod screen;
mod search;
mod verify;

/// Runs discovery from the converged `baseline` (no effects, no terms): forward stepwise
/// selection, re-linearised at each step, each step's best entries verified by output-error
/// refits.
pub(super) fn discover(
    evaluator: &mut dyn Evaluator,
    job: &Arc<Job>,
    baseline: &Fitted,
    noise: Noise,
    settings: &LmSettings,
    signature: Option<&[f64]>,
    yardstick: Option<Yardstick>,
) -> Result<Discovery> {
    let search = Search::new(job, noise, settings);
    let mut trail = Trail::default();
    if search.room == 0 {
        let why = format!(
            "discovery could not run: the term budget is full (the model already holds {MAX_TERMS} extension terms, the scenario's and --extension's, the most a run can take)"
        );
        trail.notes.push(why.clone());
        return Ok(Discovery {
            reconstruction: Vec::new(),
            found: None,
            notes: trail.notes,
            steps: Vec::new(),
            contenders: Vec::new(),
            skipped: Vec::new(),
            classes: Vec::new(),
            blocked: Some(why),
        });
    }
    let mut reconstruction = Vec::new();
    let mut sel = Selection {
        current: baseline.clone(),
        picked: Picked::default(),
        groups: Vec::new(),
        near: Vec::new(),
        without: None,
    };
    let (mut bic_before, mut best_gain) = (
        crate::bic(baseline.lm.cost, baseline.space(job).len(), search.m),
        0.0,
    );
    for step in 0..stepwise::MAX_ENTRIES {
        let Some(entered) = enter(
            evaluator,
            &search,
            &sel,
            Step {
                step,
                signature: signature.filter(|_| step == 0),
            },
            &mut trail,
            &mut reconstruction,
        )?
        else {
            break;
        };
        crate::stage_clock::lap(&format!("discovery step {}: the rest", step + 1));
        sel = remove::f_to_remove(evaluator, &search, entered, &mut trail)?;
        crate::stage_clock::lap(&format!("discovery step {} F-to-remove", step + 1));
        let bic = crate::bic(sel.current.lm.cost, sel.current.space(job).len(), search.m);
        let last_gain = bic_before - bic;
        best_gain = f64::max(best_gain, last_gain);
        bic_before = bic;
        let standing = reach::Standing {
            step: step + 1,
            bic,
            best_gain,
            last_gain,
            steps_left: stepwise::MAX_ENTRIES - step - 1,
        };
        if let Some(note) = reach::out_of_reach(yardstick, standing) {
            trail.notes.push(note);
            break;
        }
    }
    let found = conclude(evaluator, &search, baseline, sel, &mut trail)?;
    crate::stage_clock::lap("discovery's gains");
    Ok(Discovery {
        reconstruction,
        found,
        notes: trail.notes,
        steps: trail.steps,
        contenders: trail.contenders,
        skipped: trail.skipped,
        classes: trail.classes,
        blocked: None,
    })
}

/// Which step of the selection, and at the first, what the rival search asks of it.
#[derive(Clone, Copy)]
struct Step<'a> {
    /// The step (0: against the baseline).
    step: usize,
    /// What the catalogue's answer changes in the residuals, whose library mimics the first
    /// step refits for the rival search.
    signature: Option<&'a [f64]>,
}

/// One step of the forward selection from `sel`: screening (and, at the first step, the
/// reconstruction), the locator zoom, the verification refits and the winner's test; the
/// model with the entry that entered, or `None` when the selection ends here.
fn enter(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    sel: &Selection,
    at: Step,
    trail: &mut Trail,
    reconstruction: &mut Vec<Reconstruction>,
) -> Result<Option<Selection>> {
    let step = at.step;
    let Some(mut s) = screen::screen(evaluator, search, sel, step, trail)? else {
        return Ok(None);
    };
    crate::stage_clock::lap("  screening");
    if step == 0 {
        // With a catalogue answer (its signature given), the classes' candidates pass the
        // larger of the library's threshold and the level the answer met, or screen as the
        // answer does.
        classes::gather(&s, search, trail, at.signature);
    }
    if let Some(signature) = at.signature {
        let exclude = s.to_verify();
        mimic::mimics(
            evaluator,
            search,
            &s,
            &sel.current,
            signature,
            &exclude,
            trail,
        )?;
    }
    if step == 0 {
        mimic::dampings(evaluator, search, &s, &sel.current, &s.to_verify(), trail)?;
    }
    crate::stage_clock::lap("  mimics");
    if let Some(r) = s.reconstruction.take() {
        *reconstruction = r;
    }
    let mut record = s.record(step, sel.current.lm.cost);
    let best = s.to_verify();
    if best.is_empty() {
        if step == 0 {
            classes::refit_leads(evaluator, search, &s, &sel.current, trail)?;
            crate::stage_clock::lap("  rival classes");
        }
        trail.steps.push(record);
        trail.notes.push(s.nothing_significant(step));
        return Ok(None);
    }
    let located = locate::locate(evaluator, search, &s, &sel.current, &best)?;
    crate::stage_clock::lap("  locators");
    let now = sel.picked.at(search.job, &sel.current)?;
    let refits = verify::refit_candidates(evaluator, search, &sel.current, &now, located, trail)?;
    crate::stage_clock::lap(&format!("  verification ({} refits)", refits.len()));
    record.verified = refits.iter().map(Refit::verified).collect();
    if step == 0 {
        mimic::from_refits(&s, &refits, trail);
        classes::refit_leads(evaluator, search, &s, &sel.current, trail)?;
        crate::stage_clock::lap("  rival classes");
    }
    let Some(winner) = refits.first() else {
        trail.steps.push(record);
        return Ok(None);
    };
    // The winner's refit runs on to convergence.
    let fitted = converge(
        evaluator,
        search.job,
        winner.fitted.clone(),
        search.noise,
        search.settings,
        &mut trail.skipped,
    )?;
    crate::stage_clock::lap("  the winner converged");
    let gain = verify::gain_over(search, &sel.current, &fitted);
    if !(gain.p_value < s.threshold && gain.delta_bic < 0.0) {
        trail
            .notes
            .push(verify::not_passing(step, &s, &refits, &gain));
        trail.steps.push(record);
        return Ok(None);
    }
    record.accepted = Some(verify::accepted(&winner.entry, &gain));
    trail.steps.push(record);
    let mut groups = sel.groups.clone();
    groups.push(verify::group(&s, &refits, &fitted));
    let mut near = sel.near.clone();
    near.push(exchange::near(step, &refits, &fitted, s.entries.len()));
    let picked = now.with(winner.entry.clone()).at(search.job, &fitted)?;
    let (fitted, picked) = held::free_held_locator(evaluator, search, fitted, picked, trail)?;
    Ok(Some(Selection {
        current: fitted,
        picked,
        groups,
        near,
        without: None,
    }))
}

/// The extension the selection ended with, named, with its gain over the baseline; `None` when
/// no entry is in.
fn conclude(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    baseline: &Fitted,
    sel: Selection,
    trail: &mut Trail,
) -> Result<Option<Found>> {
    if sel.picked.is_empty() {
        return Ok(None);
    }
    let job = search.job;
    let fitted = sel.current;
    let picked = sel.picked.at(job, &fitted)?;
    let p_with = fitted.space(job).len();
    let gain = Gain::of(
        baseline.lm.cost,
        fitted.lm.cost,
        p_with - FACTOR_COUNT,
        p_with,
        search.m,
    );
    let gains = remove::entry_gains(
        evaluator,
        search,
        &fitted,
        &picked,
        &gain,
        sel.without,
        trail,
    )?;
    exchange::exchanges(evaluator, search, &fitted, &picked, &sel.near, trail)?;
    crate::stage_clock::lap("discovery's exchanges");
    let locations = located::locations(evaluator, search, &fitted, &picked, trail)?;
    crate::stage_clock::lap("discovery's locations");
    let terms = naming::name_terms(job, &fitted, &picked, &gains, &gain, &sel.groups, locations);
    Ok(Some(Found {
        fitted,
        terms,
        gain,
    }))
}
