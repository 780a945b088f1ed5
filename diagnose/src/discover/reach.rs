//! When discovery stops early: its model can no longer reach the catalogue's answer
//! (`docs/discovery.md` section 11.5, "Out of reach").
//!
//! Discovery's extension matters to the answer in two ways only: it replaces the catalogue's
//! answer when its BIC is lower by more than [`BIC_MARGIN`](crate::BIC_MARGIN), and it is a rival of that answer
//! when their BICs lie within [`RIVAL_MARGIN`] (R. E. Kass and A. E. Raftery, JASA 90, 1995).
//! When the catalogue's answer already explains the data to the noise, discovery goes on after
//! a step only while it could still do either. Forward selection enters the largest gain
//! available first, so a step seldom gains more than the step before it: each step still to
//! come is counted at twice the last step's BIC gain, and never above the largest gain of a
//! step so far ([`step_bound`]). Discovery stops when even that many such gains would leave its
//! model above the answer's BIC plus the rival margin. The first step always runs: it holds the
//! search for the answer's mimics among the library's terms (`mimic`).
//!
//! The bound is an assumption, not a theorem: terms that gain little alone and much together
//! would be missed. What such a stop risks is bounded too: the answer it leaves in place
//! already explains the data to the noise.

use crate::RIVAL_MARGIN;

/// The catalogue's answer, as discovery measures itself against it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Yardstick {
    /// The answer's BIC.
    pub bic: f64,
}

/// Where discovery stands after a step.
#[derive(Clone, Copy, Debug)]
pub(super) struct Standing {
    /// The step just taken (1: the first).
    pub step: usize,
    /// The discovered model's BIC now.
    pub bic: f64,
    /// The largest BIC gain of one step so far (the baseline to step 1, step 1 to 2, ...).
    pub best_gain: f64,
    /// The BIC gain of the step just taken.
    pub last_gain: f64,
    /// Steps the selection may still take.
    pub steps_left: usize,
}

/// The note that stops discovery when, from `standing`, it can neither replace the answer
/// measured by `yardstick` nor come within the rival margin of it; `None` to go on.
pub(super) fn out_of_reach(yardstick: Option<Yardstick>, standing: Standing) -> Option<String> {
    let yard = yardstick?;
    let per_step = step_bound(standing);
    let lowest = standing.bic - standing.steps_left as f64 * per_step;
    // Replacing the answer needs a BIC below its own minus BIC_MARGIN, rivalling it one below
    // its own plus RIVAL_MARGIN: the second bar is the higher.
    let bar = yard.bic + RIVAL_MARGIN;
    (standing.steps_left > 0 && lowest > bar).then(|| {
        let left = match standing.steps_left {
            1 => "the one step left".to_string(),
            n => format!("each of the {n} steps left"),
        };
        format!(
            "discovery stopped after step {}: the catalogue's answer explains the data to the noise (BIC {:.1}), and the discovered model (BIC {:.1}) would stay above {bar:.1} even if {left} gained {per_step:.1} (twice its last step's gain, at most its best step's), so it could neither replace that answer nor rival it (docs/model.md 11.5)",
            standing.step, yard.bic, standing.bic,
        )
    })
}

/// The most BIC a step still to come is counted to gain: twice the last step's gain, at most
/// the largest gain of a step so far.
fn step_bound(standing: Standing) -> f64 {
    (2.0 * standing.last_gain).min(standing.best_gain).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(bic: f64, best_gain: f64, last_gain: f64, steps_left: usize) -> Standing {
        Standing {
            step: 1,
            bic,
            best_gain,
            last_gain,
            steps_left,
        }
    }

    #[test]
    fn far_behind_stops_and_within_reach_goes_on() {
        let yard = Some(Yardstick { bic: 175.0 });
        // attitude_bias on the tests' base after step 1: 2 838 against 175, three steps left.
        assert!(out_of_reach(yard, at(2838.0, 572.0, 572.0, 3)).is_some());
        // Three steps of 900 could bring it to 138: it could still replace the answer.
        assert!(out_of_reach(yard, at(2838.0, 900.0, 900.0, 3)).is_none());
        // Within the rival margin of the answer's BIC, it could still be a rival.
        assert!(out_of_reach(yard, at(2838.0, 886.0, 886.0, 3)).is_none());
        assert!(out_of_reach(yard, at(2838.0, 885.0, 885.0, 3)).is_some());
    }

    #[test]
    fn a_step_is_counted_at_twice_the_last_gain_and_at_most_the_best() {
        let yard = Some(Yardstick { bic: 102.7 });
        // release_rates on the tests' base after step 3 of gains 613, 458 and 11.5: one step
        // left, counted at 23, cannot bring 157 below 108.7.
        assert!(out_of_reach(yard, at(157.0, 613.0, 11.5, 1)).is_some());
        // After a gain of 30, a step of 60 could: discovery goes on.
        assert!(out_of_reach(yard, at(157.0, 613.0, 30.0, 1)).is_none());
        // Twice the last gain is capped by the best: 2 x 40 is counted as 50.
        assert!(out_of_reach(yard, at(205.0, 50.0, 40.0, 2)).is_none());
        assert!(out_of_reach(yard, at(205.0, 45.0, 40.0, 2)).is_some());
        // A step that lost BIC (F-to-remove) bounds the next at nothing.
        assert!(out_of_reach(yard, at(109.0, 50.0, -3.0, 1)).is_some());
    }

    #[test]
    fn without_an_answer_explained_or_steps_left_nothing_stops() {
        assert!(out_of_reach(None, at(1e6, 0.0, 0.0, 3)).is_none());
        let yard = Some(Yardstick { bic: 0.0 });
        // The last step ends the selection by itself; no note is due.
        assert!(out_of_reach(yard, at(1e6, 1.0, 1.0, 0)).is_none());
    }
}
