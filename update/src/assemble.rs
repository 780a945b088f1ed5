//! The update's record assembled from its stages: the corrections kept with their bands, the
//! cross-validation, the answer in words and what the data cannot tell apart.

use std::collections::BTreeMap;

use sepval_common::correction::{Target, interpolate};
use sepval_common::evaluation::Job;
use sepval_common::goals::Goals;
use sepval_common::table::Variable;
use sepval_core::factors::Factor;
use sepval_fit::space::{Noise, goals_of};

use crate::explored::Proposal;
use crate::outcome::{Baseline, PanelData, Update};
use crate::record::{
    CorrectionOut, CrossValidationRecord, FittedRecord, FoldRecord, GoalsRecord, LambdaRecord,
    ReleaseRecord, ScreeningRecord, UPDATE_FORMAT, UpdateFile, ValidationRecord,
};
use crate::screen::evidence;
use crate::select::Selected;
use crate::store::Store;
use crate::uncertainty::Uncertainty;

/// Points of a correction's curve in the figure.
const CURVE_POINTS: usize = 121;

/// Everything the record is made of.
pub struct Parts<'a> {
    /// The releases.
    pub job: &'a Job,
    /// The noise.
    pub noise: Noise,
    /// The baseline.
    pub baseline: &'a Baseline,
    /// The selection.
    pub selected: &'a Selected,
    /// The final fit's uncertainty.
    pub uncertainty: &'a Uncertainty,
    /// The `--validate` releases.
    pub validation: Vec<ValidationRecord>,
    /// The updated store.
    pub store: &'a Store,
    /// The free factors.
    pub free: &'a [usize],
    /// Simulations run.
    pub evaluations: u64,
    /// Wall time \[s\].
    pub wall_s: f64,
}

/// The variable's words with its unit.
pub fn variable_label(v: Variable) -> &'static str {
    match v {
        Variable::Distance => "distance from carriage [m]",
        Variable::Alpha => "local angle of attack [deg]",
        Variable::Beta => "local sideslip [deg]",
        Variable::Z => "depth below carriage [m]",
        _ => "flight Mach number [-]",
    }
}

/// The record of an update, and the data of its figure.
pub fn assemble(p: Parts) -> Update {
    let model = &p.selected.model;
    let space = &model.space;
    let values = space.values(&model.fit.lm.x);
    let mut corrections = Vec::new();
    let mut panels = Vec::new();
    for (k, (c, v)) in space.corrections().iter().zip(&values).enumerate() {
        let explored = p.selected.explored.range(c.variable);
        corrections.push(CorrectionOut {
            name: c.name(),
            field: c.target.field(),
            variable: c.variable.key().to_string(),
            breakpoints: c.breakpoints.clone(),
            values: v.clone(),
            std: p.uncertainty.value_std(space, k),
            held: c.pinned.clone(),
            explored,
            lambda: model.corrections.lambdas[k],
        });
        // The flowfield's parts are one constant for every release: a value, not a curve (its
        // shape table over depth is a curve).
        if !matches!(c.target, sepval_common::correction::Target::Field(_)) {
            panels.push(panel(&p, k, c, v, explored));
        }
    }
    let file = record(&p, corrections);
    Update {
        file,
        store: p.store.clone(),
        factors: space.factors(&model.fit.lm.x),
        panels,
    }
}

/// What the figure draws of correction `k` (`c` with its values `v`).
fn panel(p: &Parts, k: usize, c: &Proposal, v: &[f64], explored: (f64, f64)) -> PanelData {
    let space = &p.selected.model.space;
    let (lo, last) = (c.breakpoints[0], c.breakpoints[c.breakpoints.len() - 1]);
    let hi = if c.variable == Variable::Distance {
        last.min(1.5 * explored.1.max(1e-3))
    } else {
        last
    };
    let x: Vec<f64> = (0..CURVE_POINTS)
        .map(|j| lo + (hi - lo) * j as f64 / (CURVE_POINTS - 1) as f64)
        .collect();
    let alone = space
        .corrections()
        .iter()
        .filter(|o| o.target.axis() == c.target.axis())
        .count()
        == 1;
    PanelData {
        caption: c.name(),
        x_label: variable_label(c.variable).to_string(),
        value: x
            .iter()
            .map(|&x| interpolate(&c.breakpoints, v, x))
            .collect(),
        std: p.uncertainty.band(space, k, &x),
        x,
        explored,
        knots: (c.breakpoints.clone(), v.to_vec()),
        evidence: if alone && c.variable != Variable::Mach {
            evidence(c, &p.selected.misfit, &p.baseline.factors)
        } else {
            Vec::new()
        },
    }
}

