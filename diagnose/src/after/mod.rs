//! A diagnosis that knows what was open (`--after DIR`; issue 60, items 1 and 2;
//! docs/discovery.md section 11.9).
//!
//! An earlier diagnosis (of fewer releases) leaves explanations open: its answer, its rivals,
//! and the members of its rival classes not told apart. When the next release is diagnosed
//! together with the earlier ones, discovery starts afresh and need not meet them again: its
//! screening ranks the library about the new baseline, and a refit that creeps (issue 36,
//! item 2) can tell a class apart on a refit that did not reach its optimum. So every one of
//! them is refitted on every release, with the 17 factors, from more than one start
//! (`crate::discover::carried`), beside this diagnosis's own answer, and the answer is chosen
//! among all of them by one criterion ([`CRITERION`]):
//!
//! 1. only models significant against the baseline take part (the F test of their extra
//!    parameters at 1 % over the number of models carried, and a lower BIC; this diagnosis's
//!    own answer passed its own tests);
//! 2. a model that explains every release to the noise (white residuals, both goals within
//!    1.1 sigma: `analysis::explains`) is preferred to any that does not, and among those the
//!    one with the fewest terms (an effect and an oscillation's pair count one each), then the
//!    lowest BIC;
//! 3. otherwise the lowest BIC (G. Schwarz 1978).
//!
//! The models that lose go to the rival search as contenders, so a model the new release does
//! not separate from the answer (within [`RIVAL_MARGIN`](crate::RIVAL_MARGIN) in BIC) stays a
//! rival. Each earlier explanation's fate is recorded (`AfterReport`), and with `--plan DIR`
//! the plan's predicted separations are set against the diagnosis's (`plan`).

use std::path::{Path, PathBuf};

use sepval_common::effects::CATALOGUE;
use sepval_common::evaluation::Evaluator;
use sepval_common::extension::{Regressor, Term, TermRecord};
use sepval_run::model_spec::ModelSpec;
use sepval_solve::lm::LmSettings;

use crate::answer::{Answer, Selected, Setting};
use crate::contender::Contender;
use crate::discover::carried::{Carried, Carry, carry_name, found_of, refit_carried};
use crate::found::Gain;
use crate::library::Entry;
use crate::{ALPHA, DiagnoseError, DiagnoseOptions, Diagnosis, Fitted, Result, SkippedRefit};

pub(crate) mod fates;
pub(crate) mod page;
pub mod plan;
mod record;

pub use record::{AfterReport, Fate, PairCheck, PlanCheck};

/// Earlier explanations refitted at most (the earlier answer and rivals first, then the
/// classes' members best class first): each costs a refit from up to three starts and one to
/// convergence, and a weak misfit's classes can hold a hundred oscillations and steps.
pub const MAX_CARRIED: usize = 16;

/// The criterion that chooses the answer among this diagnosis's own and the earlier
/// explanations, in words (the record's `criterion`).
pub const CRITERION: &str = "among this diagnosis's answer and the earlier explanations refitted on every release (each significant against the baseline: F test at 1 % over their number, and a lower BIC), a model that explains every release to the noise is preferred, the one with the fewest terms first, then the lowest BIC; without one, the lowest BIC";

/// An earlier diagnosis, read.
pub struct Earlier {
    /// Its directory, as given.
    pub dir: PathBuf,
    /// Its record.
    pub diagnosis: Diagnosis,
}

impl Earlier {
    /// The diagnosis in `dir` (its diagnosis.json, read and checked by the records' one
    /// reader, [`sepval_run::sealed::read_record`]).
    pub fn read(dir: &Path) -> Result<Earlier> {
        let bad = |message: String| DiagnoseError::NotAnEarlierDiagnosis {
            path: dir.to_path_buf(),
            message,
        };
        if !dir.is_dir() {
            return Err(bad(
                "not a directory (give the --out directory of an earlier `sepval diagnose`)".into(),
            ));
        }
        let path = dir.join("diagnosis.json");
        if !path.exists() {
            return Err(bad(
                "holds no diagnosis.json: not the output of `sepval diagnose`".into(),
            ));
        }
        let diagnosis = sepval_run::sealed::read_record(&path, "diagnosis").map_err(|source| {
            DiagnoseError::EarlierRecord {
                path: dir.to_path_buf(),
                source,
            }
        })?;
        Ok(Earlier {
            dir: dir.to_path_buf(),
            diagnosis,
        })
    }
}

