//! A fitted model as files hold it, so that another command rebuilds its candidate exactly:
//! the 17 factors, each catalogue effect with its parameter values, and each extension term
//! with its coefficient (the records of `extension.toml`, `docs/discovery.md`).
//!
//! The terms are the model's own, beyond those of the extension file its inputs name
//! (`InputsRecord::extension`): a job rebuilt from the same inputs applies those, and the
//! candidate these. `sepval plan` and `sepval predict` read the models of a diagnosis and of a
//! fit this way.

use serde::{Deserialize, Serialize};

use sepval_common::effects::{EffectError, EffectSet};
use sepval_common::evaluation::Candidate;
use sepval_common::extension::{TermError, TermRecord, TermSet};
use sepval_core::factors::Factors;

/// One catalogue effect with its parameter values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EffectValues {
    /// Its catalogue id.
    pub id: String,
    /// Its parameter values, in the catalogue's order.
    pub values: Vec<f64>,
}

/// A fitted model: enough to rebuild its candidate bit for bit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelSpec {
    /// The 17 factors.
    pub factors: Factors,
    /// Its catalogue effects, in the order they were added.
    pub effects: Vec<EffectValues>,
    /// Its extension terms beyond the inputs' extension file, with their coefficients.
    pub terms: Vec<TermRecord>,
}

/// A model spec that cannot be rebuilt.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModelSpecError {
    /// An effect that is unknown or has the wrong number of values. Its message is the
    /// effect's own, which names the effect (not also a cause in the chain: it was printed
    /// three times).
    #[error("{error}")]
    Effect {
        /// Its id.
        id: String,
        /// Why.
        error: EffectError,
    },
    /// A term record that does not name a term.
    #[error("term {index} ({axis}): field `{field}`: {message}")]
    TermRecord {
        /// Its position (1-based).
        index: usize,
        /// Its axis as written.
        axis: String,
        /// The field at fault.
        field: &'static str,
        /// What is wrong.
        message: String,
    },
    /// Terms that cannot run together.
    #[error("terms: {0}")]
    Terms(TermError),
}

impl ModelSpec {
    /// The spec of `candidate`.
    pub fn of(candidate: &Candidate) -> ModelSpec {
        ModelSpec {
            factors: candidate.factors,
            effects: candidate
                .effects
                .iter()
                .map(|a| EffectValues {
                    id: a.effect().id().to_string(),
                    values: a.values().to_vec(),
                })
                .collect(),
            terms: candidate.terms.iter().map(TermRecord::of).collect(),
        }
    }

    /// Its candidate.
    pub fn candidate(&self) -> Result<Candidate, ModelSpecError> {
        let mut effects = EffectSet::NONE;
        for e in &self.effects {
            effects
                .push_id(&e.id, &e.values)
                .map_err(|error| ModelSpecError::Effect {
                    id: e.id.clone(),
                    error,
                })?;
        }
        let mut terms = TermSet::NONE;
        for (k, r) in self.terms.iter().enumerate() {
            let term = r
                .term()
                .map_err(|(field, message)| ModelSpecError::TermRecord {
                    index: k + 1,
                    axis: r.axis.clone(),
                    field,
                    message,
                })?;
            terms.push(term).map_err(ModelSpecError::Terms)?;
        }
        Ok(Candidate {
            factors: self.factors,
            effects,
            terms,
            corrections: sepval_common::correction::CorrectionValues::NONE,
        })
    }

    /// The catalogue ids of its effects.
    pub fn effect_ids(&self) -> Vec<String> {
        self.effects.iter().map(|e| e.id.clone()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sepval_common::extension::{Axis, Regressor, Term};
    use sepval_core::factors::FACTOR_COUNT;

    #[test]
    fn a_candidate_survives_its_spec_and_json() {
        let mut effects = EffectSet::NONE;
        effects.push_id("roll_due_to_sideslip", &[-0.21]).unwrap();
        let mut terms = TermSet::NONE;
        terms
            .push(Term {
                axis: Axis::Cl,
                regressor: Regressor::P,
                locator: [0.0; 2],
                coefficient: -0.123_456_789,
            })
            .unwrap();
        let c = Candidate {
            effects,
            terms,
            ..Candidate::baseline(Factors([1.0 + 1e-12; FACTOR_COUNT]))
        };
        let text = serde_json::to_string(&ModelSpec::of(&c)).unwrap();
        let back: ModelSpec = serde_json::from_str(&text).unwrap();
        assert_eq!(back.candidate().unwrap(), c);
        assert_eq!(back.effect_ids(), vec!["roll_due_to_sideslip".to_string()]);
    }

    #[test]
    fn a_bad_spec_names_what_is_wrong() {
        let mut spec = ModelSpec::of(&Candidate::baseline(Factors([1.0; FACTOR_COUNT])));
        spec.effects.push(EffectValues {
            id: "no_such_effect".into(),
            values: vec![1.0],
        });
        let e = spec.candidate().unwrap_err().to_string();
        assert!(e.contains("no_such_effect"), "{e}");
        spec.effects.clear();
        let mut record = TermRecord::of(&Term {
            axis: Axis::Cl,
            regressor: Regressor::P,
            locator: [0.0; 2],
            coefficient: 0.1,
        });
        record.axis = "Cq".into();
        spec.terms.push(record);
        let e = spec.candidate().unwrap_err().to_string();
        assert!(e.contains("term 1") && e.contains("axis"), "{e}");
    }
}
