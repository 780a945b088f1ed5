//! Each condition's state in an envelope of the campaign (docs/campaign.md, "States"): `cleared`
//! when its probability of failing to clear (below the criterion or diverged) is at most the
//! allowed probability; `fails` when its probability of clearing is at most the allowed
//! probability; `undecided` otherwise. A model that has met no release clears nothing: before
//! the first release what the prior would clear stays undecided ([`State::before_release`]).

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

    /// The state of a condition predicted by a model that has met no release (round 0, the
    /// prior): [`State::of`], but never cleared. The prior's model-form band (the reach rule at
    /// [`sepval_predict::reach::UNFLOWN_REACH`]) grows with the model's own motion and cannot
    /// see a cause that makes motion the model lacks: measured on 2026-11-27, a hidden cubic
    /// pitch stiffness brought the store back to the pylon late in the release where no sample
    /// of the prior went, and the prior cleared 1 (3 x 3 grid) or 2 (5 x 5) conditions the truth
    /// fails; twice the reach did not mend it. A clearance by prediction needs a prediction
    /// that a release has checked; a prior's failure needs none (it keeps the store away).
    pub fn before_release(p_fail: f64, allowed: f64) -> State {
        match State::of(p_fail, allowed) {
            State::Cleared => State::Undecided,
            s => s,
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
    #[serde(with = "sepval_core::nonfinite")]
    pub reach: f64,
    /// The spread of the smallest clearance over the samples \[mm\]: (p95 - p5) / 3.29, the
    /// standard deviation of a normal with those percentiles.
    #[serde(with = "sepval_core::nonfinite")]
    pub spread_mm: f64,
    /// The same spread with the factors' draws alone (no model form).
    #[serde(with = "sepval_core::nonfinite")]
    pub factor_spread_mm: f64,
    /// The part of the factors' spread that is the rivals' disagreement: the spread of their
    /// median smallest clearances \[mm\] ([`crate::rivals::clearance_spread`]; 0 with no rival).
    #[serde(default)]
    pub rival_spread_mm: f64,
    /// How well a release here tells the rivals apart ([`crate::rivals::separation`]; 0 with no
    /// rival).
    #[serde(default)]
    pub rival_separation: f64,
    /// Per sample, what the planning reads a release's lesson from ([`crate::joint`]): its
    /// smallest clearance on the factors' draws and its trajectory's features (null: it did
    /// not run). Empty in assessments written before 2026-12-02 (the planning then uses the
    /// rules of [`crate::next`] without it).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joint: Vec<Option<crate::joint::Sample>>,
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

    /// How many conditions are in state `s`.
    pub fn of_state(&self, s: State) -> usize {
        match s {
            State::Cleared => self.cleared,
            State::Fails => self.fails,
            State::Undecided => self.undecided,
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

    #[test]
    fn before_a_release_nothing_is_cleared_and_failures_stand() {
        assert_eq!(State::before_release(0.0, 0.05), State::Undecided);
        assert_eq!(State::before_release(0.5, 0.05), State::Undecided);
        assert_eq!(State::before_release(0.99, 0.05), State::Fails);
    }
}
