//! The fit as a search problem: decoded factor values become candidates of a model variant,
//! evaluated through whatever [`Evaluator`] the user chose.

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::{Candidate, EvalError, Evaluator, Outcome};
use sepval_common::factors::{FACTOR_COUNT, FactorSpec, Factors};

use crate::search::ga::ParetoProblem;

/// The 17 factors of the model variant `effects` (whose values stay fixed) against the job's
/// data, through `evaluator`.
pub struct FactorProblem<'a> {
    evaluator: &'a mut dyn Evaluator,
    genes: Vec<FactorSpec>,
    effects: EffectSet,
    /// Simulations requested so far.
    pub evaluations: u64,
}

impl<'a> FactorProblem<'a> {
    /// The baseline-model problem of `evaluator`'s job.
    pub fn new(evaluator: &'a mut dyn Evaluator) -> Self {
        let genes = evaluator.job().factor_table().0.to_vec();
        FactorProblem {
            evaluator,
            genes,
            effects: EffectSet::NONE,
            evaluations: 0,
        }
    }

    /// The evaluator.
    pub fn evaluator(&mut self) -> &mut dyn Evaluator {
        self.evaluator
    }
}

/// Factors from a slice of 17 values.
pub fn factors_of(values: &[f64]) -> Factors {
    let mut f = [0.0; FACTOR_COUNT];
    f.copy_from_slice(&values[..FACTOR_COUNT]);
    Factors(f)
}

impl ParetoProblem for FactorProblem<'_> {
    fn genes(&self) -> &[FactorSpec] {
        &self.genes
    }

    fn evaluate(&mut self, batch: &[Vec<f64>]) -> Result<Vec<Outcome>, EvalError> {
        let candidates: Vec<Candidate> = batch
            .iter()
            .map(|v| Candidate {
                factors: factors_of(v),
                effects: self.effects,
            })
            .collect();
        self.evaluations += candidates.len() as u64;
        Ok(self
            .evaluator
            .evaluate(&candidates, false)?
            .into_iter()
            .map(|e| e.outcome)
            .collect())
    }
}
