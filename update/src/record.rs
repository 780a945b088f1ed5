//! DIR/update.json (`sepval-update/1`): everything an update decided and measured, for
//! programs; docs/update.md section 15.8 lists its fields.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::explored::Explored;
use crate::screen::AxisScreen;

/// Format tag of update files.
pub const UPDATE_FORMAT: &str = "sepval-update/1";

/// Goals \[m\], \[deg\] (`null` where the model did not simulate).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GoalsRecord {
    /// RMS position error \[m\].
    pub j_pos_m: Option<f64>,
    /// RMS attitude error \[deg\].
    pub j_att_deg: Option<f64>,
}

impl GoalsRecord {
    /// The record of goals (non-finite ones as `null`).
    pub fn of(g: sepval_common::goals::Goals) -> GoalsRecord {
        let f = |v: f64| v.is_finite().then_some(v);
        GoalsRecord {
            j_pos_m: f(g.j_pos_m),
            j_att_deg: f(g.j_att_deg),
        }
    }
}

/// A release and its flight condition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReleaseRecord {
    /// The data file.
    pub name: String,
    /// Flight Mach.
    pub mach: f64,
    /// Altitude \[m\].
    pub altitude_m: f64,
    /// Aircraft angle of attack \[deg\].
    pub alpha_deg: f64,
    /// Aircraft sideslip \[deg\].
    pub beta_deg: f64,
    /// Samples.
    pub samples: usize,
}

/// A correction kept, with its values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CorrectionOut {
    /// Its name, e.g. `Cm over alpha`.
    pub name: String,
    /// The field it corrects.
    pub field: String,
    /// Its variable (`distance_m`, `alpha_deg`, `beta_deg`, `mach`).
    pub variable: String,
    /// Breakpoints, in the variable's unit.
    pub breakpoints: Vec<f64>,
    /// The value at each (a coefficient; a derivative per rad).
    pub values: Vec<f64>,
    /// Its standard deviation (0 where held).
    pub std: Vec<f64>,
    /// Which values were held at 0 (an interference correction at `s_end_m`).
    pub held: Vec<bool>,
    /// The range of the variable the releases explored: outside it the correction is not
    /// measured (held at its edge value, or falling to 0 at `s_end_m` for the interference).
    pub explored: (f64, f64),
    /// Its smoothness: the penalty weight chosen by cross-validation.
    pub lambda: f64,
}

/// One round of the selection: the correction the screening took, and whether the refits kept
/// it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RoundRecord {
    /// 1, 2, ...
    pub round: usize,
    /// The correction the round chose among those it refitted (`null` when the screening
    /// passed none, which ends the selection).
    pub correction: Option<String>,
    /// The drop of the linearised cross-validated chi-square the screening's best made.
    pub linear_gain: Option<f64>,
    /// The cross-validated chi-square of the model before it (output error, the folds' sum).
    pub cv_chi2_before: f64,
    /// With it.
    pub cv_chi2_with: Option<f64>,
    /// Whether it was kept (it lowered the cross-validated chi-square by more than the margin).
    pub kept: bool,
    /// The best proposals of the round's screening: (correction, linearised gain).
    pub best: Vec<(String, f64)>,
    /// The other corrections refitted in the round: (correction, cross-validated chi-square).
    pub tried: Vec<(String, f64)>,
    /// Those of them the releases cannot tell from the one chosen (within 6 of its
    /// cross-validated chi-square, and kept-worthy themselves).
    pub cannot_tell: Vec<String>,
}

impl RoundRecord {
    /// The record of round `round` (from 0) with its `screening`, from a model whose
    /// cross-validated chi-square is `cv`.
    pub fn of(round: usize, screening: &crate::screen::Screening, cv: f64) -> RoundRecord {
        let mut best: Vec<(String, f64)> = screening
            .axes
            .iter()
            .flat_map(|a| a.scored.iter().map(|s| (s.correction.clone(), s.gain)))
            .collect();
        best.sort_by(|a, b| b.1.total_cmp(&a.1));
        best.truncate(5);
        RoundRecord {
            round: round + 1,
            correction: None,
            linear_gain: screening.picks.first().map(|p| p.gain),
            cv_chi2_before: cv,
            cv_chi2_with: None,
            kept: false,
            best,
            tried: Vec::new(),
            cannot_tell: Vec::new(),
        }
    }
}

