//! What one evaluation of a candidate gives, whatever the problem and the evaluator: its
//! [`Outcome`] (the two goals of docs/model.md section 5, a divergence, or a failure, never a
//! magic penalty hidden in a number) and the [`EvalError`]s of an evaluator (the transport
//! or a signal, not the simulation).

use serde::{Deserialize, Serialize};

/// The goals of one evaluation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Goals {
    /// RMS position error \[m\].
    pub j_pos_m: f64,
    /// RMS attitude error \[deg\].
    pub j_att_deg: f64,
}

impl Goals {
    /// The goals as an array (position first).
    pub fn as_array(&self) -> [f64; 2] {
        [self.j_pos_m, self.j_att_deg]
    }

    /// The weighted sum J_pos / sigma_pos + J_att / sigma_att.
    pub fn weighted_sum(&self, sigma_pos_m: f64, sigma_att_deg: f64) -> f64 {
        self.j_pos_m / sigma_pos_m + self.j_att_deg / sigma_att_deg
    }
}

/// The typed outcome of one evaluation: never a magic penalty hidden in a number.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum Outcome {
    /// The run finished: its goals (docs/model.md section 5), pooled over all events.
    Goals {
        /// RMS position error \[m\].
        j_pos_m: f64,
        /// RMS attitude error \[deg\].
        j_att_deg: f64,
    },
    /// The run diverged (docs/model.md section 3) in event `event` at `t_s`.
    Diverged {
        /// Time of divergence \[s\].
        t_s: f64,
        /// Index of the event that diverged.
        event: usize,
    },
    /// The candidate could not be run (invalid parameters, a malformed request).
    Failed {
        /// Why.
        reason: String,
    },
}

/// Longest failure reason an [`Outcome::Failed`] carries \[bytes of UTF-8\]. Reasons are cut
/// (at a character boundary) where the outcome is made, so that every evaluator, in this process
/// or across any transport, gives the same outcome to the last byte.
pub const MAX_REASON_BYTES: usize = 240;

impl Outcome {
    /// Whether two outcomes are identical to the last bit (what a replay must reproduce).
    pub fn same_bits(&self, other: &Outcome) -> bool {
        match (self, other) {
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
            (
                Outcome::Diverged { t_s: t1, event: e1 },
                Outcome::Diverged { t_s: t2, event: e2 },
            ) => t1.to_bits() == t2.to_bits() && e1 == e2,
            (Outcome::Failed { reason: r1 }, Outcome::Failed { reason: r2 }) => r1 == r2,
            _ => false,
        }
    }

    /// A failed outcome whose reason is cut to [`MAX_REASON_BYTES`] at a character boundary.
    pub fn failed(reason: impl Into<String>) -> Outcome {
        let mut reason = reason.into();
        if reason.len() > MAX_REASON_BYTES {
            let mut end = MAX_REASON_BYTES;
            while !reason.is_char_boundary(end) {
                end -= 1;
            }
            reason.truncate(end);
        }
        Outcome::Failed { reason }
    }

    /// The goals, if the run finished.
    pub fn goals(&self) -> Option<Goals> {
        match *self {
            Outcome::Goals { j_pos_m, j_att_deg } => Some(Goals { j_pos_m, j_att_deg }),
            _ => None,
        }
    }

    /// The two objectives for a Pareto search: the goals, or (inf, inf) for a run that did not
    /// finish, which every finished run dominates.
    pub fn objectives(&self) -> [f64; 2] {
        self.goals()
            .map_or([f64::INFINITY; 2], |g| [g.j_pos_m, g.j_att_deg])
    }
}

/// Errors of an evaluator (the transport, not the simulations: those are [`Outcome`]s).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EvalError {
    /// The evaluator cannot go on (for example every worker is gone).
    #[error("evaluator failed")]
    Transport(#[source] Box<dyn std::error::Error + Send + Sync>),
    /// A signal (SIGINT, SIGTERM) asked the process to stop.
    #[error("interrupted by a signal")]
    Interrupted,
}

impl EvalError {
    /// A transport failure with its cause.
    pub fn transport(e: impl Into<Box<dyn std::error::Error + Send + Sync>>) -> Self {
        EvalError::Transport(e.into())
    }
}
