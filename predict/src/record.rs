//! DIR/prediction.json as files hold it (format [`PREDICTION_FORMAT`]) and DIR/bands.csv,
//! documented field by field in docs/prediction.md section 13.7, and their making from a
//! prediction.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::bands::{ChannelBand, Shares};
use crate::check::{CHANNEL_NAMES, CHANNEL_WORDS, Check};
use crate::clearance::ClearanceStats;
use crate::discrepancy::HeldOutRecord;
use crate::{Prediction, Prepared};

/// The format of DIR/prediction.json.
pub const PREDICTION_FORMAT: &str = "sepval-prediction/1";

/// The flight condition predicted (prediction.json, and each row of an envelope).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ConditionRecord {
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
}

impl ConditionRecord {
    /// The record of `f`.
    pub fn of(f: &sepval_common::scenario::Flight) -> ConditionRecord {
        ConditionRecord {
            mach: f.mach,
            altitude_m: f.altitude_m,
            alpha_deg: f.alpha_deg,
            beta_deg: f.beta_deg,
            gamma_deg: f.gamma_deg,
        }
    }

    /// The flight condition it records.
    pub fn flight(&self) -> sepval_common::scenario::Flight {
        sepval_common::scenario::Flight {
            mach: self.mach,
            altitude_m: self.altitude_m,
            alpha_deg: self.alpha_deg,
            beta_deg: self.beta_deg,
            gamma_deg: self.gamma_deg,
        }
    }
}

/// One source's share of the band.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SourceShare {
    /// Its share of the variance, the mean over the channels.
    pub share: f64,
    /// Its share per channel (x, y, z, roll, pitch, yaw).
    pub channels: [f64; 6],
}

/// The model form's share, with its two parts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FormShare {
    /// Its share (rivals plus discrepancy), the mean over the channels.
    pub share: f64,
    /// Per channel.
    pub channels: [f64; 6],
    /// The rivals' part.
    pub rivals: f64,
    /// The discrepancy's part.
    pub discrepancy: f64,
    /// How the discrepancy was calibrated, in words.
    pub calibration: String,
    /// The releases held out.
    pub held_out: Vec<HeldOutRecord>,
}

/// The sources of the band.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SourcesRecord {
    /// The factors.
    pub factors: SourceShare,
    /// The model's form.
    pub model_form: FormShare,
    /// The measurement (0 unless included).
    pub measurement: SourceShare,
    /// Whether the measurement noise is in the bands.
    pub measurement_included: bool,
    /// The source with the largest share.
    pub dominant: String,
    /// Why, in words.
    pub why: String,
}

/// One model drawn from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelRecord {
    /// Its name.
    pub name: String,
    /// Whether it is the answer.
    pub answer: bool,
    /// Its BIC minus the answer's.
    pub delta_bic: f64,
    /// Its weight.
    pub weight: f64,
    /// Samples drawn of it.
    pub samples: usize,
}

/// DIR/prediction.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PredictionFile {
    /// [`PREDICTION_FORMAT`].
    pub format: String,
    /// The bands' level.
    pub level: f64,
    /// Samples drawn.
    pub samples: usize,
    /// Samples that ran (the others diverged or failed).
    pub samples_used: usize,
    /// The seed.
    pub seed: u64,
    /// The condition.
    pub condition: ConditionRecord,
    /// When the condition lies far from every release fitted, the sentence that says so
    /// (docs/model.md section 1, "The model's domain"); the summary's first sentence.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extrapolation: Option<String>,
    /// Times of the band points \[s\].
    pub t_s: Vec<f64>,
    /// Downrange \[m\].
    pub x_m: ChannelBand,
    /// Crossrange \[m\].
    pub y_m: ChannelBand,
    /// Down \[m\].
    pub z_m: ChannelBand,
    /// Roll \[deg\].
    pub roll_deg: ChannelBand,
    /// Pitch \[deg\].
    pub pitch_deg: ChannelBand,
    /// Yaw \[deg\].
    pub yaw_deg: ChannelBand,
    /// Each source's share of the width.
    pub sources: SourcesRecord,
    /// The models drawn from.
    pub models: Vec<ModelRecord>,
    /// The post-flight check, when a flown release was given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub check: Option<Check>,
    /// The clearance to the aircraft, when a geometry was given (docs/envelope.md section 14.3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearance: Option<ClearanceStats>,
    /// `fit` or `diagnosis`.
    pub from_kind: String,
    /// The source directory.
    pub from: String,
    /// Position noise \[m\].
    pub sigma_pos_m: f64,
    /// Attitude noise \[deg\].
    pub sigma_att_deg: f64,
    /// Simulations run.
    pub evaluations: u64,
    /// Wall time \[s\].
    pub wall_s: f64,
}

impl PredictionFile {
    /// The six channels' bands in order.
    pub fn channels(&self) -> [&ChannelBand; 6] {
        [
            &self.x_m,
            &self.y_m,
            &self.z_m,
            &self.roll_deg,
            &self.pitch_deg,
            &self.yaw_deg,
        ]
    }
}

fn source_share(v: [f64; 6]) -> SourceShare {
    SourceShare {
        share: Shares::overall(&v),
        channels: v,
    }
}

