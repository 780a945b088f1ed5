//! The next release(s) to fly (docs/campaign.md, "The next release"). Only conditions whose
//! probability of failing to clear is at most the fly risk are candidates: a program never
//! flies where the prediction says the store may hit the aircraft. Among them a release at c is
//! weighed two ways, both from the preposterior ([`crate::preposterior`]: what a release at c
//! is expected to leave of each condition's spread of the smallest clearance):
//!
//! - `expected_settled(c)`: the expected number of undecided conditions it settles, the sum of
//!   their P(settled) less what they would be without the release (the batch's releases
//!   before it). With nothing flown that is nothing: the prior clears nothing
//!   ([`crate::state::State::before_release`]), so a condition the prior would clear is settled
//!   by the first release when it stays more than z s' above the criterion afterwards;
//! - `narrows(c)`: how much it narrows the undecided band, the sum over the undecided
//!   conditions of 1 - s'_u / s_u: the build-up's measure, since the undecided conditions are
//!   the band about the boundary.
//!
//! The rule, one release at a time:
//!
//! 1. the release expected to settle most, when that is at least [`SETTLES_NOTHING`]; among
//!    the candidates within [`FLAT`] of it (a flat ranking: the forecast cannot tell them
//!    apart), the one that narrows the undecided band most, the build-up step toward the
//!    boundary;
//! 2. when none is expected to settle that many (an uncertain ranking), the build-up step: the
//!    candidate that narrows the undecided band most, when it narrows it by at least
//!    [`NARROWS_NOTHING`];
//! 3. only when neither holds is the envelope settled with conditions undecided: no safe
//!    release is expected to settle or narrow any of them.
//!
//! A batch of K is chosen greedily: each release chosen is taken as flown (the spreads it
//! leaves, its reach) before the next is weighed, so the batch's releases complement each
//! other; the batch's others, once nothing is expected to be settled or narrowed, go where the
//! model's form is least known (the safe condition of the largest reach from every release
//! flown or planned). Ties go to the lower risk, then to grid order.

use serde::{Deserialize, Serialize};
use statrs::distribution::ContinuousCDF;

use sepval_common::scenario::Flight;
use sepval_envelope::Grid;
use sepval_predict::reach::{effective, uncovered};
use sepval_run::domain::{covered_reach, reach};

use crate::joint;
use crate::preposterior::{Pair, Spread, normal, outcome, tail_spreads};
use crate::rivals;
use crate::state::{Assessed, State};

/// A release expected to settle fewer conditions than this settles nothing.
pub const SETTLES_NOTHING: f64 = 0.5;
/// Candidates expected to settle within this share of the best are ranked alike (rule 1).
pub const FLAT: f64 = 0.9;
/// A release that narrows the undecided band by less than this (a sum of shares of the
/// undecided conditions' spreads) narrows nothing (rule 2).
pub const NARROWS_NOTHING: f64 = 0.25;

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
    let undecided = assessed
        .iter()
        .filter(|a| a.state == State::Undecided)
        .count();
    let safe: Vec<usize> = (0..assessed.len())
        .filter(|&c| assessed[c].row.p_fail <= criteria.fly_risk)
        .collect();
    if safe.is_empty() {
        return no_safe(grid, assessed, criteria.fly_risk, undecided == 0);
    }
    let spreads = tail_spreads(assessed, criteria.criterion_mm);
    let planner = Planner {
        grid,
        assessed,
        flown,
        criteria,
        z: normal().inverse_cdf(1.0 - criteria.allowed),
        every: (0..assessed.len()).collect(),
        undecided,
        joint: assessed.iter().map(|a| a.joint.as_slice()).collect(),
        start: spreads.iter().map(Spread::total).collect(),
    };
    let mut outlook = planner.outlook_now(spreads);
    let mut chosen: Vec<Planned> = Vec::new();
    for n in flown.len()..flown.len() + count.max(1) {
        let options: Vec<Weighed> = safe
            .iter()
            .filter(|c| !chosen.iter().any(|p| p.index == **c))
            .map(|&c| planner.weigh(&outlook, c, n))
            .collect();
        let Some((pick, why)) = planner.pick(&options, &outlook, !chosen.is_empty()) else {
            break;
        };
        let w = options.into_iter().find(|w| w.c == pick).expect("picked");
        chosen.push(planned(grid, assessed, w.c, w.settles.max(0.0), why));
        // Taken as flown: the spreads it leaves, one release more.
        outlook = w.after;
    }
    let undecided = planner.undecided;
    let mut words = words(undecided, chosen.len());
    if !chosen.is_empty() && chosen.len() < count {
        words.push_str(&format!(
            "; {} of the {count} asked for: only {} of the grid's conditions are safe to fly (P(fail) within the fly risk), and each of them is planned",
            chosen.len(),
            safe.len()
        ));
    }
    Plan {
        settled: undecided == 0 || chosen.is_empty(),
        releases: chosen,
        least_risky: None,
        words,
    }
}

