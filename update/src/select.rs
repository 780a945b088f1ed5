//! The corrections kept, chosen by what they predict (docs/update.md section 15.5): forward
//! selection in rounds. Each round screens every correction on the reconstruction of what the
//! current model lacks (section 15.3, linearised about it, which also chooses the correction's
//! smoothness), then refits the current model with the best one by output error, to every
//! release and to each fold, and keeps it only when the folds' predictions of what they left
//! out improve by more than [`KEEP_MARGIN`] in chi-square and by [`KEEP_FRACTION`] of it; the
//! first correction that does not ends the selection.

use std::sync::Arc;

use sepval_common::correction::MAX_CORRECTION_VALUES;
use sepval_common::evaluation::{Candidate, Evaluator, Job};
use sepval_core::factors::Factors;
use sepval_diagnose::{Misfit, reconstruct_misfit};
use sepval_fit::space::Noise;
use sepval_solve::lm::LmSettings;

use crate::crossval::{Fold, Prediction, RefitSpec, Refitted, predict_all, refit_all};
use crate::explored::{Explored, Proposal};
use crate::jobs::{CLOCK, StartEvaluator, with_corrections};
use crate::record::RoundRecord;
use crate::refit::Mask;
use crate::screen::{AxisScreen, Pick, Screening, screen};
use crate::space::UpdateSpace;
use crate::{Result, UpdateError};

/// The cross-validated chi-square a correction must save to be kept (the margin of strong
/// evidence, as the screening's).
pub const KEEP_MARGIN: f64 = 6.0;
/// The fraction of the cross-validated chi-square a correction must also save to be kept: on
/// thousands of samples a drop of 6 is within what chance gives a correction of null data
/// (seen in the null test, 2026-11-26), and a change of the store that predicts 2 % better is
/// the least worth writing into it.
pub const KEEP_FRACTION: f64 = 0.02;
/// The multipliers tried besides 1 on every kept correction's lambda (each the one its
/// screening chose, by the linearised cross-validation), by the output-error cross-validated
/// chi-square: the linearisation's choice checked on either side.
pub const SMOOTHNESS: [f64; 2] = [0.1, 10.0];
/// Most rounds (corrections kept).
pub const MAX_ROUNDS: usize = 6;
/// Corrections of one round whose cross-validated chi-squares are within this of the best's
/// cannot be told from it (the margin of strong evidence: R. E. Kass and A. E. Raftery, JASA
/// 90, 1995).
pub const CANNOT_TELL: f64 = 6.0;

/// What the selection needs.
pub struct Setting {
    /// The releases as given (no corrections).
    pub job: Arc<Job>,
    /// The factors fitted by the baseline (the held ones stay there).
    pub base: Factors,
    /// The free factors' indices.
    pub free: Vec<usize>,
    /// The noise.
    pub noise: Noise,
    /// The refits' settings.
    pub lm: LmSettings,
    /// The folds.
    pub folds: Vec<Fold>,
}

/// Corrections with their smoothness.
#[derive(Debug, Clone, Default)]
pub struct Corrections {
    /// The corrections.
    pub proposals: Vec<Proposal>,
    /// Each correction's lambda.
    pub lambdas: Vec<f64>,
    /// Each correction's penalty weight (lambda times its values' mean information).
    pub weights: Vec<f64>,
}

/// A model of the selection: its corrections, its space and its fits.
#[derive(Debug, Clone)]
pub struct Model {
    /// The corrections.
    pub corrections: Corrections,
    /// The space.
    pub space: Arc<UpdateSpace>,
    /// The refit to every release.
    pub fit: Refitted,
    /// Each fold's prediction of what it left out.
    pub predictions: Vec<Prediction>,
    /// Their chi-squares summed.
    pub cv: f64,
}

/// One fold's predictions of the samples it left out.
#[derive(Debug, Clone)]
pub struct FoldScore {
    /// What was predicted.
    pub held_out: String,
    /// The scenario as given with the nominal factors (no fit).
    pub baseline: Prediction,
    /// The factors fitted to the fold.
    pub factors_only: Prediction,
    /// The factors and the corrections kept, fitted to the fold.
    pub updated: Prediction,
}

/// The outcome of the selection.
#[derive(Debug, Clone)]
pub struct Selected {
    /// The model kept.
    pub model: Model,
    /// The factors alone.
    pub factors_only: Model,
    /// Each round.
    pub rounds: Vec<RoundRecord>,
    /// Per fold.
    pub folds: Vec<FoldScore>,
    /// The screening of the first round (about the factors alone).
    pub first_screening: Vec<AxisScreen>,
    /// What the baseline lacks, reconstructed (the figure's evidence).
    pub misfit: Misfit,
    /// What the releases explored.
    pub explored: Explored,
    /// The smoothness tried on the corrections kept: (lambda, cross-validated chi-square).
    pub smoothness: Vec<(f64, f64)>,
    /// Simulations run.
    pub evaluations: u64,
}

