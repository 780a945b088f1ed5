//! `sepval rerun`: re-evaluates a saved generation and checks that every goal matches, bit for
//! bit.

use std::path::Path;

use sepval_common::evaluation::{Candidate, EvalError, Evaluator, Outcome};

use crate::checkpoint::{Checkpoint, CheckpointError};
use crate::problem::factors_of;

/// A member whose re-evaluation differs from the checkpoint.
#[derive(Debug, Clone, PartialEq)]
pub struct Mismatch {
    /// Index in the population.
    pub member: usize,
    /// The saved outcome.
    pub saved: Outcome,
    /// The new outcome.
    pub rerun: Outcome,
}

/// Errors of a rerun.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RerunError {
    /// The checkpoint does not fit the job.
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    /// The evaluator failed.
    #[error(transparent)]
    Eval(#[from] EvalError),
}

/// Re-evaluates the checkpoint's population with `evaluator` (whose job must be the
/// checkpoint's: checked) and returns the members that do not match bit for bit.
pub fn rerun(
    checkpoint: &Checkpoint,
    path: &Path,
    evaluator: &mut dyn Evaluator,
) -> Result<Vec<Mismatch>, RerunError> {
    checkpoint.check_job(evaluator.job(), path)?;
    let batch: Vec<Candidate> = checkpoint
        .state
        .population
        .iter()
        .map(|m| Candidate::baseline(factors_of(&m.values)))
        .collect();
    let evaluated = evaluator.evaluate(&batch, false)?;
    Ok(checkpoint
        .state
        .population
        .iter()
        .zip(evaluated)
        .enumerate()
        .filter(|(_, (m, e))| !same_bits(&m.outcome, &e.outcome))
        .map(|(member, (m, e))| Mismatch {
            member,
            saved: m.outcome.clone(),
            rerun: e.outcome,
        })
        .collect())
}

/// Whether two outcomes are identical to the last bit.
pub fn same_bits(a: &Outcome, b: &Outcome) -> bool {
    match (a, b) {
        (
            Outcome::Goals {
                j_pos_m: p1,
                j_att_deg: a1,
            },
            Outcome::Goals {
                j_pos_m: p2,
                j_att_deg: a2,
            },
        ) => p1.to_bits() == p2.to_bits() && a1.to_bits() == a2.to_bits(),
        (Outcome::Diverged { t_s: t1, event: e1 }, Outcome::Diverged { t_s: t2, event: e2 }) => {
            t1.to_bits() == t2.to_bits() && e1 == e2
        }
        (Outcome::Failed { reason: r1 }, Outcome::Failed { reason: r2 }) => r1 == r2,
        _ => false,
    }
}
