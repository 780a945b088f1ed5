//! The best goals a search has found so far, as its history records them after each generation
//! (the genetic algorithm, [`crate::ga::GenerationStats`]) or step (a fit's history, in
//! `sepval-fit`): one type, embedded with `#[serde(flatten)]`, so that both write the same
//! keys in the same order as when each spelled the fields out.

use serde::{Deserialize, Serialize};

/// The best goals so far and the simulations it took. The goals are infinite when no member
/// finished; in JSON they are then the string `"inf"` ([`sepval_core::nonfinite`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BestSoFar {
    /// Simulations run so far.
    pub evaluations: u64,
    /// Smallest first objective, J_pos \[m\].
    #[serde(with = "sepval_core::nonfinite")]
    pub best_j_pos_m: f64,
    /// Smallest second objective, J_att \[deg\].
    #[serde(with = "sepval_core::nonfinite")]
    pub best_j_att_deg: f64,
    /// Smallest weighted sum w0 J_pos + w1 J_att.
    #[serde(with = "sepval_core::nonfinite")]
    pub best_weighted: f64,
}

impl BestSoFar {
    /// The two goals (J_pos \[m\], J_att \[deg\]).
    pub fn goals(&self) -> [f64; 2] {
        [self.best_j_pos_m, self.best_j_att_deg]
    }
}
