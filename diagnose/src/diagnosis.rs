//! The diagnosis as files hold it (DIR/diagnosis.json, format [`super::DIAGNOSIS_FORMAT`]):
//! every record the analysis produces, documented field by field in docs/discovery.md section 11.7.

use std::collections::BTreeMap;

use sepval_core::factors::Factors;
use serde::{Deserialize, Serialize};

use super::{
    DiscoveredTerm, DiscoveryStep, Gain, Reconstruction, ResidualReport, ValidationReport,
};
use sepval_common::extension::TermRecord;
use sepval_fit::results::ChannelRms;
use sepval_run::inputs::InputsRecord;
use sepval_run::model_spec::ModelSpec;
use sepval_solve::identifiability::Identifiability;

/// One parameter's estimate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamValue {
    /// Parameter name.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Estimate.
    pub value: f64,
    /// Standard error (null when the data do not determine it).
    pub std_error: Option<f64>,
}

/// Summary of one model's fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelSummary {
    /// Its effects (empty: the baseline).
    pub effects: Vec<String>,
    /// Its extension terms (`axis: formula`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub terms: Vec<String>,
    /// Free parameters.
    pub parameters: usize,
    /// RMS position error \[m\].
    pub j_pos_m: f64,
    /// RMS attitude error \[deg\].
    pub j_att_deg: f64,
    /// Sum of squared normalised residuals.
    pub chi2: f64,
    /// RMS residual per channel.
    pub channel_rms: ChannelRms,
    /// The 17 factors as fitted with it (absent in files written before they were recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub factors: Option<Factors>,
}

/// One candidate extension, tried against the model of its round.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateReport {
    /// Effect id.
    pub id: String,
    /// What it adds.
    pub adds: String,
    /// Forward-selection round (1: against the baseline).
    pub round: usize,
    /// Its parameters' estimates.
    pub parameters: Vec<ParamValue>,
    /// Chi-square of the extended fit.
    pub chi2: f64,
    /// Chi-square drop from the round's model.
    pub chi2_drop: f64,
    /// F statistic of the extra parameters.
    pub f: f64,
    /// Its p-value.
    pub p_value: f64,
    /// The Bonferroni-corrected threshold of the round.
    pub p_threshold: f64,
    /// BIC change (negative: better even after charging the parameters).
    pub delta_bic: f64,
    /// Whether the extension is significant.
    pub significant: bool,
    /// Goals after the extension: J_pos \[m\], J_att \[deg\].
    pub goals: [f64; 2],
    /// RMS residual per channel after the extension.
    pub channel_rms: ChannelRms,
    /// A remark (for example a weak effect's bound).
    pub note: String,
    /// Why its refinement stopped, and after how many iterations.
    pub refinement: String,
}

/// The discovered extension: the model with the discovered terms, refitted, and its gain.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExtensionReport {
    /// Whether it is the answer (else the catalogue's effects are, and it is an alternative).
    pub answer: bool,
    /// The extension file written (relative to DIR), when it is the answer.
    pub file: Option<String>,
    /// The extended model's fit.
    pub model: ModelSummary,
    /// Its gain over the baseline (chi-square drop, F test, BIC).
    pub gain: Gain,
    /// Whether every channel's residuals are white.
    pub white: bool,
    /// Whether both goals are within 1.1 sigma.
    pub at_noise_floor: bool,
    /// Whether it explains the data to the noise (white and at the floor).
    pub explained: bool,
    /// Why its refinement stopped.
    pub refinement: String,
}

/// A model that explains part of the data but is not the answer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Alternative {
    /// `catalogue` (effects) or `discovered` (terms).
    pub kind: String,
    /// Its effects or terms.
    pub names: Vec<String>,
    /// Its fit.
    pub model: ModelSummary,
    /// Its BIC minus the answer's (positive: worse).
    pub delta_bic_vs_answer: f64,
    /// Why it is not the answer.
    pub note: String,
}

/// A class of library terms that discovery's first screening cannot tell from its best entry
/// (`docs/discovery.md` section 11.6), decided by a refit of one representative.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RivalClass {
    /// In words: "any of 14 rolling-moment terms: roll rate, sideslip, Mach, ...".
    pub words: String,
    /// Its members (`axis formula`), the best by the screening first.
    pub members: Vec<String>,
    /// `answer` (a member is a term of the answer), `better` (a significant representative's
    /// BIC is below the answer's by the margin or more), `rival` (a significant representative
    /// within the margin), `unsettled` (the class of the first screening's best entry whose
    /// every refit stopped at its iteration limit: open), `told apart` (its representatives'
    /// refits are neither) or `not refitted` (beyond the budget of refits, or beside a
    /// representative whose refit explained nothing and speaks for its own kind only: the data
    /// were not asked).
    pub status: String,
    /// Its best representative's BIC less the answer's, when one was refitted.
    pub delta_bic: Option<f64>,
    /// Each member's terms (extension-file records, in `members`' order; the coefficient is
    /// the screening's probe, a scale, not an estimate), so that a later diagnosis given this
    /// one (`--after`) can refit every member. Absent in older files.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub member_terms: Vec<Vec<TermRecord>>,
}