/// What the planning reads the envelope from.
struct Planner<'a> {
    grid: &'a Grid,
    assessed: &'a [Assessed],
    flown: &'a [Flight],
    criteria: Criteria,
    /// The normal quantile of 1 - allowed.
    z: f64,
    /// Every condition's index.
    every: Vec<usize>,
    /// How many conditions are undecided.
    undecided: usize,
    /// Each condition's joint samples ([`Assessed::joint`]).
    joint: Vec<&'a [Option<joint::Sample>]>,
    /// Each condition's total spread before the batch: what is learnt is measured from it.
    start: Vec<f64>,
}

/// The envelope as the planning expects it once the batch chosen so far is flown.
struct Outlook {
    /// The batch's conditions.
    batch: Vec<usize>,
    /// Each condition's spread, in its parts.
    spreads: Vec<Spread>,
    /// Each condition's reach.
    reaches: Vec<f64>,
    /// The share of each condition's factors' variance the batch leaves
    /// ([`joint::left_after`]; `None`: the rules without the joint samples).
    left: Option<Vec<f64>>,
}

/// A candidate weighed against an outlook.
struct Weighed {
    c: usize,
    /// Its expected number of undecided conditions settled.
    settles: f64,
    /// How much it narrows the undecided band.
    narrows: f64,
    /// The outlook once it is flown.
    after: Outlook,
}

impl Planner<'_> {
    /// The envelope before any release of the batch, each condition's spread `spreads`.
    fn outlook_now(&self, spreads: Vec<Spread>) -> Outlook {
        Outlook {
            batch: Vec::new(),
            spreads,
            reaches: self.assessed.iter().map(|a| a.reach).collect(),
            left: joint::left_after(&self.joint, &[], &self.every),
        }
    }

    /// A release at `c` flown after the outlook `o`'s batch, with `n` releases flown or
    /// chosen before it.
    fn weigh(&self, o: &Outlook, c: usize, n: usize) -> Weighed {
        let mut batch = o.batch.clone();
        batch.push(c);
        let left = o
            .left
            .as_ref()
            .and_then(|_| joint::left_after(&self.joint, &batch, &self.every));
        // Each condition's reach once c is flown: from the nearest release, beyond what the
        // releases held out in turn then cover (as the next round's band reads it).
        let mut all: Vec<&Flight> = self.flown.iter().collect();
        all.extend(batch.iter().map(|&k| self.grid.flight(k)));
        let covered = covered_reach(&all, &[]);
        let rivals_left = rivals::left_after(self.assessed[c].rival_separation);
        let mut after = Outlook {
            batch,
            spreads: o.spreads.clone(),
            reaches: o.reaches.clone(),
            left: None,
        };
        let (mut settles, mut narrows) = (0.0, 0.0);
        for &u in &self.every {
            let pair = Pair {
                reach: uncovered(reach(&all, self.grid.flight(u)), covered),
                margin_mm: self.assessed[u].row.clearance_p50_mm - self.criteria.criterion_mm,
                rivals_left,
                factors_left: left.as_ref().zip(o.left.as_ref()).map(|(l, now)| {
                    if now[u] > 0.0 {
                        (l[u] / now[u]).min(1.0)
                    } else {
                        1.0
                    }
                }),
                z: self.z,
            };
            let out = outcome(&pair, &o.spreads[u], o.reaches[u], self.start[u], n);
            if self.assessed[u].state == State::Undecided {
                settles += out.gain;
                narrows += out.narrows;
            }
            (after.spreads[u], after.reaches[u]) = (out.after, pair.reach);
        }
        after.left = left;
        Weighed {
            c,
            settles,
            narrows,
            after,
        }
    }

    /// The release to take among `options` (module docs' rule) and why; `None` when none
    /// settles or narrows anything and `batch_begun` is false.
    fn pick(&self, options: &[Weighed], o: &Outlook, batch_begun: bool) -> Option<(usize, String)> {
        let risk = |c: usize| self.assessed[c].row.p_fail;
        let best = |key: &dyn Fn(&Weighed) -> f64, among: &dyn Fn(&Weighed) -> bool| {
            options.iter().filter(|w| among(w)).max_by(|a, b| {
                key(a)
                    .total_cmp(&key(b))
                    .then(risk(b.c).total_cmp(&risk(a.c)))
                    .then(b.c.cmp(&a.c))
            })
        };
        let top = best(&|w| w.settles, &|_| true)?;
        let undecided = self.undecided;
        let (w, mut why) = if top.settles >= SETTLES_NOTHING {
            let floor = FLAT * top.settles;
            let w = best(&|w| w.narrows, &|w| w.settles >= floor).expect("top is among them");
            let mut why = format!(
                "expected to settle {:.1} of the {undecided} undecided conditions",
                w.settles
            );
            if w.c != top.c {
                why.push_str(&format!(
                    "; as many as the best (within {:.0} %), and of those the build-up step: it narrows the undecided band most ({:.2} of their spreads)",
                    100.0 * (1.0 - FLAT),
                    w.narrows
                ));
            }
            (w, why)
        } else if let Some(w) = best(&|w| w.narrows, &|w| w.narrows >= NARROWS_NOTHING) {
            let why = format!(
                "the build-up step: no release is expected to settle a condition (the most, {:.1}), and this one narrows the band of the {undecided} undecided conditions most ({:.2} of their spreads), a step toward the boundary",
                top.settles.max(0.0),
                w.narrows
            );
            (w, why)
        } else if batch_begun {
            // The batch's others: where the model's form is least known.
            let w = best(&|w| effective(o.reaches[w.c]), &|_| true).expect("options");
            let why = format!(
                "adds {:.1} to what the releases before it in the batch settle; chosen as the safe condition farthest from every release flown or planned (reach {:.1}), where the model's form is least known",
                w.settles.max(0.0),
                o.reaches[w.c]
            );
            (w, why)
        } else {
            return None;
        };
        why.push_str(&format!(
            "; P(fail) here {:.4}, within the fly risk {}",
            risk(w.c),
            self.criteria.fly_risk
        ));
        Some((w.c, why))
    }
}

