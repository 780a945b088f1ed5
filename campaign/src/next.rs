//! The next release(s) to fly (docs/campaign.md, "The next release"). Only conditions whose
//! probability of failing to clear is at most the fly risk are candidates: a program never
//! flies where the prediction says the store may hit the aircraft. Among them, a release at c
//! is ranked by the expected number of undecided conditions it settles, a preposterior
//! analysis under a normal approximation of each condition's smallest clearance:
//!
//! - at undecided condition u, m_u the median smallest clearance less the criterion, s_u the
//!   spread of the normal about m_u that fails as often as its samples did (s_u = m_u /
//!   Phi^-1(1 - p_fail): the tail, divergences included, decides a state, not the body), split
//!   as the samples' spread is between the factors (s_f,u, the spread without the model-form
//!   band) and the model form (s_m,u = sqrt(max(0, s_u^2 - s_f,u^2)));
//! - a release at c brings u's reach down to r'_u = min(r_u, reach(c, u)): the model form's
//!   part scales with the reach ([`sepval_predict::reach`]), s'_m,u = s_m,u e(r'_u) / e(r_u),
//!   e the reach the band uses;
//! - the factors' part is split again into the rivals' disagreement s_r,u (the spread of their
//!   median clearances, [`crate::rivals`]) and the spread within a model s_w,u =
//!   sqrt(max(0, s_f,u^2 - s_r,u^2));
//! - it tells the rivals apart as well as their trajectories differ at c against the noise and
//!   their own spread there (the separation S_c, [`crate::rivals::separation`]); the same model
//!   holds everywhere, so s'_r,u = s_r,u sqrt(1 / (1 + S_c^2)) at every u: a release where the
//!   rivals disagree settles the conditions whose decision hangs on them;
//! - it informs the factors within a model, which are the same at every condition (the model's
//!   form is what differs from one condition to another, and the reach carries it): with n
//!   releases flown, s'_w,u = s_w,u sqrt(n / (n + 1)); with none, s'_w,u =
//!   [`FIRST_RELEASE_SHARE`] s_w,u, the share of the prior's spread a first release leaves;
//! - the median moves by what is learnt, a normal of variance tau^2 = s_u^2 - s'_u^2, and u is
//!   settled when it ends more than z s'_u from the criterion (z the normal quantile of 1 -
//!   allowed): P(settled) = Phi((m_u - z s'_u) / tau) + Phi((-m_u - z s'_u) / tau).
//!
//! `expected_settled(c)` sums P(settled) over the undecided conditions, less what they would be
//! without the release (the batch's releases before it). With nothing flown that is nothing:
//! the prior clears nothing ([`crate::state::State::before_release`]), so a condition the
//! prior would clear is settled by the first release when it stays more than z s'_u above the
//! criterion afterwards. A batch of K is chosen
//! greedily: each release chosen is taken as flown (the spreads it leaves, one more release)
//! before the next is ranked, so that the batch's releases complement each other rather than
//! settle the same conditions; once the releases chosen are expected to settle all that can be
//! settled, the batch's others go where the model's form is least known (the safe condition of
//! the largest reach from every release flown or planned). Ties go to the lower risk, then to
//! grid order.

use serde::{Deserialize, Serialize};
use statrs::distribution::{ContinuousCDF, Normal};

use sepval_common::scenario::Flight;
use sepval_envelope::Grid;
use sepval_fit::domain::reach;
use sepval_predict::reach::effective;

use crate::rivals;
use crate::state::{Assessed, State};

/// The share of the prior's spread of the factors that a first release at the condition
/// leaves: a release of 1 s determines the factors that act there to a few per cent of their
/// prior range (docs/performance.md, the study's comparison: standard errors of 0.02 to 0.16
/// against ranges of 0.2 to 1.75), so a quarter is a cautious reading.
pub const FIRST_RELEASE_SHARE: f64 = 0.25;
/// A release expected to settle fewer conditions than this settles nothing.
pub const SETTLES_NOTHING: f64 = 0.5;

/// One release planned.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Planned {
    /// Its index in the grid.
    pub index: usize,
    /// Mach.
    pub mach: f64,
    /// Altitude \[m\].
    pub altitude_m: f64,
    /// Aircraft angle of attack \[deg\].
    pub alpha_deg: f64,
    /// Sideslip \[deg\].
    pub beta_deg: f64,
    /// Flight-path angle \[deg\].
    pub gamma_deg: f64,
    /// The predicted probability of failing to clear there.
    pub p_fail: f64,
    /// How many undecided conditions it is expected to settle.
    pub expected_settled: f64,
    /// Why, in words.
    pub why: String,
}

