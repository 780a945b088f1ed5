//! DIR/plan.json as files hold it (format [`PLAN_FORMAT`]), documented field by field in
//! docs/planning.md section 12.5, and its making from a plan.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use sepval_run::model_spec::ModelSpec;

use crate::conditions::Quantity;
use crate::ranking::{RankedCondition, Standing};
use crate::separation::SEPARATION_THRESHOLD;
use crate::{Plan, Prepared};

/// The format of DIR/plan.json.
pub const PLAN_FORMAT: &str = "sepval-plan/1";

/// One model of the plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelRecord {
    /// Its name (its effects and terms).
    pub name: String,
    /// Whether it is the diagnosis's answer.
    pub answer: bool,
    /// Its BIC minus the answer's on the releases flown.
    pub delta_bic: f64,
    /// Its free parameters.
    pub parameters: usize,
    /// The model.
    pub model: ModelSpec,
}

/// Two models at one condition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PairRecord {
    /// The two models.
    pub models: [String; 2],
    /// chi2 left when the second is refitted to the first's trajectories, and the other way.
    pub chi2: [f64; 2],
    /// The expected BIC margins of those refits.
    pub margins: [f64; 2],
    /// The smaller margin.
    pub separation: f64,
    /// Whether it is above the threshold.
    pub separated: bool,
    /// Whether a model of the pair has a located term (a step's or gust's time, a gust's length,
    /// a frequency, a decay length) whose locator the diagnosis refits but this separation,
    /// linearised at the models' fits, holds: the separation may then be optimistic (a refitted
    /// frequency and phase can absorb more than the coefficients alone). Absent when false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub locators_held: bool,
}

/// One condition of the ranking.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConditionRecord {
    /// Its rank (1: recommended).
    pub rank: usize,
    /// Mach.
    pub mach: f64,
    /// Altitude \[m\].
    pub altitude_m: f64,
    /// Aircraft alpha \[deg\].
    pub alpha_deg: f64,
    /// Aircraft beta \[deg\].
    pub beta_deg: f64,
    /// Flight-path angle \[deg\].
    pub gamma_deg: f64,
    /// The smallest separation over the pairs (null without rivals or where a model did not
    /// run).
    pub separation: Option<f64>,
    /// The gain in ln det of the answer's information (null where it did not run).
    pub information_gain: Option<f64>,
    /// The pairs of models a release there separates.
    pub separates: Vec<[String; 2]>,
    /// Every pair there.
    pub pairs: Vec<PairRecord>,
    /// `ranked`, `tables_left` or `diverged`, with notes saying which and why.
    #[serde(flatten)]
    pub standing: Standing,
}

/// DIR/plan.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanFile {
    /// [`PLAN_FORMAT`].
    pub format: String,
    /// The diagnosis directory planned from.
    pub from: PathBuf,
    /// The models: the answer, then its rivals.
    pub models: Vec<ModelRecord>,
    /// `separation` with rivals, `information` without: what ranks the conditions.
    pub ranked_by: String,
    /// The separation above which a pair counts as separated.
    pub threshold: f64,
    /// Position noise \[m\] (the diagnosis's).
    pub sigma_pos_m: f64,
    /// Attitude noise \[deg\] (the diagnosis's).
    pub sigma_att_deg: f64,
    /// The quantities varied, with their values.
    pub axes: Vec<(Quantity, Vec<f64>)>,
    /// Every pair at the releases flown alone.
    pub flown_pairs: Vec<PairRecord>,
    /// ln det of the answer's information from the releases flown (with the prior).
    pub flown_log_det: f64,
    /// The conditions, best first.
    pub conditions: Vec<ConditionRecord>,
    /// Simulations run.
    pub evaluations: u64,
    /// Wall time \[s\].
    pub wall_s: f64,
}

/// DIR/plan.json's content.
pub fn plan_file(prepared: &Prepared, plan: &Plan, from: &Path, wall_s: f64) -> PlanFile {
    let models = &prepared.models.list;
    let pair = |p: &crate::separation::PairSeparation| PairRecord {
        models: p.models.map(|i| models[i].name.clone()),
        chi2: p.chi2,
        margins: p.margins,
        separation: p.separation,
        separated: p.separated(),
        locators_held: p.models.iter().any(|&i| models[i].located()),
    };
    let condition = |rank: usize, c: &RankedCondition| {
        let f = &prepared.conditions.list[c.index].flight;
        ConditionRecord {
            rank,
            mach: f.mach,
            altitude_m: f.altitude_m,
            alpha_deg: f.alpha_deg,
            beta_deg: f.beta_deg,
            gamma_deg: f.gamma_deg,
            separation: c.separation,
            information_gain: c.information_gain,
            separates: c
                .pairs
                .iter()
                .filter(|p| p.separated())
                .map(|p| p.models.map(|i| models[i].name.clone()))
                .collect(),
            pairs: c.pairs.iter().map(pair).collect(),
            standing: c.standing.clone(),
        }
    };
    PlanFile {
        format: PLAN_FORMAT.into(),
        from: from.to_path_buf(),
        models: models
            .iter()
            .map(|m| ModelRecord {
                name: m.name.clone(),
                answer: m.answer,
                delta_bic: m.delta_bic,
                parameters: m.parameters(),
                model: m.spec.clone(),
            })
            .collect(),
        ranked_by: if prepared.models.has_rivals() {
            "separation"
        } else {
            "information"
        }
        .into(),
        threshold: SEPARATION_THRESHOLD,
        sigma_pos_m: prepared.diagnosis.sigma_pos_m,
        sigma_att_deg: prepared.diagnosis.sigma_att_deg,
        axes: prepared.conditions.axes.clone(),
        flown_pairs: plan.separations.flown.iter().map(pair).collect(),
        flown_log_det: plan.information.flown_log_det,
        conditions: plan
            .ranking
            .conditions
            .iter()
            .enumerate()
            .map(|(i, c)| condition(i + 1, c))
            .collect(),
        evaluations: plan.simulated.evaluations,
        wall_s,
    }
}