/// An explanation the data cannot tell from the answer: its evidence is within
/// [`RIVAL_MARGIN`](super::RIVAL_MARGIN) of the answer's in BIC.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RivalReport {
    /// `catalogue` (effects only) or `discovered` (terms, with effects when it mixes both).
    pub kind: String,
    /// Its catalogue effects' ids.
    pub effects: Vec<String>,
    /// Its extension terms (axis, family, regressor, the family's locator, coefficient).
    pub terms: Vec<TermRecord>,
    /// Its BIC minus the answer's (negative: it fits better, by less than the margin).
    pub delta_bic: f64,
    /// Sum of squared normalised residuals of its refit.
    pub chi2: f64,
    /// RMS position error \[m\].
    pub j_pos_m: f64,
    /// RMS attitude error \[deg\].
    pub j_att_deg: f64,
    /// Its free parameters.
    pub parameters: usize,
    /// How it came to be tried (which pool, against which part of the answer).
    pub origin: String,
    /// The model, to rebuild its candidate.
    pub model: ModelSpec,
}

/// A refit that did not simulate (its start or a derivative probe): left out, and the
/// diagnosis went on without it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkippedRefit {
    /// Where: `catalogue round 1`, `discovery step 2`, `F-to-remove`, `convergence`.
    pub stage: String,
    /// The model refitted: an effect id, a library entry, `the model without ...`.
    pub model: String,
    /// Why it stopped (`the derivative probe of Cl.cos(2pi13Hzt) did not simulate`).
    pub reason: String,
}

fn yes() -> bool {
    true
}

/// Whether a diagnosis's converged baseline fit reached near the noise: one decision, so that
/// a diagnosis cannot say both (docs/discovery.md section 11.5, step 2).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(from = "BaselineFields", into = "BaselineFields")]
pub enum BaselineVerdict {
    /// It did: the tests of its extensions mean something.
    Converged,
    /// It did not (why: its goals against the limit): the answer is unreliable.
    Unreliable(String),
}

impl BaselineVerdict {
    /// The verdict of a baseline that failed for `why`, or converged (`None`).
    pub fn of(why: Option<String>) -> BaselineVerdict {
        why.map_or(BaselineVerdict::Converged, BaselineVerdict::Unreliable)
    }

    /// Whether the baseline converged near the noise.
    pub fn converged(&self) -> bool {
        matches!(self, BaselineVerdict::Converged)
    }

    /// Why it counts as not converged.
    pub fn why(&self) -> Option<&str> {
        match self {
            BaselineVerdict::Converged => None,
            BaselineVerdict::Unreliable(why) => Some(why),
        }
    }
}

/// The verdict as diagnosis.json records it, in two fields (as before it was one decision).
#[derive(Serialize, Deserialize)]
struct BaselineFields {
    #[serde(default = "yes")]
    baseline_converged: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    baseline_unreliable: Option<String>,
}

impl From<BaselineFields> for BaselineVerdict {
    fn from(f: BaselineFields) -> Self {
        match (f.baseline_converged, f.baseline_unreliable) {
            (true, None) => BaselineVerdict::Converged,
            // A record that says both, or not converged without a reason: unreliable, the
            // cautious reading.
            (_, Some(why)) => BaselineVerdict::Unreliable(why),
            (false, None) => BaselineVerdict::Unreliable(
                "the baseline fit did not reach near the noise (the record gives no reason)".into(),
            ),
        }
    }
}

impl From<BaselineVerdict> for BaselineFields {
    fn from(v: BaselineVerdict) -> Self {
        BaselineFields {
            baseline_converged: v.converged(),
            baseline_unreliable: v.why().map(str::to_string),
        }
    }
}