/// One explanation the earlier diagnosis left open.
pub(crate) struct Open {
    /// What to refit.
    pub carry: Carry,
    /// In words.
    pub name: String,
    /// What it was.
    pub was: String,
    /// Its kind (effects, terms), to match a plan's models.
    pub key: Key,
}

/// A model's kind: its effects' ids and its terms' axis, regressor and locator (to 1e-3),
/// sorted.
pub(crate) type Key = (Vec<String>, Vec<(String, String, i64)>);

/// The kind of a model of effect `ids` and `terms`.
pub(crate) fn key_of(ids: &[String], terms: &[Term]) -> Key {
    let mut ids = ids.to_vec();
    ids.sort();
    let mut t: Vec<(String, String, i64)> = terms
        .iter()
        .map(|t| {
            (
                t.axis.name().to_string(),
                t.regressor.name().to_string(),
                (t.locator[0] * 1000.0).round() as i64,
            )
        })
        .collect();
    t.sort();
    (ids, t)
}

/// The kind of a model record, when it reads.
pub(crate) fn spec_key(spec: &ModelSpec) -> Option<Key> {
    let terms: Option<Vec<Term>> = spec.terms.iter().map(|r| r.term().ok()).collect();
    Some(key_of(&spec.effect_ids(), &terms?))
}

/// Terms grouped into library entries (an oscillation's sine and cosine at one frequency on one
/// axis are one entry).
fn entries_of(terms: &[Term]) -> Vec<Entry> {
    let mut out: Vec<Entry> = Vec::new();
    for t in terms {
        if let Some(last) = out.last_mut() {
            let s = last.terms[0];
            let pair = last.terms.len() == 1
                && s.regressor == Regressor::Sin
                && t.regressor == Regressor::Cos
                && s.axis == t.axis
                && s.locator[0].total_cmp(&t.locator[0]).is_eq();
            if pair {
                last.terms.push(*t);
                continue;
            }
        }
        out.push(Entry { terms: vec![*t] });
    }
    out
}

/// Terms of records, or why one does not read.
fn read_terms(records: &[TermRecord]) -> std::result::Result<Vec<Term>, String> {
    records
        .iter()
        .map(|r| {
            r.term()
                .map_err(|(field, message)| format!("{} `{field}`: {message}", r.axis))
        })
        .collect()
}

/// The explanation of model record `spec` (`was` what it was), when it names one.
fn from_spec(spec: &ModelSpec, was: String, notes: &mut Vec<String>) -> Option<Open> {
    if spec.effects.is_empty() && spec.terms.is_empty() {
        return None;
    }
    let mut effects = Vec::new();
    for e in &spec.effects {
        let Some(index) = CATALOGUE.iter().position(|c| c.id() == e.id) else {
            notes.push(format!("{was}: effect `{}` is not in the catalogue", e.id));
            return None;
        };
        effects.push((index, e.values.clone()));
    }
    let terms = match read_terms(&spec.terms) {
        Ok(t) => t,
        Err(why) => {
            notes.push(format!("{was}: a term does not read: {why}"));
            return None;
        }
    };
    let carry = Carry {
        effects,
        entries: entries_of(&terms),
        estimated: true,
        earlier: spec.factors,
    };
    Some(Open {
        name: carry_name(&carry),
        key: key_of(&spec.effect_ids(), &terms),
        was,
        carry,
    })
}

