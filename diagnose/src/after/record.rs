//! What a diagnosis given an earlier one (`--after DIR`) records of it (diagnosis.json's
//! `after`, documented in docs/discovery.md section 11.9).

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

/// What the releases given did to what an earlier diagnosis left open.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AfterReport {
    /// The earlier diagnosis's directory, as given.
    pub from: PathBuf,
    /// The releases it was made from (the first of this diagnosis's releases, by convention).
    pub earlier_releases: usize,
    /// The criterion that chose the answer among this diagnosis's own and the earlier
    /// explanations refitted, in words.
    pub criterion: String,
    /// Each earlier explanation (the answer, each rival, each member of each class not told
    /// apart) and this diagnosis's own answer when an earlier one replaced it: what the
    /// releases did to it.
    pub fates: Vec<Fate>,
    /// The plan's predicted separations against the diagnosis's, when `--plan` was given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plan: Option<PlanCheck>,
    /// Why something could not be carried forward (a record without its classes' terms, a term
    /// that does not read, the budget of refits).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

/// What the releases did to one explanation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fate {
    /// The explanation: its effects' ids and its terms (`axis formula`).
    pub name: String,
    /// What it was: `the earlier answer`, `an earlier rival (BIC +1.2)`, `a member of the
    /// earlier class "any of 5 pitching-moment terms: ..." (answer)`, or `this diagnosis's
    /// discovery`.
    pub was: String,
    /// `answer`, `rival` (these releases do not separate it from the answer), `told apart`,
    /// `not settled` (its refit stopped before it converged, so its BIC is only an upper
    /// bound), `not significant` (not significant against the baseline on these releases), `failed`
    /// (no start simulated) or `not refitted` (beyond the budget).
    pub status: String,
    /// Its terms and effects, as the criterion counts them (an oscillation's pair is one).
    pub terms: usize,
    /// Its free parameters, when refitted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parameters: Option<usize>,
    /// Its chi-square on every release, when refitted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chi2: Option<f64>,
    /// Its BIC less the answer's, when refitted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delta_bic: Option<f64>,
    /// Whether it explains every release to the noise (white residuals, goals at the floor).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub explained: Option<bool>,
    /// The start its best refit came from (`this baseline`, `the earlier fit`, `this answer`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<String>,
    /// Whether its refit stopped at its iteration limit (its chi-square only an upper bound).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub cut_off: bool,
    /// In words: "Cm q d/2V: explains both releases to the noise, 1 term: the answer".
    pub words: String,
}

/// The plan's predicted separations of the condition flown against the diagnosis's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanCheck {
    /// The plan's directory, as given.
    pub plan: PathBuf,
    /// The plan's condition the new release was flown at (`Mach 1.1, 3000 m, alpha -2 deg,
    /// beta 0 deg, gamma 0 deg`), or why none.
    pub condition: String,
    /// Its rank in the plan (1: recommended), when one matched.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rank: Option<usize>,
    /// Each pair the plan said the release separates.
    pub pairs: Vec<PairCheck>,
    /// The pairs on which the plan and the diagnosis disagree, in words.
    pub disagreements: Vec<String>,
}

/// One pair the plan said the release separates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PairCheck {
    /// The two models, as the plan names them.
    pub models: [String; 2],
    /// The plan's predicted separation (the smaller of its two expected BIC margins).
    pub predicted: f64,
    /// The diagnosis's: the BIC difference of the two models refitted on every release
    /// (null when one was not refitted).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub after: Option<f64>,
    /// Whether the diagnosis separates them too (`after` above the plan's threshold); null
    /// when it could not say.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub agree: Option<bool>,
}