/// A model to refit: its corrections, and its space in the evaluator's job (whose corrections
/// may hold others, held at 0), with its start.
struct Trial {
    corrections: Corrections,
    /// Where the factors it holds stay.
    base: Factors,
    space: Arc<UpdateSpace>,
    x0: Vec<f64>,
}

/// The refits of `trials` on `evaluator`, all in one batch loop: each to every release, then to
/// each fold from there, then each fold's prediction of what it left out; each model's space
/// is then its corrections' own (`model`: the corrections' bounds).
fn fit_models(
    s: &Setting,
    evaluator: &mut dyn Evaluator,
    model: &sepval_common::model::Model,
    trials: Vec<Trial>,
    evaluations: &mut u64,
) -> Result<Vec<Model>> {
    let every = Mask::all(evaluator.job().events().len());
    let specs = trials
        .iter()
        .map(|t| RefitSpec {
            space: Arc::clone(&t.space),
            mask: every.clone(),
            x0: t.x0.clone(),
        })
        .collect();
    let fits = refit_all(evaluator, specs, s.noise, &s.lm)?;
    let mut specs = Vec::new();
    for (t, fit) in trials.iter().zip(&fits) {
        specs.extend(s.folds.iter().map(|f| RefitSpec {
            space: Arc::clone(&t.space),
            mask: f.fit.clone(),
            x0: fit.lm.x.clone(),
        }));
    }
    let folds = refit_all(evaluator, specs, s.noise, &s.lm)?;
    *evaluations += fits
        .iter()
        .chain(&folds)
        .map(|r| r.lm.evaluations)
        .sum::<u64>();
    let per = s.folds.len();
    let mut items: Vec<(&UpdateSpace, &[f64], &Mask)> = Vec::new();
    for (t, chunk) in trials.iter().zip(folds.chunks(per)) {
        for (r, f) in chunk.iter().zip(&s.folds) {
            items.push((t.space.as_ref(), r.lm.x.as_slice(), &f.test));
        }
    }
    let predictions = predict_all(evaluator, &items, s.noise)?;
    *evaluations += predictions.len() as u64;
    Ok(trials
        .into_iter()
        .zip(fits)
        .zip(predictions.chunks(per))
        .map(|((t, fit), p)| {
            let c = &t.corrections;
            let space = Arc::new(UpdateSpace::new(
                model,
                t.base,
                &s.free,
                &c.proposals,
                &c.weights,
            ));
            Model {
                corrections: t.corrections,
                space,
                fit,
                predictions: p.to_vec(),
                cv: p.iter().map(|p| p.chi2).sum(),
            }
        })
        .collect())
}

/// What `model` lacks, reconstructed on `evaluator` (whose job holds its corrections): the
/// free parameters not at a bound stay free.
fn misfit_of(evaluator: &mut dyn Evaluator, model: &Model, noise: Noise) -> Result<Misfit> {
    let lm = &model.fit.lm;
    let m = model.fit.measure.data_rows;
    let params = &model.space.params;
    let free: Vec<usize> = (0..lm.x.len())
        .filter(|&c| {
            let tol = 1e-6 * params.range(c);
            lm.x[c] > params.lo[c] + tol && lm.x[c] < params.hi[c] - tol
        })
        .collect();
    let candidate: Candidate = model.space.candidate(&lm.x);
    reconstruct_misfit(
        evaluator,
        &candidate,
        &lm.residuals[..m],
        &lm.jacobian.rows(0, m).into_owned(),
        &free,
        noise,
    )
    .map_err(UpdateError::Misfit)
}

