//! The explanations an earlier diagnosis left open, refitted on every release of this one
//! (`--after DIR`; docs/discovery.md section 11.9): each with the 17 factors, from more than
//! one start, as discovery's own entries are refitted (the layout of [`Picked`], so that a
//! carried model that becomes the answer is named as a discovered one is).
//!
//! **Starts.** A refit from one point can stop in a valley far from the optimum (issue 36,
//! item 2: `Cm q d/2V` refitted from the baseline's factors crept along a curved valley while
//! from the truth's factors it reached the noise). Each carried model is therefore refitted
//! from up to three points, for discovery's screening iterations each, all sharing each
//! batch: this diagnosis's baseline with the terms at zero (discovery's own start), the earlier
//! diagnosis's fit of the model (its factors, effects' values and coefficients; for a member of
//! a class, the earlier answer's factors), and this diagnosis's answer's factors with the terms
//! at zero. The best start of each then runs on to convergence (the diagnosis's refinement:
//! 400 iterations, the stall rule of its BIC resolution).
//!
//! **Bounds.** A coefficient moves within ten times the larger of its recorded value and a
//! tenth of what changes its coefficient by 1 at the largest |regressor| along this
//! baseline's trajectory ([`library::probe_size`] times 100): a class member's record holds
//! only the screening's probe, no estimate.

use std::sync::Arc;

use sepval_common::effects::{CATALOGUE, EffectSet};
use sepval_common::evaluation::{Evaluator, Job};
use sepval_common::extension::Term;
use sepval_core::factors::{FACTOR_COUNT, Factors};
use sepval_fit::refine::{ModelLm, refine_together};
use sepval_fit::space::{Noise, ParamSpace};
use sepval_solve::lm::LmSettings;

use super::picked::Picked;
use super::search::{Search, Selection, Trail};
use crate::found::Found;
use crate::library::{self, Entry};
use crate::{Fitted, Result, SkippedRefit};

/// The scale of a carried term's coefficient bound, in probes ([`library::probe_size`]): a
/// tenth of a coefficient change of 1 at the largest |regressor| (the bound is ten times it).
const PROBES_PER_SCALE: f64 = 100.0;

/// Iterations of a carried model's refit from each start (verification's are 40): enough to
/// rank the starts and the models; the best run on to convergence.
const START_ITERATIONS: usize = 15;

/// The BIC distance from the lowest (this answer's, or a carried model's from its best start)
/// within which a carried model's best start runs on to convergence: that of the rival search
/// (`crate::rivals`), three times the rival margin.
const CONVERGE_WITHIN: f64 = 3.0 * crate::RIVAL_MARGIN;

/// One explanation to carry forward.
#[derive(Debug, Clone)]
pub(crate) struct Carry {
    /// Its effects (catalogue index and recorded values).
    pub effects: Vec<(usize, Vec<f64>)>,
    /// Its entries, each term at its recorded coefficient (a class member's: its probe).
    pub entries: Vec<Entry>,
    /// Whether the coefficients are estimates (an earlier fit's), or probes only.
    pub estimated: bool,
    /// The earlier fit's factors (a class member: the earlier answer's).
    pub earlier: Factors,
}

/// A carried explanation refitted.
pub(crate) struct Carried {
    /// Its refit on every release.
    pub fitted: Fitted,
    /// Which start its refit came from.
    pub start: &'static str,
    /// Its entries at their refitted values (terms only; empty with effects).
    pub picked: Vec<Entry>,
    /// Whether its last refit stopped at its iteration limit.
    pub cut_off: bool,
}

/// A start: its name, its factors, whether the terms start at their recorded values.
type Start<'a> = (&'static str, &'a Factors, bool);