/// Every explanation `earlier` left open, each once, at most [`MAX_CARRIED`]: its answer, its
/// rivals, then the members of its classes not told apart; what could not be carried in
/// `notes`.
pub(crate) fn open_explanations(earlier: &Diagnosis, notes: &mut Vec<String>) -> Vec<Open> {
    let mut all: Vec<Open> = Vec::new();
    all.extend(from_spec(
        &earlier.model,
        "the earlier answer".into(),
        notes,
    ));
    for r in &earlier.rivals {
        let was = format!("an earlier rival (BIC {:+.1})", r.delta_bic);
        all.extend(from_spec(&r.model, was, notes));
    }
    let open = earlier
        .rival_classes
        .iter()
        .filter(|c| c.status != "told apart");
    for c in open {
        if c.member_terms.len() != c.members.len() {
            notes.push(format!(
                "the earlier class \"{}\" records no terms for its members (a record written before they were): only its answer and rivals are carried",
                c.words
            ));
            continue;
        }
        for (label, records) in c.members.iter().zip(&c.member_terms) {
            let terms = match read_terms(records) {
                Ok(t) => t,
                Err(why) => {
                    notes.push(format!("{label}: a term does not read: {why}"));
                    continue;
                }
            };
            let carry = Carry {
                effects: Vec::new(),
                entries: entries_of(&terms),
                estimated: false,
                earlier: earlier.model.factors,
            };
            all.push(Open {
                name: label.clone(),
                key: key_of(&[], &terms),
                was: format!(
                    "a member of the earlier class \"{}\" ({})",
                    c.words, c.status
                ),
                carry,
            });
        }
    }
    let mut out: Vec<Open> = Vec::new();
    for o in all {
        if !out.iter().any(|k| k.key == o.key) {
            out.push(o);
        }
    }
    if out.len() > MAX_CARRIED {
        let left: Vec<String> = out[MAX_CARRIED..].iter().map(|o| o.name.clone()).collect();
        notes.push(format!(
            "{} earlier explanations beyond the {MAX_CARRIED} carried were not refitted: {}",
            left.len(),
            left.join("; ")
        ));
        out.truncate(MAX_CARRIED);
    }
    out
}

/// What the diagnosis carries from the earlier one to its report.
pub(crate) struct AfterState {
    /// The earlier diagnosis's directory.
    pub from: PathBuf,
    /// Its releases.
    pub earlier_releases: usize,
    /// Its open explanations.
    pub opens: Vec<Open>,
    /// Each refitted (`None`: every start failed).
    pub carried: Vec<Option<Carried>>,
    /// This diagnosis's own answer, when an earlier explanation replaced it: its name and fit.
    pub displaced: Option<(String, Fitted)>,
    /// What could not be carried.
    pub notes: Vec<String>,
}

/// The answer chosen by [`CRITERION`] among `answer` (this diagnosis's) and the earlier
/// explanations refitted, the models that lost as contenders of the rival search, and what
/// the report needs of them.
pub(crate) fn settle(
    evaluator: &mut dyn Evaluator,
    setting: &Setting,
    baseline: &Fitted,
    answer: Answer,
    earlier: &Earlier,
    settings: &LmSettings,
    skipped: &mut Vec<SkippedRefit>,
) -> Result<(Answer, Vec<Contender>, AfterState)> {
    let job = &setting.job;
    let mut notes = Vec::new();
    let opens = open_explanations(&earlier.diagnosis, &mut notes);
    let carries: Vec<Carry> = opens.iter().map(|o| o.carry.clone()).collect();
    let models = (baseline, answer.model(baseline));
    let carried = refit_carried(
        evaluator,
        job,
        setting.noise,
        settings,
        models,
        &carries,
        skipped,
    )?;
    crate::stage_clock::lap("after: the earlier explanations refitted");
    let pool = carried.len().max(1);
    let winner = choose(setting, baseline, &answer, &carried)?;
    let mut contenders: Vec<Contender> = carried
        .iter()
        .zip(&opens)
        .filter_map(|(c, o)| c.as_ref().map(|c| (c, o)))
        .map(|(c, o)| Contender::new(&c.fitted, pool, format!("carried forward: {}", o.was)))
        .collect();
    let mut state = AfterState {
        from: earlier.dir.clone(),
        earlier_releases: earlier.diagnosis.inputs.data.len(),
        opens,
        carried,
        displaced: None,
        notes,
    };
    let Some(w) = winner else {
        return Ok((answer, contenders, state));
    };
    let (replaced, displaced) = replace(
        evaluator,
        setting,
        (baseline, settings),
        answer,
        &state,
        w,
        skipped,
    )?;
    if let Some((name, fitted)) = &displaced {
        let origin =
            format!("this diagnosis's own answer ({name}), replaced by an earlier explanation");
        contenders.push(Contender::new(fitted, 1, origin));
    }
    state.displaced = displaced;
    Ok((replaced, contenders, state))
}

