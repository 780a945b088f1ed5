//! Prediction of events that took no part in the fits (`--validate`): the goals of the
//! baseline, the answer and the alternatives on each, and the verdict's caution when an
//! alternative predicts clearly better than the answer (docs/discovery.md section 11.5).

use std::sync::Arc;

use sepval_common::evaluation::{Candidate, Job, JobError, Outcome};
use serde::{Deserialize, Serialize};

use sepval_fit::space::Noise;

/// Prediction of one event that took no part in the fits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ValidationReport {
    /// The event.
    pub event: String,
    /// The baseline's RMS position error on it \[m\].
    pub baseline_j_pos_m: Option<f64>,
    /// The baseline's RMS attitude error \[deg\].
    pub baseline_j_att_deg: Option<f64>,
    /// The answer's RMS position error \[m\].
    pub extended_j_pos_m: Option<f64>,
    /// The answer's RMS attitude error \[deg\].
    pub extended_j_att_deg: Option<f64>,
    /// The alternatives' predictions.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub alternatives: Vec<AlternativePrediction>,
    /// Why a model did not simulate it, if one did not.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub note: String,
}

/// An alternative's prediction of a validation event.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AlternativePrediction {
    /// The alternative (`catalogue: ...` or `discovered: ...`).
    pub model: String,
    /// RMS position error \[m\].
    pub j_pos_m: f64,
    /// RMS attitude error \[deg\].
    pub j_att_deg: f64,
}

/// Goals of the baseline, the answer and the alternatives (named) on each validation event.
pub(super) fn validate(
    v: &Job,
    base: &Candidate,
    answer: &Candidate,
    alternatives: &[(String, Candidate)],
) -> Vec<ValidationReport> {
    v.events()
        .iter()
        .map(|e| {
            let one = Job::new(vec![e.clone()]).map_err(Arc::new);
            let goals = |c: &Candidate| -> Prediction {
                let job = one.as_ref().map_err(|e| NotPredicted::Job(Arc::clone(e)))?;
                let ev = job.evaluate(c);
                match ev.outcome.goals() {
                    Some(g) => Ok((g.j_pos_m, g.j_att_deg)),
                    None => Err(NotPredicted::Outcome(ev.outcome)),
                }
            };
            let (b, a) = (goals(base), goals(answer));
            let others: Vec<(String, Prediction)> = alternatives
                .iter()
                .map(|(n, c)| (n.clone(), goals(c)))
                .collect();
            let mut note: Vec<String> = [("baseline", &b), ("extended model", &a)]
                .iter()
                .filter_map(|(n, r)| r.as_ref().err().map(|e| format!("{n}: {e}")))
                .collect();
            note.extend(
                others
                    .iter()
                    .filter_map(|(n, r)| r.as_ref().err().map(|e| format!("{n}: {e}"))),
            );
            ValidationReport {
                event: e.name.clone(),
                baseline_j_pos_m: b.as_ref().ok().map(|g| g.0),
                baseline_j_att_deg: b.as_ref().ok().map(|g| g.1),
                extended_j_pos_m: a.as_ref().ok().map(|g| g.0),
                extended_j_att_deg: a.as_ref().ok().map(|g| g.1),
                alternatives: others
                    .iter()
                    .filter_map(|(n, r)| {
                        r.as_ref().ok().map(|g| AlternativePrediction {
                            model: n.clone(),
                            j_pos_m: g.0,
                            j_att_deg: g.1,
                        })
                    })
                    .collect(),
                note: note.join("; "),
            }
        })
        .collect()
}

/// A model's goals on a validation event (J_pos \[m\], J_att \[deg\]), or why it did not simulate.
type Prediction = std::result::Result<(f64, f64), NotPredicted>;

/// Why a model did not predict a validation event.
#[derive(Debug, Clone, thiserror::Error)]
enum NotPredicted {
    /// The event does not make a job.
    #[error("{0}")]
    Job(Arc<JobError>),
    /// The run did not reach its goals (diverged, failed).
    #[error("{0:?}")]
    Outcome(Outcome),
}

/// A caveat for the verdict when an alternative predicts the events not fitted clearly better
/// than the answer (its sum over events of `(J_pos/sigma_pos)^2 + (J_att/sigma_att)^2` below
/// 0.8 of the answer's): the answer may fit its own data by mimicry.
pub(super) fn prediction_caveat(validation: &[ValidationReport], noise: Noise) -> Option<String> {
    let score = |p: f64, a: f64| (p / noise.pos_m).powi(2) + (a / noise.att_deg).powi(2);
    let mut answer = 0.0;
    let mut alts: Vec<(String, f64, f64, f64)> = Vec::new();
    for v in validation {
        let (Some(p), Some(a)) = (v.extended_j_pos_m, v.extended_j_att_deg) else {
            return None;
        };
        answer += score(p, a);
        for (i, alt) in v.alternatives.iter().enumerate() {
            if alts.len() <= i {
                alts.push((alt.model.clone(), 0.0, 0.0, 0.0));
            }
            alts[i].1 += score(alt.j_pos_m, alt.j_att_deg);
            alts[i].2 += alt.j_pos_m.powi(2);
            alts[i].3 += alt.j_att_deg.powi(2);
        }
    }
    let n = validation.len() as f64;
    let (model, s, p2, a2) = alts
        .into_iter()
        .filter(|a| a.1.is_finite())
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    if n == 0.0 || s >= 0.8 * answer || !s.is_finite() {
        return None;
    }
    let kind = model.split(':').next().unwrap_or("an");
    Some(format!(
        "on the events not fitted the {kind} alternative predicts better (RMS over events J_pos {:.4} m, J_att {:.3} deg): the answer may fit these data without naming their cause",
        (p2 / n).sqrt(),
        (a2 / n).sqrt()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn event(answer: (f64, f64), alt: (f64, f64)) -> ValidationReport {
        ValidationReport {
            event: "e".into(),
            baseline_j_pos_m: Some(0.1),
            baseline_j_att_deg: Some(1.0),
            extended_j_pos_m: Some(answer.0),
            extended_j_att_deg: Some(answer.1),
            alternatives: vec![AlternativePrediction {
                model: "catalogue: cg_offset".into(),
                j_pos_m: alt.0,
                j_att_deg: alt.1,
            }],
            note: String::new(),
        }
    }

    #[test]
    fn an_alternative_that_predicts_clearly_better_is_a_caveat() {
        let noise = Noise {
            pos_m: 0.001,
            att_deg: 0.1,
        };
        // Answer 0.012 m / 0.75 deg against the alternative's 0.008 m / 0.26 deg: caveat.
        let better = [event((0.012, 0.75), (0.008, 0.26))];
        let note = prediction_caveat(&better, noise).expect("a caveat");
        assert!(
            note.contains("catalogue alternative predicts better"),
            "{note}"
        );
        assert!(note.contains("0.0080 m"), "{note}");
        // Within 20 % of the answer's score: no caveat.
        let close = [event((0.010, 0.5), (0.0095, 0.48))];
        assert_eq!(prediction_caveat(&close, noise), None);
        // The answer predicts better: no caveat.
        let worse = [event((0.008, 0.26), (0.012, 0.75))];
        assert_eq!(prediction_caveat(&worse, noise), None);
    }
}
