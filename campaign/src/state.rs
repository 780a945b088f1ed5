//! Each condition's state in an envelope of the campaign (docs/campaign.md, "States"): `cleared`
//! when its probability of failing to clear (below the criterion or diverged) is at most the
//! allowed probability; `fails` when its probability of clearing is at most the allowed
//! probability; `undecided` otherwise.

use serde::{Deserialize, Serialize};

use sepval_envelope::Row;

/// A condition's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum State {
    /// The store clears the aircraft there.
    Cleared,
    /// It fails to clear there.
    Fails,
    /// The prediction cannot tell yet.
    Undecided,
}

impl State {
    /// The state of a condition whose probability of failing to clear is `p_fail`, with the
    /// allowed probability `allowed`.
    pub fn of(p_fail: f64, allowed: f64) -> State {
        if p_fail <= allowed {
            State::Cleared
        } else if p_fail >= 1.0 - allowed {
            State::Fails
        } else {
            State::Undecided
        }
    }

    /// Its name in files.
    pub fn name(self) -> &'static str {
        match self {
            State::Cleared => "cleared",
            State::Fails => "fails",
            State::Undecided => "undecided",
        }
    }
}

/// One condition of an envelope of the campaign: the envelope's row and what the planning
/// needs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Assessed {
    /// The row `sepval envelope` writes.
    pub row: Row,
    /// Its state.
    pub state: State,
    /// Its reach: how far it lies from the nearest release flown beyond what the releases
    /// held out in turn cover ([`sepval_predict::reach::uncovered`]; null when nothing was
    /// flown).
    #[serde(with = "sepval_common::nonfinite")]
    pub reach: f64,
    /// The spread of the smallest clearance over the samples \[mm\]: (p95 - p5) / 3.29, the
    /// standard deviation of a normal with those percentiles.
    #[serde(with = "sepval_common::nonfinite")]
    pub spread_mm: f64,
    /// The same spread with the factors' draws alone (no model form).
    #[serde(with = "sepval_common::nonfinite")]
    pub factor_spread_mm: f64,
}

/// The counts of an envelope's states.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counts {
    /// Conditions.
    pub conditions: usize,
    /// Cleared.
    pub cleared: usize,
    /// Failing.
    pub fails: usize,
    /// Undecided.
    pub undecided: usize,
}

impl Counts {
    /// The counts of `assessed`.
    pub fn of(assessed: &[Assessed]) -> Counts {
        let n = |s: State| assessed.iter().filter(|a| a.state == s).count();
        Counts {
            conditions: assessed.len(),
            cleared: n(State::Cleared),
            fails: n(State::Fails),
            undecided: n(State::Undecided),
        }
    }
}

/// The spread of a normal whose 5th and 95th percentiles are `p5` and `p95`.
pub fn spread(p5: f64, p95: f64) -> f64 {
    (p95 - p5) / (2.0 * 1.644_853_626_951_472_2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn states_follow_the_allowed_probability_both_ways() {
        assert_eq!(State::of(0.0, 0.05), State::Cleared);
        assert_eq!(State::of(0.05, 0.05), State::Cleared);
        assert_eq!(State::of(0.5, 0.05), State::Undecided);
        assert_eq!(State::of(0.95, 0.05), State::Fails);
        assert_eq!(State::of(1.0, 0.05), State::Fails);
    }
}