/// The plan in words, from the undecided conditions and the releases chosen.
fn words(undecided: usize, chosen: usize) -> String {
    if undecided == 0 {
        "settled: no condition is undecided".to_string()
    } else if chosen == 0 {
        format!(
            "settled: {undecided} condition(s) stay undecided, and no release safe to fly is expected to settle or narrow any of them"
        )
    } else {
        format!("{chosen} release(s) planned for the {undecided} undecided condition(s)")
    }
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
    use sepval_predict::record::ConditionRecord;
    use sepval_run::conditions::Quantity;

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
                    joint: Vec::new(),
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

    #[test]
    fn with_nothing_expected_settled_the_build_up_step_goes_toward_the_boundary() {
        // Flown at Mach 0.6; safe at 0.6 and 0.7; undecided at 0.8 to 1.0, their medians on the
        // criterion, so that no release is expected to settle them: the build-up step is the
        // release nearer them (it narrows their model form's share too), and the envelope is
        // not called settled.
        let (grid, mut a) = envelope([0.0, 0.0, 0.45, 0.45, 0.45], [60.0, 60.0, 25.5, 25.5, 25.5]);
        let flown = [grid.flight(0).clone()];
        for (k, c) in a.iter_mut().enumerate() {
            c.reach = k as f64;
            (c.spread_mm, c.factor_spread_mm) = (10.0, 9.5);
        }
        let p = plan(&grid, &a, &flown, CRITERIA, 1);
        assert!(!p.settled, "{p:?}");
        assert_eq!(p.releases[0].index, 1, "{p:?}");
        assert!(p.releases[0].why.starts_with("the build-up step"), "{p:?}");
        // With the undecided conditions' spread all the factors' within a model (nothing a
        // release nearer them narrows more than one at Mach 0.6), neither settles nor narrows
        // enough after many releases: settled, saying so.
        let many: Vec<Flight> = (0..50).map(|_| grid.flight(0).clone()).collect();
        for c in &mut a {
            (c.reach, c.factor_spread_mm) = (0.0, 10.0);
        }
        let p = plan(&grid, &a, &many, CRITERIA, 1);
        assert!(p.settled && p.releases.is_empty(), "{p:?}");
        assert!(p.words.contains("settle or narrow"), "{p:?}");
    }
}