/// Whether carried model `c` is significant against `baseline` (1 % over `pool`, lower BIC).
pub(crate) fn significant(setting: &Setting, baseline: &Fitted, c: &Fitted, pool: usize) -> bool {
    let job = &setting.job;
    let p_with = c.space(job).len();
    let q = p_with.saturating_sub(baseline.space(job).len());
    q > 0
        && Gain::of(baseline.lm.cost, c.lm.cost, q, p_with, setting.m)
            .significant(ALPHA / pool.max(1) as f64)
}

pub(crate) use crate::rivals::term_count;

/// The carried model [`CRITERION`] prefers to `answer`, if any (its index).
fn choose(
    setting: &Setting,
    baseline: &Fitted,
    answer: &Answer,
    carried: &[Option<Carried>],
) -> Result<Option<usize>> {
    let pool = carried.len();
    // (index: None for the answer, explained, terms, BIC)
    let mut field: Vec<(Option<usize>, bool, usize, f64)> = Vec::new();
    if !matches!(answer, Answer::Baseline) {
        let f = answer.model(baseline);
        let explained = crate::analysis::explains(setting, f)?;
        field.push((None, explained, term_count(f), setting.bic(f)));
    }
    let decided = answer.model(baseline);
    for (k, c) in carried.iter().enumerate() {
        let Some(c) = c else { continue };
        let f = &c.fitted;
        // The answer found again keeps its place (and its fate reads `answer`).
        let again = crate::rivals::same_model(f, decided, &setting.job);
        let mixed = !f.effects.is_empty() && !f.terms.is_empty();
        if again || mixed || !significant(setting, baseline, f, pool) {
            continue;
        }
        let explained = crate::analysis::explains(setting, f)?;
        field.push((Some(k), explained, term_count(f), setting.bic(f)));
    }
    let any_explains = field.iter().any(|m| m.1);
    let best = field
        .iter()
        .filter(|m| m.1 || !any_explains)
        .min_by(|a, b| {
            let by_terms = if any_explains {
                a.2.cmp(&b.2)
            } else {
                std::cmp::Ordering::Equal
            };
            by_terms.then(a.3.total_cmp(&b.3))
        });
    Ok(best.and_then(|m| m.0))
}

/// `answer` replaced by carried model `w`: the new answer, and the one it displaced (its name
/// and fit) when there was one. A carried model of terms is named as discovery names its
/// extension (each entry's gain by a refit without it, `settings`).
fn replace(
    evaluator: &mut dyn Evaluator,
    setting: &Setting,
    (baseline, settings): (&Fitted, &LmSettings),
    answer: Answer,
    state: &AfterState,
    w: usize,
    skipped: &mut Vec<SkippedRefit>,
) -> Result<(Answer, Option<(String, Fitted)>)> {
    let Some(c) = state.carried[w].as_ref() else {
        return Ok((answer, None));
    };
    let carry = &state.opens[w].carry;
    let named = if carry.effects.is_empty() {
        let job = &setting.job;
        let (found, more) = found_of(
            evaluator,
            job,
            setting.noise,
            settings,
            baseline,
            &c.fitted,
            &c.picked,
        )?;
        skipped.extend(more);
        match found {
            Some(f) => Some(f),
            None => return Ok((answer, None)),
        }
    } else {
        None
    };
    let (selected, found, displaced) = match answer {
        Answer::Baseline => (None, None, None),
        Answer::Catalogue { selected, rival } => {
            let d = (selected.names().join(" + "), selected.fitted.clone());
            (None, rival, Some(d))
        }
        Answer::Discovered { found, mimic } => {
            let name = found
                .terms
                .iter()
                .map(|t| format!("{} {}", t.axis, t.term))
                .collect::<Vec<_>>()
                .join(" + ");
            let d = (name, found.fitted.clone());
            (mimic, None, Some(d))
        }
    };
    let answer = match named {
        Some(found) => Answer::Discovered {
            found,
            mimic: selected,
        },
        None => Answer::Catalogue {
            selected: Selected {
                fitted: c.fitted.clone(),
                chosen: carry.effects.iter().map(|(i, _)| *i).collect(),
            },
            rival: found,
        },
    };
    Ok((answer, displaced))
}