/// Each of `carries` refitted on every release of `job`, from `baseline`'s factors, the
/// earlier fit's and `answer`'s (the diagnosis's answer, when it is not the baseline); `None`
/// for one whose every start failed (recorded in `skipped`).
pub(crate) fn refit_carried(
    evaluator: &mut dyn Evaluator,
    job: &Arc<Job>,
    noise: Noise,
    settings: &LmSettings,
    (baseline, answer): (&Fitted, &Fitted),
    carries: &[Carry],
    skipped: &mut Vec<SkippedRefit>,
) -> Result<Vec<Option<Carried>>> {
    let search = Search::new(job, noise, settings);
    let history = library::flow_history(job, &baseline.candidate(job)?);
    let base = factors_of(baseline);
    let ans = factors_of(answer);
    let screening = LmSettings {
        max_iterations: search.screening.max_iterations.min(START_ITERATIONS),
        ..search.screening.clone()
    };
    let mut runs: Vec<ModelLm> = Vec::new();
    let mut owner: Vec<(usize, &'static str)> = Vec::new();
    for (k, c) in carries.iter().enumerate() {
        let (space, recorded) = carried_space(job, c, &history)?;
        let mut starts: Vec<Start> = vec![("this baseline", &base, false)];
        starts.push(("the earlier fit", &c.earlier, c.estimated));
        let same = |a: &Factors, b: &Factors| {
            a.0.iter()
                .zip(&b.0)
                .all(|(x, y)| x.to_bits() == y.to_bits())
        };
        if c.estimated && !same(&ans, &base) {
            starts.push(("this answer", &ans, false));
        }
        for (name, factors, at_recorded) in starts {
            let x0 = start_vector(&space, factors, &recorded, at_recorded, c);
            runs.push(ModelLm::new(
                space.clone(),
                Arc::clone(job),
                &x0,
                noise,
                screening.clone(),
            ));
            owner.push((k, name));
        }
    }
    refine_together(evaluator, &mut runs)?;
    let mut best: Vec<Option<(Fitted, &'static str)>> = vec![None; carries.len()];
    for ((k, name), run) in owner.into_iter().zip(runs) {
        let space = run.space().clone();
        if run.failure().is_some() {
            continue;
        }
        let lm = run.finish();
        if best[k].as_ref().is_none_or(|(b, _)| lm.cost < b.lm.cost) {
            let fitted = Fitted {
                effects: space.effects,
                terms: space.terms.clone(),
                lm,
            };
            best[k] = Some((fitted, name));
        }
    }
    let bic = |f: &Fitted| crate::bic(f.lm.cost, f.space(job).len(), search.m);
    let lowest = best
        .iter()
        .flatten()
        .map(|(f, _)| bic(f))
        .fold(bic(answer), f64::min);
    let near: Vec<bool> = best
        .iter()
        .map(|b| {
            b.as_ref()
                .is_some_and(|(f, _)| bic(f) < lowest + CONVERGE_WITHIN)
        })
        .collect();
    converge_best(evaluator, &search, carries, best, &near, skipped)
}

/// The best start of each carried model `near` the lowest BIC run on to convergence, all
/// sharing each batch (the others keep their start's refit, cut off: their BIC an upper bound).
fn converge_best(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    carries: &[Carry],
    best: Vec<Option<(Fitted, &'static str)>>,
    near: &[bool],
    skipped: &mut Vec<SkippedRefit>,
) -> Result<Vec<Option<Carried>>> {
    let job = search.job;
    let mut runs: Vec<ModelLm> = Vec::new();
    let mut of: Vec<usize> = Vec::new();
    for (k, b) in best.iter().enumerate() {
        match b {
            Some(_) if !near[k] => {}
            Some((f, _)) => {
                runs.push(ModelLm::new(
                    f.space(job),
                    Arc::clone(job),
                    &f.lm.x,
                    search.noise,
                    search.settings.clone(),
                ));
                of.push(k);
            }
            None => skipped.push(SkippedRefit {
                stage: "after: carried forward".into(),
                model: carry_name(&carries[k]),
                reason: "no start simulated".into(),
            }),
        }
    }
    refine_together(evaluator, &mut runs)?;
    let mut out: Vec<Option<Carried>> = best
        .into_iter()
        .map(|b| {
            b.map(|(fitted, start)| Carried {
                cut_off: fitted.lm.cut_off(),
                fitted,
                start,
                picked: Vec::new(),
            })
        })
        .collect();
    for (k, run) in of.into_iter().zip(runs) {
        let failed = run.failure().is_some();
        let lm = run.finish();
        if let Some(c) = out[k].as_mut() {
            c.cut_off = if failed { c.cut_off } else { lm.cut_off() };
            if !failed && lm.cost < c.fitted.lm.cost {
                c.fitted.lm = lm;
            }
        }
    }
    for (c, carry) in out.iter_mut().zip(carries) {
        match c.as_mut() {
            Some(c) if carry.effects.is_empty() => {
                c.picked = picked(carry).at(job, &c.fitted)?.entries().to_vec();
            }
            _ => {}
        }
    }
    Ok(out)
}

/// The factors of a fitted model.
fn factors_of(f: &Fitted) -> Factors {
    let mut x = [0.0; FACTOR_COUNT];
    x.copy_from_slice(&f.lm.x[..FACTOR_COUNT]);
    Factors(x)
}

/// The entries of a carried model as [`Picked`] lays them out.
fn picked(c: &Carry) -> Picked {
    c.entries
        .iter()
        .fold(Picked::default(), |p, e| p.with(e.clone()))
}

/// The parameter space of a carried model (its effects at their neutral values, its terms
/// bounded as the module says) and each term's recorded coefficient.
fn carried_space(
    job: &Job,
    c: &Carry,
    history: &[Vec<library::Sample>],
) -> Result<(ParamSpace, Vec<f64>)> {
    let mut effects = EffectSet::NONE;
    for (index, _) in &c.effects {
        let neutral: Vec<f64> = CATALOGUE[*index]
            .params()
            .iter()
            .map(|p| p.neutral)
            .collect();
        effects.push(*index, &neutral)?;
    }
    let mut recorded = Vec::new();
    let scaled: Vec<Entry> = c
        .entries
        .iter()
        .map(|e| Entry {
            terms: e
                .terms
                .iter()
                .map(|t| {
                    recorded.push(t.coefficient);
                    let scale = PROBES_PER_SCALE * library::probe_size(t, history);
                    Term {
                        coefficient: scale.max(t.coefficient.abs()),
                        ..*t
                    }
                })
                .collect(),
        })
        .collect();
    let terms = scaled
        .iter()
        .fold(Picked::default(), |p, e| p.with(e.clone()))
        .free_terms();
    Ok((
        ParamSpace::with_terms(job.factor_table(), &effects, &terms),
        recorded,
    ))
}

/// The start vector of `space` at `factors` (clamped to the factor table), the effects at their
/// recorded values (`at_recorded`) or neutral, the terms' coefficients at their recorded values
/// or zero.
fn start_vector(
    space: &ParamSpace,
    factors: &Factors,
    recorded: &[f64],
    at_recorded: bool,
    c: &Carry,
) -> Vec<f64> {
    let mut x = space.vector(factors, &space.effects);
    if at_recorded {
        let values: Vec<f64> = c.effects.iter().flat_map(|(_, v)| v.clone()).collect();
        if values.len() == x.len() - FACTOR_COUNT {
            x.truncate(FACTOR_COUNT);
            x.extend(values);
        }
    }
    for (t, &r) in space.terms.iter().zip(recorded) {
        let mut s = t.start();
        s[0] = if at_recorded { r } else { 0.0 };
        x.extend(s);
    }
    for (j, v) in x.iter_mut().enumerate() {
        *v = v.clamp(space.params.lo[j], space.params.hi[j]);
    }
    x
}

/// A carried model in words.
pub(crate) fn carry_name(c: &Carry) -> String {
    let mut parts: Vec<String> = c
        .effects
        .iter()
        .map(|(i, _)| CATALOGUE[*i].id().to_string())
        .collect();
    parts.extend(c.entries.iter().map(Entry::label));
    parts.join(" + ")
}

/// A carried model of terms only, refitted (`fitted`, its entries `entries`), named as
/// discovery names its extension, with its gain over `baseline` and each entry's own.
pub(crate) fn found_of(
    evaluator: &mut dyn Evaluator,
    job: &Arc<Job>,
    noise: Noise,
    settings: &LmSettings,
    baseline: &Fitted,
    fitted: &Fitted,
    entries: &[Entry],
) -> Result<(Option<Found>, Vec<SkippedRefit>)> {
    let search = Search::new(job, noise, settings);
    let mut trail = Trail::default();
    let picked = entries
        .iter()
        .fold(Picked::default(), |p, e| p.with(e.clone()));
    let sel = Selection {
        current: fitted.clone(),
        picked,
        groups: vec![Vec::new(); entries.len()],
        near: vec![super::search::Near::default(); entries.len()],
        without: None,
    };
    let found = super::conclude(evaluator, &search, baseline, sel, &mut trail)?;
    Ok((found, trail.skipped))
}
