//! The catalogue stage of a diagnosis: every effect of the catalogue (`docs/model.md` section
//! 7) extends the model in turn and is refitted from the baseline optimum, all candidate refits
//! sharing each batch sent to the workers; each is judged by nested least squares (chi-square
//! drop, the F test of its extra parameters, Bonferroni-corrected over the round, and the BIC
//! change, G. Schwarz 1978); the significant one of lowest BIC is chosen, and further effects
//! are added while each addition is itself significant (forward selection). A candidate whose
//! refit does not simulate is reported as skipped and not judged; the others go on.

use std::collections::BTreeMap;
use std::sync::Arc;

use sepval_common::effects::{CATALOGUE, EffectSet, MAX_ACTIVE_EFFECTS};
use sepval_common::evaluation::{Evaluator, Job};
use sepval_core::factors::FACTOR_COUNT;

use super::contender::Contender;
use super::residuals::{physical_residuals, rms_channels};
use super::{ALPHA, CandidateReport, Fitted, ParamValue, Result, SkippedRefit, bic};
use sepval_fit::refine::{ModelLm, refine_together};
use sepval_fit::space::{Noise, ParamSpace};
use sepval_solve::identifiability::identifiability;
use sepval_solve::lm::{LmResult, LmSettings};
use sepval_solve::run::SearchError;
use sepval_solve::stats::f_test;

/// Refines a model again from its optimum until it converges (a reference model must be
/// converged for the drops of its extensions to measure them); keeps the better of the two.
/// A refinement that does not simulate leaves the model as it was, reported in `skipped`.
pub(super) fn converge(
    evaluator: &mut dyn Evaluator,
    job: &Arc<Job>,
    fitted: Fitted,
    noise: Noise,
    settings: &LmSettings,
    skipped: &mut Vec<SkippedRefit>,
) -> Result<Fitted> {
    let (lm, failure) = refine_from(evaluator, job, &fitted, &fitted.lm.x, noise, settings)?;
    if let Some(reason) = failure {
        skipped.push(SkippedRefit {
            stage: "convergence".into(),
            model: model_name(&fitted),
            reason,
        });
        return Ok(fitted);
    }
    Ok(if lm.cost < fitted.lm.cost {
        Fitted { lm, ..fitted }
    } else {
        fitted
    })
}

/// The model of `fitted` (its space) refined from `x0`, with the reason when the refinement
/// did not simulate (its result then counts the simulations only).
pub(super) fn refine_from(
    evaluator: &mut dyn Evaluator,
    job: &Arc<Job>,
    fitted: &Fitted,
    x0: &[f64],
    noise: Noise,
    settings: &LmSettings,
) -> Result<(LmResult, Option<String>)> {
    let mut run = [ModelLm::new(
        fitted.space(job),
        Arc::clone(job),
        x0,
        noise,
        settings.clone(),
    )];
    refine_together(evaluator, &mut run)?;
    let [run] = run;
    let failure = run.failure().map(ToString::to_string);
    Ok((run.finish(), failure))
}

/// How a skipped refit names its model: its effects and terms, or `baseline`.
fn model_name(f: &Fitted) -> String {
    let mut names: Vec<String> = f
        .effects
        .iter()
        .map(|a| a.effect().id().to_string())
        .collect();
    names.extend(
        f.terms
            .iter()
            .map(|t| format!("{}: {}", t.term.axis.name(), t.term.formula())),
    );
    if names.is_empty() {
        "baseline".into()
    } else {
        names.join(" + ")
    }
}

/// The extensions of `base` by each effect of `ids`, refitted together from `base`'s optimum;
/// `Err` with the reason for one whose refit did not simulate.
fn try_extensions(
    evaluator: &mut dyn Evaluator,
    job: &Arc<Job>,
    base: &Fitted,
    ids: &[usize],
    noise: Noise,
    settings: &LmSettings,
) -> Result<Vec<(usize, std::result::Result<Fitted, SearchError>)>> {
    let table = *job.factor_table();
    let mut runs = Vec::new();
    let mut sets = Vec::new();
    for &index in ids {
        let mut set = base.effects;
        let neutral: Vec<f64> = CATALOGUE[index]
            .params()
            .iter()
            .map(|p| p.neutral)
            .collect();
        set.push(index, &neutral)?;
        let space = ParamSpace::new(&table, &set);
        let mut x0 = base.lm.x.clone();
        x0.extend(neutral);
        runs.push(ModelLm::new(
            space,
            Arc::clone(job),
            &x0,
            noise,
            settings.clone(),
        ));
        sets.push((index, set));
    }
    refine_together(evaluator, &mut runs)?;
    Ok(sets
        .into_iter()
        .zip(runs)
        .map(|((index, effects), run)| {
            let fitted = match run.failure() {
                Some(reason) => Err(reason.clone()),
                None => Ok(Fitted {
                    effects,
                    terms: Vec::new(),
                    lm: run.finish(),
                }),
            };
            (index, fitted)
        })
        .collect())
}

/// The estimates of parameters `from..` of a fitted model, with their standard errors
/// (corrected for coloured residuals).
pub(super) fn param_values(
    space: &ParamSpace,
    fitted: &Fitted,
    events: &[usize],
    from: usize,
) -> Vec<ParamValue> {
    let id = identifiability(
        &space.params,
        &fitted.lm.x,
        &fitted.lm.residuals,
        &fitted.lm.jacobian,
        events,
    );
    id.parameters[from..]
        .iter()
        .map(|p| ParamValue {
            name: p.name.clone(),
            unit: p.unit.clone(),
            value: p.value,
            std_error: p.std_error,
        })
        .collect()
}