/// The calibration in words.
fn calibration_words(p: &Prediction) -> String {
    let held = p.discrepancy.held_out.iter().filter(|h| h.note.is_empty());
    let left = held.clone().filter(|h| h.how == "left out").count();
    let validate = held.filter(|h| h.how == "validate").count();
    if left + validate == 0 {
        return "no release was held out: the discrepancy is the answer's misfit on the releases fitted beyond the noise, which understates the error at another condition".into();
    }
    format!(
        "calibrated on {} release(s) held out ({left} left out of a refit in turn, {validate} given to validate): their errors beyond the factor bands and the noise",
        left + validate
    )
}

/// The dominant source and why.
fn dominant(s: &Shares, p: &Prediction) -> (String, String) {
    let form = Shares::overall(&s.rivals) + Shares::overall(&s.discrepancy);
    let all = [
        ("factors", Shares::overall(&s.factors)),
        ("model_form", form),
        ("measurement", Shares::overall(&s.measurement)),
    ];
    let (name, share) = all
        .iter()
        .copied()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or(("factors", 0.0));
    let pct = 100.0 * share;
    let why = match name {
        "model_form" if Shares::overall(&s.rivals) > Shares::overall(&s.discrepancy) => format!(
            "the model's form ({pct:.0} % of the variance): the rivals of the answer, which the releases fitted cannot tell from it, predict different trajectories here"
        ),
        "model_form" => format!(
            "the model's form ({pct:.0} % of the variance): {}",
            if p.discrepancy.held_out.iter().any(|h| h.note.is_empty()) {
                "the releases held out were predicted with errors beyond what their refits' factor bands and the noise allow, so the model lacks something the factors cannot absorb"
            } else {
                "the answer does not fit the releases fitted to the noise"
            }
        ),
        "measurement" => format!(
            "the measurement ({pct:.0} % of the variance): the model and its factors are known better than the telemetry's noise"
        ),
        _ => format!(
            "the factors ({pct:.0} % of the variance): {}",
            if p.discrepancy.held_out.iter().any(|h| h.note.is_empty()) {
                "the releases held out were predicted within what their refits' own factor bands and the noise allow, so nothing shows the fitted model's form to be wrong and what is left is how well the releases fitted pin its factors"
            } else {
                "the answer fits the releases fitted to the noise and no release was held out, so nothing shows the model's form to be wrong"
            }
        ),
    };
    (name.to_string(), why)
}

/// The record of a prediction.
pub fn prediction_file(
    prepared: &Prepared,
    p: &Prediction,
    from: &Path,
    wall_s: f64,
) -> PredictionFile {
    let s = &p.bands.shares;
    let f = &prepared.condition.flight;
    let [x_m, y_m, z_m, roll_deg, pitch_deg, yaw_deg] = p.bands.channels.clone();
    let (dominant, why) = dominant(s, p);
    let form: [f64; 6] = std::array::from_fn(|c| s.rivals[c] + s.discrepancy[c]);
    PredictionFile {
        format: PREDICTION_FORMAT.into(),
        level: prepared.settings.level,
        samples: prepared.settings.samples,
        samples_used: p.bands.used,
        seed: prepared.settings.seed,
        condition: ConditionRecord::of(f),
        extrapolation: prepared.extrapolation.clone(),
        t_s: prepared.grid.t_s.clone(),
        x_m,
        y_m,
        z_m,
        roll_deg,
        pitch_deg,
        yaw_deg,
        sources: SourcesRecord {
            factors: source_share(s.factors),
            model_form: FormShare {
                share: Shares::overall(&form),
                channels: form,
                rivals: Shares::overall(&s.rivals),
                discrepancy: Shares::overall(&s.discrepancy),
                calibration: calibration_words(p),
                held_out: p.discrepancy.held_out.clone(),
            },
            measurement: source_share(s.measurement),
            measurement_included: prepared.settings.with_noise || p.check.is_some(),
            dominant,
            why,
        },
        models: prepared
            .ensemble
            .members
            .iter()
            .enumerate()
            .map(|(i, m)| ModelRecord {
                name: m.name.clone(),
                answer: m.answer,
                delta_bic: m.delta_bic,
                weight: m.weight,
                samples: p.models.iter().filter(|&&k| k == i).count(),
            })
            .collect(),
        check: p.check.clone(),
        clearance: p.clearance.clone(),
        from_kind: prepared.source.kind.name().into(),
        from: from.display().to_string(),
        sigma_pos_m: prepared.source.noise.pos_m,
        sigma_att_deg: prepared.source.noise.att_deg,
        evaluations: p.evaluations,
        wall_s,
    }
}

/// DIR/bands.csv: `t_s`, then `lo`, `mid`, `hi` of each channel.
pub fn bands_csv(file: &PredictionFile) -> String {
    let mut s = format!(
        "# sepval predict: {:.0} % bands at Mach {}, altitude {} m, alpha {} deg, beta {} deg, gamma {} deg; {} samples\n",
        100.0 * file.level,
        file.condition.mach,
        file.condition.altitude_m,
        file.condition.alpha_deg,
        file.condition.beta_deg,
        file.condition.gamma_deg,
        file.samples_used
    );
    s.push_str("t_s");
    for name in CHANNEL_NAMES {
        s.push_str(&format!(",{name}_lo,{name}_mid,{name}_hi"));
    }
    s.push('\n');
    let channels = file.channels();
    for (k, t) in file.t_s.iter().enumerate() {
        s.push_str(&format!("{t}"));
        for b in channels {
            s.push_str(&format!(",{},{},{}", b.lo[k], b.mid[k], b.hi[k]));
        }
        s.push('\n');
    }
    s
}

/// A channel's name in words (`pitch`).
pub fn channel_words(c: usize) -> &'static str {
    CHANNEL_WORDS[c]
}