/// DIR/diagnosis.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Diagnosis {
    /// [`DIAGNOSIS_FORMAT`](super::DIAGNOSIS_FORMAT).
    pub format: String,
    /// The catalogue effects named as causes, in the order chosen (empty when the baseline
    /// explains the data, or when a discovered extension explains it better).
    pub causes: Vec<String>,
    /// Whether the catalogue's answer leaves nothing but noise: the model with the effects it
    /// chose (the baseline when it chose none), even when those effects are not the answer
    /// (`causes` is then empty because a discovered extension explains better). A discovered
    /// extension's own verdict is `extension.explained`; the terminal summary shows the
    /// answer's.
    pub explained: bool,
    /// The verdict in one sentence (ending with the caution when there is one; starting with
    /// the warning when the baseline fit failed).
    pub verdict: String,
    /// Whether the converged baseline reached near the noise (both goals within
    /// [`BASELINE_LIMIT_SIGMA`](super::BASELINE_LIMIT_SIGMA) sigma). When it did not, the
    /// answer below is unreliable (a refit may have found another optimum of the factors, not
    /// a cause) and nothing is `explained`. Recorded as `baseline_converged` and, when not,
    /// `baseline_unreliable` (why).
    #[serde(flatten)]
    pub baseline_verdict: BaselineVerdict,
    /// Why the first baseline fit was replaced: the catalogue's refits showed it in a local
    /// optimum of the factors, and the baseline refined again from theirs fits better
    /// (`docs/discovery.md` section 11.5, step 2a).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub baseline_restart: Option<String>,
    /// Why the answer may not name the cause: an alternative predicts the `--validate` events
    /// clearly better.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub caution: Option<String>,
    /// Terms found beyond the catalogue, most important first, when they are the answer.
    pub discovered: Vec<DiscoveredTerm>,
    /// Whether the data cannot tell the answer from another explanation (`rivals` not empty).
    pub ambiguous: bool,
    /// Explanations the data cannot tell from the answer, best first.
    pub rivals: Vec<RivalReport>,
    /// The classes of library terms the first screening could not tell apart, and what the
    /// refits of their representatives said.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rival_classes: Vec<RivalClass>,
    /// The clearance to the aircraft of the answer's trajectory of each release, when the
    /// diagnosis was given `--aircraft` (docs/envelope.md section 14.2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearance: Option<Vec<sepval_run::clearance::ReleaseClearance>>,
    /// What these releases did to what an earlier diagnosis left open (`--after DIR`): each
    /// earlier explanation refitted on every release, its fate, and the plan's predicted
    /// separations against the diagnosis's (`--plan DIR`). Absent without `--after`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub after: Option<crate::AfterReport>,
    /// Models that explain part of the data but not as well as the answer (mimics).
    pub alternatives: Vec<Alternative>,
    /// The discovered extension and its gain, when discovery verified one.
    pub extension: Option<ExtensionReport>,
    /// What discovery did beyond its findings (why nothing was named, terms dropped).
    pub discovery_notes: Vec<String>,
    /// Each step of discovery's selection: the entries ranked, the refits, what entered.
    pub discovery_steps: Vec<DiscoveryStep>,
    /// Refits that did not simulate and were left out (the diagnosis went on without them).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub skipped: Vec<SkippedRefit>,
    /// The scenario tables the fitted runs left (held at the edge), one line per model, event
    /// and table: the baseline's, and a catalogue answer's.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub tables_left: Vec<String>,
    /// Position noise \[m\].
    pub sigma_pos_m: f64,
    /// Attitude noise \[deg\].
    pub sigma_att_deg: f64,
    /// Where the sigmas came from.
    pub sigma_source: String,
    /// The baseline fit.
    pub baseline: ModelSummary,
    /// The answer's model; the baseline when nothing is named.
    pub extended: ModelSummary,
    /// The answer's model as other commands rebuild it (`sepval plan`, `sepval predict`).
    pub model: ModelSpec,
    /// Where the inputs came from: data, scenario and extension file.
    pub inputs: InputsRecord,
    /// Each named effect's parameters with standard errors.
    pub parameters: BTreeMap<String, Vec<ParamValue>>,
    /// How sure every parameter of the answer's model is (factors, effects' parameters, terms'
    /// coefficients): standard errors and the correlation matrix of its refit, from which
    /// `sepval predict` draws it (covariance std_i std_j rho_ij). Absent in files written before
    /// it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub identifiability: Option<Identifiability>,
    /// Every candidate tried, every round.
    pub candidates: Vec<CandidateReport>,
    /// Residual analysis before and after.
    pub residuals: BTreeMap<String, ResidualReport>,
    /// Per event, the reconstructed coefficient increments with their bands.
    pub reconstruction: Vec<Reconstruction>,
    /// Prediction of the `--validate` events.
    pub validation: Vec<ValidationReport>,
    /// Simulations run (baseline fit included).
    pub evaluations: u64,
    /// Wall time \[s\].
    pub wall_s: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Holder {
        #[serde(flatten)]
        v: BaselineVerdict,
    }

    fn read(text: &str) -> BaselineVerdict {
        serde_json::from_str::<Holder>(text).unwrap().v
    }

    #[test]
    fn the_baseline_verdict_is_one_decision_in_the_records_two_fields() {
        let why = BaselineVerdict::Unreliable("J_pos 18 sigma".into());
        for (v, text) in [
            (BaselineVerdict::Converged, r#"{"baseline_converged":true}"#),
            (
                why.clone(),
                r#"{"baseline_converged":false,"baseline_unreliable":"J_pos 18 sigma"}"#,
            ),
        ] {
            assert_eq!(
                serde_json::to_string(&Holder { v: v.clone() }).unwrap(),
                text
            );
            assert_eq!(read(text), v);
        }
        // Records from before the field: converged. A record that says both is unreliable.
        assert_eq!(read("{}"), BaselineVerdict::Converged);
        let both = r#"{"baseline_converged":true,"baseline_unreliable":"J_pos 18 sigma"}"#;
        assert_eq!(read(both), why);
        assert!(!read(r#"{"baseline_converged":false}"#).converged());
    }
}
