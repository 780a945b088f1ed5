//! Plan and diagnosis agree (issue 60, item 2; docs/discovery.md section 11.9): for each pair
//! of models `sepval plan` said its release separates, the plan's predicted separation (the
//! smaller of its two expected BIC margins, docs/planning.md section 12.2) against the
//! diagnosis's after the release (the BIC difference of the two models refitted on every
//! release), and the pairs on which they disagree.
//!
//! The plan is read from its directory (`--plan DIR`, DIR/plan.json of `sepval plan`, format
//! `sepval-plan/1`): only the fields used here, since this crate stands below `sepval-plan`.
//! The release flown is the first release of this diagnosis after the earlier diagnosis's
//! (the earlier releases come first, as `sepval campaign add` gives them); the plan's
//! condition is the best-ranked one at its flight condition.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use sepval_common::evaluation::Job;
use sepval_run::model_spec::ModelSpec;

use super::{AfterState, Key, PairCheck, PlanCheck, spec_key};
use crate::Fitted;
use crate::answer::Setting;

/// The plan format read.
pub const PLAN_FORMAT: &str = "sepval-plan/1";

/// A plan that cannot be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlanReadError {
    /// plan.json cannot be read.
    #[error("--plan {}: cannot read plan.json", path.display())]
    Io {
        /// The plan's directory.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// plan.json is not a plan.
    #[error("--plan {}: plan.json is not a plan of `sepval plan`", path.display())]
    Json {
        /// The plan's directory.
        path: PathBuf,
        /// Why.
        #[source]
        source: serde_json::Error,
    },
    /// Another format.
    #[error("--plan {}: format `{found}`, this sepval reads `{PLAN_FORMAT}`", path.display())]
    Format {
        /// The plan's directory.
        path: PathBuf,
        /// The format written.
        found: String,
    },
}

/// A plan, as far as it is read here.
#[derive(Debug, Clone, Deserialize)]
pub struct Plan {
    /// Its directory (filled in on reading).
    #[serde(skip)]
    pub dir: PathBuf,
    format: String,
    models: Vec<PlanModel>,
    threshold: f64,
    conditions: Vec<PlanCondition>,
}

#[derive(Debug, Clone, Deserialize)]
struct PlanModel {
    name: String,
    model: ModelSpec,
}

#[derive(Debug, Clone, Deserialize)]
struct PlanCondition {
    rank: usize,
    mach: f64,
    altitude_m: f64,
    alpha_deg: f64,
    beta_deg: f64,
    gamma_deg: f64,
    pairs: Vec<PlanPair>,
}

#[derive(Debug, Clone, Deserialize)]
struct PlanPair {
    models: [String; 2],
    separation: f64,
    separated: bool,
}

/// The plan in `dir` (its plan.json).
pub fn read(dir: &Path) -> Result<Plan, PlanReadError> {
    let path = dir.to_path_buf();
    let text =
        std::fs::read_to_string(dir.join("plan.json")).map_err(|source| PlanReadError::Io {
            path: path.clone(),
            source,
        })?;
    let mut plan: Plan = serde_json::from_str(&text).map_err(|source| PlanReadError::Json {
        path: path.clone(),
        source,
    })?;
    if plan.format != PLAN_FORMAT {
        return Err(PlanReadError::Format {
            path,
            found: plan.format,
        });
    }
    plan.dir = dir.to_path_buf();
    Ok(plan)
}

impl PlanCondition {
    /// Whether `f` is at this condition (Mach to 1e-4, altitude to 0.1 m, angles to 1e-3 deg).
    fn holds(&self, f: &sepval_common::scenario::Flight) -> bool {
        (self.mach - f.mach).abs() < 1e-4
            && (self.altitude_m - f.altitude_m).abs() < 0.1
            && (self.alpha_deg - f.alpha_deg).abs() < 1e-3
            && (self.beta_deg - f.beta_deg).abs() < 1e-3
            && (self.gamma_deg - f.gamma_deg).abs() < 1e-3
    }

    fn words(&self) -> String {
        format!(
            "Mach {}, {} m, alpha {} deg, beta {} deg, gamma {} deg",
            self.mach, self.altitude_m, self.alpha_deg, self.beta_deg, self.gamma_deg
        )
    }
}

/// The plan's predicted separations at the condition flown against the diagnosis's: the BIC of
/// each model of a pair refitted on every release (`state`'s carried models; `answer`, the
/// final answer, and the model it displaced).
pub(crate) fn check(
    plan: &Plan,
    setting: &Setting,
    state: &AfterState,
    answer: &Fitted,
) -> PlanCheck {
    let job: &Job = &setting.job;
    let flown: Vec<&sepval_common::scenario::Flight> = job
        .events()
        .iter()
        .skip(state.earlier_releases)
        .map(|e| &e.simulator.scenario().flight)
        .collect();
    let Some(at) = plan
        .conditions
        .iter()
        .find(|c| flown.iter().any(|f| c.holds(f)))
    else {
        return PlanCheck {
            plan: plan.dir.clone(),
            condition:
                "none: no release after the earlier diagnosis's is at a condition of the plan"
                    .into(),
            rank: None,
            pairs: Vec::new(),
            disagreements: Vec::new(),
        };
    };
    let bic_of = |name: &str| -> Option<f64> {
        let spec = &plan.models.iter().find(|m| m.name == name)?.model;
        let key: Key = spec_key(spec)?;
        let fitted = state
            .opens
            .iter()
            .zip(&state.carried)
            .find(|(o, _)| o.key == key)
            .and_then(|(_, c)| c.as_ref().map(|c| &c.fitted))
            .or_else(|| (fitted_key(setting, answer) == Some(key)).then_some(answer))?;
        Some(setting.bic(fitted))
    };
    let mut pairs = Vec::new();
    let mut disagreements = Vec::new();
    for p in at.pairs.iter().filter(|p| p.separated) {
        let after = match (bic_of(&p.models[0]), bic_of(&p.models[1])) {
            (Some(a), Some(b)) => Some((a - b).abs()),
            _ => None,
        };
        let agree = after.map(|a| a > plan.threshold);
        let [a, b] = &p.models;
        match (after, agree) {
            (Some(d), Some(false)) => disagreements.push(format!(
                "{a} and {b}: the plan predicted a separation of {:.1}; after the release their BIC differ by {d:.1}, not above {}: not separated",
                p.separation, plan.threshold
            )),
            (None, _) => disagreements.push(format!(
                "{a} and {b}: the plan predicted a separation of {:.1}; a model of the pair was not refitted on every release, so the diagnosis cannot say",
                p.separation
            )),
            _ => {}
        }
        pairs.push(PairCheck {
            models: p.models.clone(),
            predicted: p.separation,
            after,
            agree,
        });
    }
    PlanCheck {
        plan: plan.dir.clone(),
        condition: at.words(),
        rank: Some(at.rank),
        pairs,
        disagreements,
    }
}

/// The kind of a fitted model.
fn fitted_key(setting: &Setting, f: &Fitted) -> Option<Key> {
    let c = f.candidate(&setting.job).ok()?;
    let ids: Vec<String> = c
        .effects
        .iter()
        .map(|a| a.effect().id().to_string())
        .collect();
    let terms: Vec<_> = c.terms.iter().copied().collect();
    Some(super::key_of(&ids, &terms))
}