/// Goals of a fit's data rows.
fn fit_goals(r: &crate::crossval::Refitted, noise: Noise) -> Goals {
    goals_of(&r.lm.residuals[..r.measure.data_rows], noise)
}

fn record(p: &Parts, corrections: Vec<CorrectionOut>) -> UpdateFile {
    let sel = p.selected;
    let folds: Vec<FoldRecord> = sel
        .folds
        .iter()
        .map(|f| FoldRecord {
            held_out: f.held_out.clone(),
            baseline: GoalsRecord::of(f.baseline.goals),
            factors_only: GoalsRecord::of(f.factors_only.goals),
            updated: GoalsRecord::of(f.updated.goals),
        })
        .collect();
    let factors = sel.model.space.factors(&sel.model.fit.lm.x);
    let fitted = FittedRecord {
        factors: Factor::ALL
            .iter()
            .map(|f| (f.name().to_string(), factors.get(*f)))
            .collect::<BTreeMap<_, _>>(),
        free: p
            .free
            .iter()
            .map(|&i| Factor::NAMES[i].to_string())
            .collect(),
        goals: GoalsRecord::of(fit_goals(&sel.model.fit, p.noise)),
        factors_only_goals: GoalsRecord::of(fit_goals(&sel.factors_only.fit, p.noise)),
        baseline_goals: GoalsRecord::of(p.baseline.lm.goals),
    };
    let (_, method) = crate::crossval::folds(p.job);
    let mut file = UpdateFile {
        format: UPDATE_FORMAT.to_string(),
        verdict: String::new(),
        releases: releases(p.job),
        sigma_pos_m: p.noise.pos_m,
        sigma_att_deg: p.noise.att_deg,
        explored: sel.explored.clone(),
        screening: ScreeningRecord {
            folds: if p.job.events().len() > 1 {
                "leave one release out".into()
            } else {
                format!(
                    "{} contiguous blocks of the one release",
                    crate::screen::TIME_BLOCKS
                )
            },
            axes: sel.first_screening.clone(),
        },
        corrections,
        rounds: sel.rounds.clone(),
        smoothness: sel
            .smoothness
            .iter()
            .map(|&(lambda, cv_chi2)| LambdaRecord { lambda, cv_chi2 })
            .collect(),
        effective_parameters: p.uncertainty.effective_parameters,
        residual_scale: p.uncertainty.residual_scale,
        cross_validation: CrossValidationRecord {
            method,
            cv_chi2_updated: sel.model.cv,
            cv_chi2_factors_only: sel.factors_only.cv,
            folds,
        },
        fitted,
        validation: p.validation.clone(),
        cannot_tell: Vec::new(),
        notes: Vec::new(),
        files: std::iter::once("scenario.toml".to_string())
            .chain(p.store.files.iter().map(|(f, _)| f.display().to_string()))
            .chain(["factors.json".to_string()])
            .collect(),
        evaluations: p.evaluations,
        wall_s: p.wall_s,
    };
    file.cannot_tell = crate::words::cannot_tell(p.job, &file);
    file.notes = crate::words::notes(p.selected, p.uncertainty, &file);
    file.verdict = crate::words::verdict(&file);
    file
}

/// The releases and their conditions.
fn releases(job: &Job) -> Vec<ReleaseRecord> {
    job.events()
        .iter()
        .map(|e| {
            let f = &e.simulator.scenario().flight;
            ReleaseRecord {
                name: e.name.clone(),
                mach: f.mach,
                altitude_m: f.altitude_m,
                alpha_deg: f.alpha_deg,
                beta_deg: f.beta_deg,
                samples: e.data.len(),
            }
        })
        .collect()
}

/// Whether `target` acts through the interference (its value scaled by a multiplier).
pub fn is_interference(target: Target) -> bool {
    matches!(target, Target::Interference(_))
}
