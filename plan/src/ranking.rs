//! The ranking of the conditions (docs/planning.md section 12.4): with rivals, by the number of
//! pairs of models a release there separates (most first), then by its separation (the hardest
//! pair's, largest first), then by information gain; without rivals, by information gain alone.
//! Every model, the answer or a rival, may be the true one, so every pair counts alike: with
//! many rivals the hardest pair (often two rivals, neither the answer) may be inseparable
//! everywhere in the ranges, and the smallest separation alone would then rank by a pair no
//! release settles. Conditions where a model leaves a table come after every condition
//! that stays inside them, and conditions where a model diverges (or a step of its
//! sensitivities does) come last, in grid order: they are reported, never recommended first.

use std::cmp::Ordering;

use serde::{Deserialize, Serialize};

use crate::conditions::Conditions;
use crate::information::Information;
use crate::separation::{PairSeparation, Separations};

/// Where a condition stands.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "status", content = "notes", rename_all = "snake_case")]
pub enum Standing {
    /// Every model simulates there within the scenario's tables.
    Ranked,
    /// A model leaves a table there (each excursion, in words).
    TablesLeft(Vec<String>),
    /// A model diverges or fails there (why).
    Diverged(Vec<String>),
}

impl Standing {
    fn class(&self) -> u8 {
        match self {
            Standing::Ranked => 0,
            Standing::TablesLeft(_) => 1,
            Standing::Diverged(_) => 2,
        }
    }
}

/// One condition with its scores.
#[derive(Debug, Clone, PartialEq)]
pub struct RankedCondition {
    /// Its index in the grid.
    pub index: usize,
    /// The number of pairs of models a release there separates.
    pub separated_pairs: usize,
    /// Its separation (none without rivals or where a model did not run).
    pub separation: Option<f64>,
    /// Its information gain (none where the answer's sensitivities are missing).
    pub information_gain: Option<f64>,
    /// Every pair of models there.
    pub pairs: Vec<PairSeparation>,
    /// Where it stands.
    pub standing: Standing,
}

/// The conditions, best first.
#[derive(Debug, Clone, PartialEq)]
pub struct Ranking {
    /// Best first.
    pub conditions: Vec<RankedCondition>,
}

impl Ranking {
    /// The recommended condition: the first, unless none is ranked.
    pub fn recommended(&self) -> Option<&RankedCondition> {
        self.conditions
            .first()
            .filter(|c| !matches!(c.standing, Standing::Diverged(_)))
    }
}

/// Ranks the conditions.
pub fn rank(
    conditions: &Conditions,
    separations: &Separations,
    information: &Information,
    tables_left: &[Vec<String>],
    rivals: bool,
) -> Ranking {
    let mut list: Vec<RankedCondition> = (0..conditions.list.len())
        .map(|k| {
            let pairs = separations.conditions[k].clone();
            let gain = information.gains[k].clone();
            let mut why: Vec<String> = Vec::new();
            if let Err(r) = &pairs {
                why.push(r.to_string());
            }
            if let Err(r) = &gain {
                let r = r.to_string();
                if !why.contains(&r) {
                    why.push(r);
                }
            }
            let standing = if !why.is_empty() {
                Standing::Diverged(why)
            } else if !tables_left[k].is_empty() {
                Standing::TablesLeft(tables_left[k].clone())
            } else {
                Standing::Ranked
            };
            let pairs = pairs.unwrap_or_default();
            RankedCondition {
                index: k,
                separated_pairs: pairs.iter().filter(|p| p.separated()).count(),
                separation: separations.of(k),
                information_gain: gain.ok(),
                pairs,
                standing,
            }
        })
        .collect();
    // A score that is missing or not a number goes last within its class.
    let key = |v: Option<f64>| v.filter(|v| !v.is_nan()).unwrap_or(f64::NEG_INFINITY);
    list.sort_by(|a, b| {
        let by_class = a.standing.class().cmp(&b.standing.class());
        if by_class != Ordering::Equal || a.standing.class() == 2 {
            return by_class.then(a.index.cmp(&b.index));
        }
        let by_separation = if rivals {
            b.separated_pairs
                .cmp(&a.separated_pairs)
                .then(key(b.separation).total_cmp(&key(a.separation)))
        } else {
            Ordering::Equal
        };
        by_separation
            .then(key(b.information_gain).total_cmp(&key(a.information_gain)))
            .then(a.index.cmp(&b.index))
    });
    Ranking { conditions: list }
}