/// What the planning found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// The releases to fly, best first (empty when none is safe, or none settles anything).
    pub releases: Vec<Planned>,
    /// When no condition is safe to fly: the least risky, with its risk.
    pub least_risky: Option<Planned>,
    /// Whether the envelope is settled: nothing undecided, or no safe release expected to
    /// settle any.
    pub settled: bool,
    /// In words.
    pub words: String,
}

/// What decides a plan.
#[derive(Debug, Clone, Copy)]
pub struct Criteria {
    /// The clearance criterion \[mm\].
    pub criterion_mm: f64,
    /// The allowed probability of failing (a condition's state).
    pub allowed: f64,
    /// The largest probability of failing at which a release may be flown.
    pub fly_risk: f64,
}

/// The plan of `count` releases over `assessed` (the current envelope of `grid`), with
/// `flown` releases so far.
pub fn plan(
    grid: &Grid,
    assessed: &[Assessed],
    flown: &[Flight],
    criteria: Criteria,
    count: usize,
) -> Plan {
    let Criteria {
        criterion_mm,
        allowed,
        fly_risk,
    } = criteria;
    let undecided: Vec<usize> = (0..assessed.len())
        .filter(|&u| assessed[u].state == State::Undecided)
        .collect();
    let safe: Vec<usize> = (0..assessed.len())
        .filter(|&c| assessed[c].row.p_fail <= fly_risk)
        .collect();
    if safe.is_empty() {
        return no_safe(grid, assessed, fly_risk, undecided.is_empty());
    }
    let z = normal().inverse_cdf(1.0 - allowed);
    let mut spreads = tail_spreads(assessed, criterion_mm);
    // Each condition's spread before any release of the batch: what is learnt is measured
    // from it.
    let start: Vec<f64> = spreads.iter().map(Spread::total).collect();
    let mut reaches: Vec<f64> = assessed.iter().map(|a| a.reach).collect();
    let at = |c: usize, u: usize| Pair {
        reach: reach(&[grid.flight(c)], grid.flight(u)),
        margin_mm: assessed[u].row.clearance_p50_mm - criterion_mm,
        rivals_left: rivals::left_after(assessed[c].rival_separation),
        z,
    };
    let mut chosen: Vec<Planned> = Vec::new();
    for n in flown.len()..flown.len() + count.max(1) {
        let open: Vec<(usize, f64)> = safe
            .iter()
            .filter(|c| !chosen.iter().any(|p| p.index == **c))
            .map(|&c| {
                let gain = |u: usize| gain(&at(c, u), spreads[u], reaches[u], start[u], n);
                (c, undecided.iter().map(|&u| gain(u)).sum())
            })
            .collect();
        let risk = |c: usize| assessed[c].row.p_fail;
        let by = |key: &dyn Fn(&(usize, f64)) -> f64| {
            open.iter().copied().max_by(|a, b| {
                key(a)
                    .total_cmp(&key(b))
                    .then(risk(b.0).total_cmp(&risk(a.0)))
                    .then(b.0.cmp(&a.0))
            })
        };
        let Some((mut c, mut e)) = by(&|x| x.1) else {
            break;
        };
        // A gain is a difference of sums: what rounds to 0 is said as 0, never "-0.0".
        let e_shown = |e: f64| if e > 0.0 { e } else { 0.0 };
        let mut why = format!(
            "expected to settle {:.1} of the {} undecided conditions",
            e_shown(e),
            undecided.len()
        );
        if e < SETTLES_NOTHING {
            if chosen.is_empty() {
                break;
            }
            // The batch's others: where the model's form is least known.
            (c, e) = by(&|x| effective(reaches[x.0])).expect("open is not empty");
            why = format!(
                "adds {:.1} to what the releases before it in the batch settle; chosen as the safe condition farthest from every release flown or planned (reach {:.1}), where the model's form is least known",
                e_shown(e),
                reaches[c]
            );
        }
        why.push_str(&format!(
            "; P(fail) here {:.4}, within the fly risk {fly_risk}",
            risk(c)
        ));
        chosen.push(planned(grid, assessed, c, e_shown(e), why));
        // Taken as flown: the spreads it leaves, one release more.
        for u in 0..assessed.len() {
            (spreads[u], reaches[u]) = settle(&at(c, u), &spreads[u], reaches[u], n);
        }
    }
    let mut words = words(undecided.len(), chosen.len());
    if !chosen.is_empty() && chosen.len() < count {
        words.push_str(&format!(
            "; {} of the {count} asked for: only {} of the grid's conditions are safe to fly (P(fail) within the fly risk), and each of them is planned",
            chosen.len(),
            safe.len()
        ));
    }
    Plan {
        settled: undecided.is_empty() || chosen.is_empty(),
        releases: chosen,
        least_risky: None,
        words,
    }
}

