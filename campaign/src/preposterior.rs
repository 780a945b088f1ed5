//! The preposterior of the planning (docs/campaign.md, "The next release"): what a release at
//! condition c is expected to do to condition u's spread of the smallest clearance, and so
//! whether u is expected to end settled. A normal approximation of each condition's smallest
//! clearance:
//!
//! - at condition u, m_u the median smallest clearance less the criterion, s_u the spread of
//!   the normal about m_u that fails as often as its samples did (s_u = m_u / Phi^-1(1 -
//!   p_fail): the tail, divergences included, decides a state, not the body), split as the
//!   samples' spread is between the factors (s_f,u, the spread without the model-form band) and
//!   the model form (s_m,u = sqrt(max(0, s_u^2 - s_f,u^2))), and the factors' part again into
//!   the rivals' disagreement s_r,u (the spread of their median clearances, [`crate::rivals`])
//!   and the spread within a model s_w,u = sqrt(max(0, s_f,u^2 - s_r,u^2));
//! - the model form is what differs from one condition to another: once c is flown, u's reach
//!   is r'_u, from the nearest release flown or planned beyond what the releases held out in
//!   turn then cover ([`sepval_predict::reach::uncovered`], as the next round's band reads it:
//!   the cover grows as the releases spread out), and s'_m,u = s_m,u e(r'_u) / e(r_u), e the
//!   reach the band uses (larger where the reach grows: the first release far from u, beyond
//!   the prior's reach, or the cover shrinking; the median is then not expected to move);
//! - the factors' part is what the round's samples say a release at c teaches of u
//!   ([`crate::joint`]): s'_f,u^2 = L_cu s_f,u^2, L_cu the share of the variance of u's
//!   clearance left once c's trajectory is measured, over the batch (rivals and within a model
//!   alike: the samples are drawn from both). Without the joint samples (an assessment written
//!   before 2026-12-02) the older rules: the rivals are told apart as well as their
//!   trajectories differ at c against the noise (S_c, [`crate::rivals::separation`]),
//!   s'_r,u = s_r,u sqrt(1 / (1 + S_c^2)); the factors within a model, the same at every
//!   condition, s'_w,u = s_w,u sqrt(n / (n + 1)) with n releases flown, and
//!   [`FIRST_RELEASE_SHARE`] s_w,u with none;
//! - the median moves by what is learnt, a normal of variance tau^2 = s_u^2 - s'_u^2, and u is
//!   settled when it ends more than z s'_u from the criterion (z the normal quantile of 1 -
//!   allowed): P(settled) = Phi((m_u - z s'_u) / tau) + Phi((-m_u - z s'_u) / tau).

use statrs::distribution::{ContinuousCDF, Normal};

use sepval_predict::reach::effective;

use crate::state::Assessed;

/// The share of the prior's spread of the factors that a first release at the condition
/// leaves, when the round holds no joint samples: a release of 1 s determines the factors that
/// act there to a few per cent of their prior range (docs/performance.md, the study's
/// comparison: standard errors of 0.02 to 0.16 against ranges of 0.2 to 1.75), so a quarter is
/// a cautious reading.
pub const FIRST_RELEASE_SHARE: f64 = 0.25;

/// A condition's spread of the smallest clearance in its three parts \[mm\] (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Spread {
    /// The rivals' disagreement.
    pub(crate) rivals: f64,
    /// The factors' within a model.
    pub(crate) within: f64,
    /// The model form's.
    pub(crate) form: f64,
}

impl Spread {
    pub(crate) fn total(&self) -> f64 {
        self.rivals.hypot(self.within).hypot(self.form)
    }
}

/// Each condition's spread: the spread of the normal that fails as often as its samples did
/// (their tail, divergences included, decides the state, not their body), shared as the
/// samples' spread is between the rivals, the factors within a model and the model form.
pub(crate) fn tail_spreads(assessed: &[Assessed], criterion_mm: f64) -> Vec<Spread> {
    assessed
        .iter()
        .map(|a| {
            let s = finite_or_zero(a.spread_mm);
            let f = finite_or_zero(a.factor_spread_mm).min(s);
            let r = finite_or_zero(a.rival_spread_mm).min(f);
            let part = |of: f64, less: f64| (of * of - less * less).max(0.0).sqrt();
            let k = effective_spread(a.row.clearance_p50_mm - criterion_mm, a.row.p_fail)
                .map_or(1.0, |e| if s > 0.0 { e / s } else { 1.0 });
            Spread {
                rivals: k * r,
                within: k * part(f, r),
                form: k * part(s, f),
            }
        })
        .collect()
}

/// The standard deviation of a normal about a median `margin` above the criterion that
/// falls below it with probability `p_fail`; `None` when that says nothing (no margin, or a
/// probability of 0, 1 or not finite).
fn effective_spread(margin: f64, p_fail: f64) -> Option<f64> {
    if !(margin.is_finite() && margin.abs() > 0.0 && p_fail > 0.0 && p_fail < 1.0) {
        return None;
    }
    let z = normal().inverse_cdf(1.0 - p_fail);
    let s = margin / z;
    (s.is_finite() && s > 0.0).then_some(s)
}