/// Selects the corrections, starting its evaluators with `start`.
pub fn select(s: &Setting, start: &mut StartEvaluator<'_>) -> Result<Selected> {
    let mut evaluations = 0;
    // One evaluator at a time: an iceoryx2 run has one coordinator.
    let mut evaluator = start(Arc::clone(&s.job)).map_err(UpdateError::Start)?;
    let model = evaluator.job().events()[0].simulator.model().clone();
    let none = Arc::new(UpdateSpace::new(&model, s.base, &s.free, &[], &[]));
    let trial = Trial {
        corrections: Corrections::default(),
        base: s.base,
        x0: none.start(&s.base, None),
        space: none,
    };
    let factors_only =
        fit_models(s, evaluator.as_mut(), &model, vec![trial], &mut evaluations)?.remove(0);
    CLOCK.lap("select: the factors alone and their folds");
    let first = misfit_of(evaluator.as_mut(), &factors_only, s.noise)?;
    evaluations += first.evaluations;
    let explored = Explored::of(&s.job, &first.history);
    let mut misfit = first.clone();
    let mut current = factors_only.clone();
    let mut rounds = Vec::new();
    let mut first_screening = Vec::new();
    for round in 0..MAX_ROUNDS {
        let factors = current.space.factors(&current.fit.lm.x);
        let screening = screen(
            &s.job,
            &misfit,
            &factors,
            &explored,
            &current.corrections.proposals,
        );
        if round == 0 {
            first_screening = screening.axes.clone();
        }
        let mut record = RoundRecord::of(round, &screening, current.cv);
        drop(evaluator);
        let shape = field_picks(&explored, &current);
        let trials = round_trials(s, start, &current, &screening, &shape, &mut evaluations)?;
        let Some((best, others)) = trials else {
            rounds.push(record);
            evaluator = start_with(s, start, &current)?;
            break;
        };
        CLOCK.lap(&format!("select: round {}", round + 1));
        judge(&mut record, &current, &best, &others);
        let kept = record.kept;
        rounds.push(record);
        if kept {
            current = best;
        }
        evaluator = start_with(s, start, &current)?;
        if !kept {
            break;
        }
        misfit = misfit_of(evaluator.as_mut(), &current, s.noise)?;
        evaluations += misfit.evaluations;
    }
    let (current, smoothness) =
        smoothness(s, evaluator.as_mut(), &model, current, &mut evaluations)?;
    CLOCK.lap("select: smoothness");
    drop(evaluator);
    let mut evaluator = start(Arc::clone(&s.job)).map_err(UpdateError::Start)?;
    let baseline = nominal_predictions(evaluator.as_mut(), s, &model)?;
    evaluations += baseline.len() as u64;
    let folds = s
        .folds
        .iter()
        .zip(baseline)
        .zip(factors_only.predictions.iter().zip(&current.predictions))
        .map(|((f, b), (fo, up))| FoldScore {
            held_out: f.held_out.clone(),
            baseline: b,
            factors_only: *fo,
            updated: *up,
        })
        .collect();
    Ok(Selected {
        model: current,
        factors_only,
        rounds,
        folds,
        first_screening,
        misfit: first,
        explored,
        smoothness,
        evaluations,
    })
}

/// The smoothness of the corrections kept, chosen by their cross-validated chi-square: each
/// multiplier of [`SMOOTHNESS`] on every correction's weight refitted (from the model fitted at
/// the screening's lambdas) on `evaluator`, whose job holds those corrections. Returns the best model and
/// every (lambda, cross-validated chi-square).
fn smoothness(
    s: &Setting,
    evaluator: &mut dyn Evaluator,
    model: &sepval_common::model::Model,
    current: Model,
    evaluations: &mut u64,
) -> Result<(Model, Vec<(f64, f64)>)> {
    // The first correction with a penalty (the flowfield's shape has none) names the weights.
    let Some(first) = current.corrections.lambdas.iter().position(|&l| l > 0.0) else {
        return Ok((current, Vec::new()));
    };
    let base = current.space.factors(&current.fit.lm.x);
    let trials: Vec<Trial> = SMOOTHNESS
        .iter()
        .map(|&m| {
            let mut corrections = current.corrections.clone();
            corrections.lambdas.iter_mut().for_each(|l| *l *= m);
            corrections.weights.iter_mut().for_each(|w| *w *= m);
            let space = Arc::new(UpdateSpace::new(
                model,
                base,
                &s.free,
                &corrections.proposals,
                &corrections.weights,
            ));
            Trial {
                corrections,
                base,
                x0: current.fit.lm.x.clone(),
                space,
            }
        })
        .collect();
    let models = fit_models(s, evaluator, model, trials, evaluations)?;
    let mut all = vec![current];
    all.extend(models);
    let mut scores: Vec<(f64, f64)> = all
        .iter()
        .map(|m| (m.corrections.lambdas[first], m.cv))
        .collect();
    scores.sort_by(|a, b| a.0.total_cmp(&b.0));
    let best = (0..all.len())
        .min_by(|&a, &b| all[a].cv.total_cmp(&all[b].cv))
        .unwrap_or(0);
    Ok((all.swap_remove(best), scores))
}

/// Records a round's choice `best` among its refits (`others` the rest) against `current`:
/// whether it is kept, and which of the others the releases cannot tell from it.
fn judge(record: &mut RoundRecord, current: &Model, best: &Model, others: &[Model]) {
    let needed = keep_needed(current.cv);
    record.correction = best.corrections.proposals.last().map(Proposal::name);
    record.cv_chi2_with = Some(best.cv);
    record.kept = best.cv < current.cv - needed;
    record.tried = others
        .iter()
        .map(|m| {
            let name = m.corrections.proposals.last().map(Proposal::name);
            (name.unwrap_or_default(), m.cv)
        })
        .collect();
    record.cannot_tell = others
        .iter()
        .filter(|m| m.cv - best.cv < CANNOT_TELL && m.cv < current.cv - needed)
        .filter_map(|m| m.corrections.proposals.last().map(Proposal::name))
        .collect();
}