/// The plan in words, from the undecided conditions and the releases chosen.
fn words(undecided: usize, chosen: usize) -> String {
    if undecided == 0 {
        "settled: no condition is undecided".to_string()
    } else if chosen == 0 {
        format!(
            "settled: {undecided} condition(s) stay undecided, and no release safe to fly is expected to settle any of them"
        )
    } else {
        format!("{chosen} release(s) planned for the {undecided} undecided condition(s)")
    }
}

/// A condition's spread of the smallest clearance in its three parts \[mm\] (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Spread {
    /// The rivals' disagreement.
    rivals: f64,
    /// The factors' within a model.
    within: f64,
    /// The model form's.
    form: f64,
}

impl Spread {
    fn total(&self) -> f64 {
        self.rivals.hypot(self.within).hypot(self.form)
    }
}

/// Each condition's spread: the spread of the normal that fails as often as its samples did
/// (their tail, divergences included, decides the state, not their body), shared as the
/// samples' spread is between the rivals, the factors within a model and the model form.
fn tail_spreads(assessed: &[Assessed], criterion_mm: f64) -> Vec<Spread> {
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

/// The plan when no condition is safe to fly: none, and the least risky named.
fn no_safe(grid: &Grid, assessed: &[Assessed], fly_risk: f64, settled: bool) -> Plan {
    let least = (0..assessed.len())
        .min_by(|&a, &b| assessed[a].row.p_fail.total_cmp(&assessed[b].row.p_fail))
        .map(|c| {
            let why = format!(
                "the least risky condition: P(fail) {:.3} there, above the fly risk {fly_risk}",
                assessed[c].row.p_fail
            );
            planned(grid, assessed, c, 0.0, why)
        });
    Plan {
        releases: Vec::new(),
        least_risky: least,
        settled,
        words: format!(
            "no condition is safe to fly: every one has a probability of failing to clear above {fly_risk}"
        ),
    }
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

fn normal() -> Normal {
    Normal::new(0.0, 1.0).expect("the standard normal")
}

fn finite_or_zero(v: f64) -> f64 {
    if v.is_finite() { v.max(0.0) } else { 0.0 }
}

/// A release at c as condition u sees it.
struct Pair {
    /// reach(c, u).
    reach: f64,
    /// u's median smallest clearance less the criterion \[mm\].
    margin_mm: f64,
    /// The share of the rivals' variance a release at c leaves ([`rivals::left_after`]).
    rivals_left: f64,
    /// The normal quantile of 1 - allowed.
    z: f64,
}

/// What a release does to a condition (`pair`) of spread `spread` and reach `r`, with `n`
/// releases flown: its spread and reach afterwards.
fn settle(pair: &Pair, spread: &Spread, r: f64, n: usize) -> (Spread, f64) {
    let r_after = r.min(pair.reach);
    let (e0, e1) = (effective(r), effective(r_after));
    let form = if e0 > 0.0 {
        spread.form * e1 / e0
    } else {
        spread.form
    };
    let within = if n == 0 {
        spread.within * FIRST_RELEASE_SHARE
    } else {
        spread.within * (n as f64 / (n as f64 + 1.0)).sqrt()
    };
    let rivals = spread.rivals * pair.rivals_left.clamp(0.0, 1.0).sqrt();
    (
        Spread {
            rivals,
            within,
            form,
        },
        r_after,
    )
}

/// What a release (`pair`) adds to the probability that a condition ends settled, its spread
/// `spread` and reach `r` now, its spread `start` before the batch, with `n` releases flown or
/// chosen.
fn gain(pair: &Pair, spread: Spread, r: f64, start: f64, n: usize) -> f64 {
    let (after, _) = settle(pair, &spread, r, n);
    // Before the first release nothing is cleared (`State::before_release`): whatever the
    // prior would settle, the first release settles.
    let before = if n == 0 {
        0.0
    } else {
        p_settle(pair, start, spread.total())
    };
    p_settle(pair, start, after.total()) - before
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

/// The planned release at condition `c`.
fn planned(grid: &Grid, assessed: &[Assessed], c: usize, e: f64, why: String) -> Planned {
    let f = grid.flight(c);
    Planned {
        index: c,
        mach: f.mach,
        altitude_m: f.altitude_m,
        alpha_deg: f.alpha_deg,
        beta_deg: f.beta_deg,
        gamma_deg: f.gamma_deg,
        p_fail: assessed[c].row.p_fail,
        expected_settled: e,
        why,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sepval_common::scenario::Scenario;
    use sepval_envelope::Row;
    use sepval_envelope::grid::Axis;
    use sepval_fit::conditions::Quantity;
    use sepval_predict::record::ConditionRecord;

    /// A grid of five Mach numbers whose conditions fail with `p_fail`, median clearance `p50`.
    fn envelope(p_fail: [f64; 5], p50: [f64; 5]) -> (Grid, Vec<Assessed>) {
        let base = Scenario::embedded_default();
        let grid = Grid::of(&base, &[Axis::parse(Quantity::Mach, "0.6:1.0:5").unwrap()]).unwrap();
        let assessed = (0..5)
            .map(|k| {
                let mut row = Row::all_diverged(k, ConditionRecord::of(grid.flight(k)));
                (row.p_fail, row.clearance_p50_mm, row.diverged_share) = (p_fail[k], p50[k], 0.0);
                Assessed {
                    state: State::of(p_fail[k], 0.05),
                    reach: f64::INFINITY,
                    spread_mm: 10.0,
                    factor_spread_mm: 8.0,
                    rival_spread_mm: 0.0,
                    rival_separation: 0.0,
                    row,
                }
            })
            .collect();
        (grid, assessed)
    }

    const CRITERIA: Criteria = Criteria {
        criterion_mm: 25.4,
        allowed: 0.05,
        fly_risk: 0.01,
    };

    #[test]
    fn only_safe_conditions_are_planned_and_a_batch_is_distinct() {
        let (grid, a) = envelope([0.0, 0.005, 0.2, 0.3, 0.4], [60.0, 55.0, 33.0, 30.0, 28.0]);
        let p = plan(&grid, &a, &[], CRITERIA, 3);
        assert!(!p.settled, "{p:?}");
        assert_eq!(p.releases.len(), 2, "only two conditions are safe: {p:?}");
        let mut seen: Vec<usize> = p.releases.iter().map(|r| r.index).collect();
        assert!(seen.iter().all(|&k| a[k].row.p_fail <= 0.01), "{p:?}");
        seen.dedup();
        assert_eq!(seen.len(), 2);
        assert!(p.releases[0].expected_settled > 0.0, "{p:?}");
    }

    #[test]
    fn no_safe_condition_names_the_least_risky_and_nothing_undecided_is_settled() {
        let (grid, a) = envelope([0.2, 0.3, 0.02, 0.4, 0.5], [40.0, 35.0, 45.0, 30.0, 25.0]);
        let p = plan(&grid, &a, &[], CRITERIA, 1);
        assert!(p.releases.is_empty());
        assert_eq!(p.least_risky.as_ref().map(|r| r.index), Some(2));
        let (grid, a) = envelope([0.0; 5], [90.0; 5]);
        let p = plan(&grid, &a, &[], CRITERIA, 1);
        assert!(p.settled && p.releases.is_empty(), "{p:?}");
        assert_eq!(p.words, "settled: no condition is undecided");
    }

    #[test]
    fn before_any_release_the_first_settles_what_the_prior_would_clear() {
        let (grid, mut a) = envelope([0.0, 0.001, 0.002, 0.003, 0.004], [90.0; 5]);
        for c in &mut a {
            c.state = State::before_release(c.row.p_fail, 0.05);
        }
        let p = plan(&grid, &a, &[], CRITERIA, 2);
        assert!(!p.settled, "{p:?}");
        let first = &p.releases[0];
        assert!(first.expected_settled > 4.9, "{p:?}");
        assert!(first.why.starts_with("expected to settle"), "{p:?}");
        // The batch's second settles nothing more: it goes where the model's form is least known.
        assert!(
            p.releases[1].why.contains("farthest from every release"),
            "{p:?}"
        );
    }

    #[test]
    fn a_release_where_the_rivals_part_ways_settles_what_hangs_on_them() {
        // Three undecided conditions whose factors' spread is mostly the rivals' disagreement;
        // two safe ones, Mach 0.7 nearer them than Mach 0.6.
        let (grid, mut a) = envelope([0.0, 0.0, 0.3, 0.3, 0.3], [60.0, 60.0, 30.0, 30.0, 30.0]);
        for c in &mut a[2..] {
            (c.factor_spread_mm, c.rival_spread_mm) = (9.9, 9.8);
        }
        let flown = [grid.flight(4).clone()];
        // No release tells the rivals apart: none is expected to settle anything.
        let p = plan(&grid, &a, &flown, CRITERIA, 1);
        assert!(p.releases.is_empty() && p.settled, "{p:?}");
        // At Mach 0.6, the farther, a release tells them apart (their trajectories 20 noise
        // apart there): it is planned, for the conditions whose decision hangs on them.
        a[0].rival_separation = 20.0;
        let p = plan(&grid, &a, &flown, CRITERIA, 1);
        assert_eq!(p.releases.len(), 1, "{p:?}");
        assert_eq!(p.releases[0].index, 0, "{p:?}");
        assert!(p.releases[0].expected_settled > 1.0, "{p:?}");
    }
}