pub(crate) fn normal() -> Normal {
    Normal::new(0.0, 1.0).expect("the standard normal")
}

fn finite_or_zero(v: f64) -> f64 {
    if v.is_finite() { v.max(0.0) } else { 0.0 }
}

/// A release at c as condition u sees it.
pub(crate) struct Pair {
    /// u's reach once the release at c is flown (the nearest release's, beyond what the
    /// releases held out then cover).
    pub(crate) reach: f64,
    /// u's median smallest clearance less the criterion \[mm\].
    pub(crate) margin_mm: f64,
    /// The share of the rivals' variance a release at c leaves ([`rivals::left_after`]).
    pub(crate) rivals_left: f64,
    /// The share of u's factors' variance (the rivals' and within a model) a release at c
    /// leaves, read from the round's joint samples ([`joint::left_after`]); `None` without
    /// them, when the rules of the module docs apply.
    pub(crate) factors_left: Option<f64>,
    /// The normal quantile of 1 - allowed.
    pub(crate) z: f64,
}

/// What a release does to a condition (`pair`) of spread `spread` and reach `r`, with `n`
/// releases flown: its spread afterwards (its reach afterwards is `pair.reach`).
pub(crate) fn settle(pair: &Pair, spread: &Spread, r: f64, n: usize) -> Spread {
    let (e0, e1) = (effective(r), effective(pair.reach));
    // A reach may grow (the first release far from a condition, beyond the prior's
    // `UNFLOWN_REACH`, or the releases' cover shrinking): the band grows with it, as the next
    // round's will, and the condition's median is then not expected to move.
    let form = if e0 > 0.0 {
        spread.form * e1 / e0
    } else {
        spread.form
    };
    let (within, rivals) = match pair.factors_left {
        Some(left) => {
            let k = left.clamp(0.0, 1.0).sqrt();
            (spread.within * k, spread.rivals * k)
        }
        None => (
            if n == 0 {
                spread.within * FIRST_RELEASE_SHARE
            } else {
                spread.within * (n as f64 / (n as f64 + 1.0)).sqrt()
            },
            spread.rivals * pair.rivals_left.clamp(0.0, 1.0).sqrt(),
        ),
    };
    Spread {
        rivals,
        within,
        form,
    }
}

/// What a release does to one condition.
pub(crate) struct Outcome {
    /// The condition's spread afterwards.
    pub(crate) after: Spread,
    /// What the release adds to the probability that the condition ends settled.
    pub(crate) gain: f64,
    /// How much it narrows the condition's spread ([`narrowing`]), counted only as far as the
    /// batch before it has not settled the condition already.
    pub(crate) narrows: f64,
}

/// What a release (`pair`) does to a condition of spread `spread` and reach `r` now, its
/// total spread `start` before the batch, with `n` releases flown or chosen.
pub(crate) fn outcome(pair: &Pair, spread: &Spread, r: f64, start: f64, n: usize) -> Outcome {
    let after = settle(pair, spread, r, n);
    let before = settled_before(pair, spread, start, n);
    Outcome {
        gain: p_settle(pair, start, after.total()) - before,
        narrows: (1.0 - before).clamp(0.0, 1.0) * narrowing(spread, &after),
        after,
    }
}

/// The probability that a condition of spread `spread` now (`start` before the batch) is
/// settled by the batch chosen so far, with `n` releases flown or chosen. Before the first
/// release nothing is cleared (`State::before_release`): whatever the prior would settle, the
/// first release settles.
fn settled_before(pair: &Pair, spread: &Spread, start: f64, n: usize) -> f64 {
    if n == 0 {
        0.0
    } else {
        p_settle(pair, start, spread.total())
    }
}

/// The probability that a condition whose spread goes from `s` to `s_after` ends settled: its
/// median moves by a normal of variance s^2 - s_after^2 and must end more than z s_after from
/// the criterion (module docs). 0 when nothing is learnt or the median is unknown.
fn p_settle(pair: &Pair, s: f64, s_after: f64) -> f64 {
    let (margin, z) = (pair.margin_mm, pair.z);
    if !margin.is_finite() {
        return 0.0;
    }
    let tau = (s * s - s_after * s_after).max(1e-12).sqrt();
    let nd = normal();
    (nd.cdf((margin - z * s_after) / tau) + nd.cdf((-margin - z * s_after) / tau)).min(1.0)
}

/// How much a release narrows a condition's spread: 1 - s' / s (negative where it widens it,
/// at least -1), 0 when it had none.
fn narrowing(before: &Spread, after: &Spread) -> f64 {
    let (s0, s1) = (before.total(), after.total());
    if s0 > 0.0 {
        (1.0 - s1 / s0).clamp(-1.0, 1.0)
    } else {
        0.0
    }
}