/// The drop of the cross-validated chi-square from `cv` a correction must make to be kept.
pub fn keep_needed(cv: f64) -> f64 {
    KEEP_MARGIN.max(KEEP_FRACTION * cv)
}

/// An evaluator of the releases with `model`'s corrections.
fn start_with(
    s: &Setting,
    start: &mut StartEvaluator<'_>,
    model: &Model,
) -> Result<Box<dyn Evaluator>> {
    let job = Arc::new(with_corrections(&s.job, &model.corrections.proposals)?);
    start(job).map_err(UpdateError::Start)
}

/// The corrections of the flowfield's shape (docs/update.md section 15.3a) that `current` does
/// not hold yet, as picks of every round: not screened (the field's shape acts on every axis
/// through the stations, which the linearised screening of one axis's increments does not
/// see), refitted beside the screening's picks and kept by the same rule; no penalty (one
/// constant each).
fn field_picks(explored: &Explored, current: &Model) -> Vec<Pick> {
    crate::explored::field_proposals(explored)
        .into_iter()
        .filter(|p| {
            !current
                .corrections
                .proposals
                .iter()
                .any(|q| q.target == p.target)
        })
        .map(|proposal| Pick {
            proposal,
            gain: 0.0,
            lambda: 0.0,
            scale: 0.0,
        })
        .collect()
}

/// The round's picks (the screening's, then `shape`'s) refitted side by side (each added to
/// the current model, in one job that holds them all, the others held at 0): the best by its
/// cross-validated chi-square, and the others; `None` when there is none.
fn round_trials(
    s: &Setting,
    start: &mut StartEvaluator<'_>,
    current: &Model,
    screening: &Screening,
    shape: &[Pick],
    evaluations: &mut u64,
) -> Result<Option<(Model, Vec<Model>)>> {
    let mut picks: Vec<&Pick> = Vec::new();
    let mut values: usize = current
        .corrections
        .proposals
        .iter()
        .map(|p| p.breakpoints.len())
        .sum();
    for p in screening.picks.iter().chain(shape) {
        if values + p.proposal.breakpoints.len() <= MAX_CORRECTION_VALUES {
            values += p.proposal.breakpoints.len();
            picks.push(p);
        }
    }
    if picks.is_empty() {
        return Ok(None);
    }
    let mut union = current.corrections.proposals.clone();
    union.extend(picks.iter().map(|p| p.proposal.clone()));
    let job = Arc::new(with_corrections(&s.job, &union)?);
    let mut evaluator = start(job).map_err(UpdateError::Start)?;
    let model = evaluator.job().events()[0].simulator.model().clone();
    let kept = current.corrections.proposals.len();
    let base = current.space.factors(&current.fit.lm.x);
    let trials: Vec<Trial> = (0..picks.len())
        .map(|i| {
            let mut corrections = current.corrections.clone();
            corrections.proposals.push(picks[i].proposal.clone());
            corrections.lambdas.push(picks[i].lambda);
            corrections.weights.push(picks[i].lambda * picks[i].scale);
            // In the union's order: the current model's, then every pick, the others held.
            let mut proposals = union.clone();
            let mut weights = current.corrections.weights.clone();
            for (j, p) in picks.iter().enumerate() {
                if j != i {
                    proposals[kept + j].pinned = vec![true; p.proposal.pinned.len()];
                }
                weights.push(if j == i { p.lambda * p.scale } else { 0.0 });
            }
            let space = Arc::new(UpdateSpace::new(
                &model, base, &s.free, &proposals, &weights,
            ));
            Trial {
                corrections,
                base,
                x0: space.project(&current.space, &current.fit.lm.x),
                space,
            }
        })
        .collect();
    let mut models = fit_models(s, evaluator.as_mut(), &model, trials, evaluations)?;
    let best = (0..models.len())
        .min_by(|&a, &b| models[a].cv.total_cmp(&models[b].cv))
        .unwrap_or(0);
    let best = models.remove(best);
    Ok(Some((best, models)))
}

/// What the scenario as given, with the nominal factors, predicts for each fold's samples left
/// out.
fn nominal_predictions(
    evaluator: &mut dyn Evaluator,
    s: &Setting,
    model: &sepval_common::model::Model,
) -> Result<Vec<Prediction>> {
    let nominal = UpdateSpace::new(model, Factors::NOMINAL, &[], &[], &[]);
    let items: Vec<(&UpdateSpace, &[f64], &Mask)> = s
        .folds
        .iter()
        .map(|f| (&nominal, &[][..], &f.test))
        .collect();
    predict_all(evaluator, &items, s.noise)
}