/// What the catalogue stage found.
pub(super) struct CatalogueOutcome {
    /// The model with the chosen effects (the baseline when none).
    pub fitted: Fitted,
    /// The chosen effects' catalogue indices, in the order chosen.
    pub chosen: Vec<usize>,
    /// Every candidate tried, every round.
    pub candidates: Vec<CandidateReport>,
    /// Each effect refitted alone from the baseline (the first round), for the rival search.
    pub contenders: Vec<Contender>,
}

/// Forward selection over the catalogue from the converged `baseline`.
pub(super) fn select(
    evaluator: &mut dyn Evaluator,
    job: &Arc<Job>,
    baseline: &Fitted,
    noise: Noise,
    settings: &LmSettings,
    skipped: &mut Vec<SkippedRefit>,
) -> Result<CatalogueOutcome> {
    let mut current = Fitted {
        effects: EffectSet::NONE,
        terms: Vec::new(),
        lm: baseline.lm.clone(),
    };
    let mut chosen: Vec<usize> = Vec::new();
    let mut candidates = Vec::new();
    let mut contenders = Vec::new();
    for round in 1..=MAX_ACTIVE_EFFECTS {
        let remaining: Vec<usize> = (0..CATALOGUE.len())
            .filter(|i| !chosen.contains(i))
            .collect();
        if remaining.is_empty() {
            break;
        }
        let judge = Judge {
            job,
            current: &current,
            round,
            threshold: ALPHA / remaining.len() as f64,
            noise,
        };
        let tried = try_extensions(evaluator, job, &current, &remaining, noise, settings)?;
        let mut best: Option<(usize, f64)> = None;
        let mut fitted_by_index = BTreeMap::new();
        for (index, fitted) in tried {
            let fitted = match fitted {
                Ok(f) => f,
                Err(reason) => {
                    skipped.push(SkippedRefit {
                        stage: format!("catalogue round {round}"),
                        model: CATALOGUE[index].id().to_string(),
                        reason: reason.to_string(),
                    });
                    continue;
                }
            };
            let report = judge.report(index, &fitted);
            if report.significant && best.is_none_or(|(_, b)| report.delta_bic < b) {
                best = Some((index, report.delta_bic));
            }
            candidates.push(report);
            if round == 1 {
                contenders.push(Contender::new(
                    &fitted,
                    remaining.len(),
                    format!("catalogue effect alone: {}", CATALOGUE[index].id()),
                ));
            }
            fitted_by_index.insert(index, fitted);
        }
        let Some((index, _)) = best else {
            break;
        };
        chosen.push(index);
        let Some(picked) = fitted_by_index.remove(&index) else {
            break;
        };
        current = converge(evaluator, job, picked, noise, settings, skipped)?;
    }
    Ok(CatalogueOutcome {
        fitted: current,
        chosen,
        candidates,
        contenders,
    })
}

/// How one round judges its candidates: against the current model, at the round's
/// Bonferroni-corrected threshold.
struct Judge<'a> {
    job: &'a Arc<Job>,
    current: &'a Fitted,
    round: usize,
    threshold: f64,
    noise: Noise,
}

impl Judge<'_> {
    /// The report of effect `index`, `fitted` with it: its F test, BIC change and estimates.
    fn report(&self, index: usize, fitted: &Fitted) -> CandidateReport {
        let (job, current, threshold) = (self.job, self.current, self.threshold);
        let events: Vec<usize> = job.events().iter().map(|e| e.data.len()).collect();
        let m = 6 * job.sample_count();
        let effect = CATALOGUE[index];
        let q = effect.params().len();
        let p1 = FACTOR_COUNT + fitted.effects.param_count();
        let (f, p) = f_test(current.lm.cost, fitted.lm.cost, q, m, p1);
        let delta_bic = bic(fitted.lm.cost, p1, m) - bic(current.lm.cost, p1 - q, m);
        let space = fitted.space(job);
        let from = space.len() - q;
        let parameters = param_values(&space, fitted, &events, from);
        let significant = p < threshold && delta_bic < 0.0;
        let note = if significant {
            String::new()
        } else {
            format!(
                "not significant (p = {p:.2e}, threshold {threshold:.1e}; BIC change {delta_bic:+.1}); the data bound it to {}",
                parameters
                    .iter()
                    .map(|v| match v.std_error {
                        Some(se) => format!(
                            "|{}| <~ {:.3e} {} (2 SE)",
                            v.name,
                            v.value.abs() + 2.0 * se,
                            v.unit
                        ),
                        None => format!("{}: undetermined", v.name),
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        };
        CandidateReport {
            id: effect.id().to_string(),
            adds: effect.adds().to_string(),
            round: self.round,
            parameters,
            chi2: fitted.lm.cost,
            chi2_drop: current.lm.cost - fitted.lm.cost,
            f,
            p_value: p,
            p_threshold: threshold,
            delta_bic,
            significant,
            goals: fitted.lm.goals.as_array(),
            channel_rms: rms_channels(&physical_residuals(
                &fitted.lm.residuals,
                self.noise,
                &events,
            )),
            note,
            refinement: format!(
                "{} after {} iterations",
                fitted.lm.stop, fitted.lm.iterations
            ),
        }
    }
}