/// A smoothness tried.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LambdaRecord {
    /// The penalty weight lambda.
    pub lambda: f64,
    /// Its cross-validated chi-square.
    pub cv_chi2: f64,
}

/// What one fold predicted for what it left out.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FoldRecord {
    /// What was left out.
    pub held_out: String,
    /// The scenario as given, nominal factors.
    pub baseline: GoalsRecord,
    /// The factors fitted without it.
    pub factors_only: GoalsRecord,
    /// The updated store fitted without it.
    pub updated: GoalsRecord,
}

/// The cross-validation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CrossValidationRecord {
    /// How the folds were made.
    pub method: String,
    /// The cross-validated chi-square of the updated store.
    pub cv_chi2_updated: f64,
    /// Of the factors alone.
    pub cv_chi2_factors_only: f64,
    /// Per fold.
    pub folds: Vec<FoldRecord>,
}

/// The fit to every release.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FittedRecord {
    /// The 17 factors fitted with the corrections (DIR/factors.json).
    pub factors: BTreeMap<String, f64>,
    /// The factors left free.
    pub free: Vec<String>,
    /// The goals of the updated store.
    pub goals: GoalsRecord,
    /// The goals of the factors alone (the scenario as given).
    pub factors_only_goals: GoalsRecord,
    /// The goals of the baseline fit.
    pub baseline_goals: GoalsRecord,
}

/// A release given with `--validate`, predicted by each model fitted to every release.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ValidationRecord {
    /// The release.
    pub release: String,
    /// The scenario as given, nominal factors.
    pub baseline: GoalsRecord,
    /// The factors fitted to every release.
    pub factors_only: GoalsRecord,
    /// The updated store.
    pub updated: GoalsRecord,
}

/// The first round's screening (about the factors alone).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScreeningRecord {
    /// How the linearised cross-validation's rows were split.
    pub folds: String,
    /// Per axis.
    pub axes: Vec<AxisScreen>,
}

/// DIR/update.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UpdateFile {
    /// [`UPDATE_FORMAT`].
    pub format: String,
    /// The answer in one sentence.
    pub verdict: String,
    /// The releases fitted.
    pub releases: Vec<ReleaseRecord>,
    /// The noise the residuals are measured in \[m\], \[deg\].
    pub sigma_pos_m: f64,
    /// See `sigma_pos_m`.
    pub sigma_att_deg: f64,
    /// What the releases explored.
    pub explored: Explored,
    /// The first round's screening of every correction (estimation before modelling).
    pub screening: ScreeningRecord,
    /// The corrections kept.
    pub corrections: Vec<CorrectionOut>,
    /// The rounds of the selection.
    pub rounds: Vec<RoundRecord>,
    /// The smoothness tried on the corrections kept, and its cross-validated chi-square.
    pub smoothness: Vec<LambdaRecord>,
    /// The effective number of parameters of the final fit (factors included).
    pub effective_parameters: f64,
    /// The residuals' variance in units of the noise (at least 1) that widens the bands.
    pub residual_scale: f64,
    /// The cross-validation.
    pub cross_validation: CrossValidationRecord,
    /// The fit to every release.
    pub fitted: FittedRecord,
    /// The `--validate` releases.
    pub validation: Vec<ValidationRecord>,
    /// What the data cannot tell apart, in words.
    pub cannot_tell: Vec<String>,
    /// Notes.
    pub notes: Vec<String>,
    /// The files of the updated store, relative to the output directory.
    pub files: Vec<String>,
    /// Simulations run.
    pub evaluations: u64,
    /// Wall time \[s\].
    pub wall_s: f64,
}