/// The earlier diagnosis (`--after`) and the plan made from it (`--plan`), read and checked
/// before anything runs.
pub(crate) fn read_given(
    options: &DiagnoseOptions,
) -> Result<(Option<Earlier>, Option<plan::Plan>)> {
    let earlier = options.after.as_deref().map(Earlier::read).transpose()?;
    if options.plan.is_some() && earlier.is_none() {
        return Err(DiagnoseError::PlanWithoutAfter);
    }
    let plan = options.plan.as_deref().map(plan::read).transpose()?;
    Ok((earlier, plan))
}

/// The answer `decided`, chosen again (with an earlier diagnosis, `given`) among it and the
/// earlier explanations refitted on every release (`after`), its rivals among `contenders`
/// and the rival classes' reports, and what the releases did to the earlier explanations.
pub(crate) fn answer_and_rivals(
    evaluator: &mut dyn Evaluator,
    setting: &Setting,
    (baseline, settings): (&Fitted, &LmSettings),
    (decided, mut contenders, classes): (Answer, Vec<Contender>, &[crate::classes::ClassInfo]),
    given: (Option<&Earlier>, Option<&plan::Plan>),
    skipped: &mut Vec<SkippedRefit>,
) -> Result<(
    Answer,
    crate::Rivals,
    Vec<crate::RivalClass>,
    Option<AfterReport>,
)> {
    let (answer, state) = match given.0 {
        Some(earlier) => {
            let (answer, carried, state) = settle(
                evaluator, setting, baseline, decided, earlier, settings, skipped,
            )?;
            contenders.extend(carried);
            (answer, Some(state))
        }
        None => (decided, None),
    };
    contenders.extend(answer.rival().map(|r| r.contender()));
    let (rivals, rival_classes) = crate::rival_search(
        evaluator, setting, baseline, &answer, contenders, classes, settings,
    )?;
    let report = match &state {
        Some(state) => {
            let mut r = fates::report(setting, baseline, &answer, &rivals, state)?;
            r.plan = given
                .1
                .map(|p| plan::check(p, setting, state, answer.model(baseline)));
            Some(r)
        }
        None => None,
    };
    Ok((answer, rivals, rival_classes, report))
}

#[cfg(test)]
mod tests {
    use sepval_common::extension::Axis;

    use super::*;

    fn term(axis: Axis, regressor: Regressor, locator: f64) -> Term {
        Term {
            axis,
            regressor,
            locator: [locator, 0.0],
            coefficient: 0.1,
        }
    }

    /// An oscillation's sine and cosine at one frequency on one axis are one entry (one term as
    /// the criterion counts them); a sine alone, or a cosine at another frequency, is not paired.
    #[test]
    fn an_oscillations_pair_is_one_entry_and_kinds_ignore_order() {
        let terms = [
            term(Axis::Cm, Regressor::Q, 0.0),
            term(Axis::Cl, Regressor::Sin, 6.5),
            term(Axis::Cl, Regressor::Cos, 6.5),
            term(Axis::Cn, Regressor::Sin, 3.0),
            term(Axis::Cn, Regressor::Cos, 3.5),
        ];
        let entries = entries_of(&terms);
        let sizes: Vec<usize> = entries.iter().map(|e| e.terms.len()).collect();
        assert_eq!(sizes, [1, 2, 1, 1]);
        let mut reversed = terms;
        reversed.reverse();
        assert_eq!(key_of(&[], &terms), key_of(&[], &reversed));
        // A step's time tells two steps apart (to 1 ms), a rate term has none.
        let a = key_of(&[], &[term(Axis::CY, Regressor::Step, 0.43)]);
        let b = key_of(&[], &[term(Axis::CY, Regressor::Step, 0.45)]);
        assert_ne!(a, b);
        let ids = ["cg_offset".to_string()];
        assert_ne!(key_of(&ids, &[]), key_of(&[], &[]));
    }
}
