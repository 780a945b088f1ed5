//! A release given to `sepval campaign add`, read and screened before anything is written
//! (docs/campaign.md, "Adding releases"):
//!
//! - its condition stated: a campaign release names in its metadata its Mach, its altitude and
//!   every axis of the campaign's grid (`# mach = 0.8`, `# altitude_m = 3000`, ...); one that
//!   does not is refused, naming the keys missing. Before 2026-12-01 a release with no `# mach`
//!   line was recorded at the scenario's Mach (0.95 for the embedded default), a condition
//!   nobody flew;
//! - a condition outside the grid (beyond an axis's range, or off a quantity the grid holds
//!   fixed) is accepted, fitted and recorded with a note, said first;
//! - a release whose `# scenario_sha256` names another scenario than the campaign's flown at
//!   its condition (the hash `sepval simulate` writes: [`Scenario::content_hash`]) is refused,
//!   unless the user says it is another simulation of the same store (`--other-scenario`), when
//!   it is recorded with a note;
//! - [`overlap`]: a release that shares half or more of its samples (time and all six values,
//!   bit for bit) with one already flown or given beside it is the same flight counted twice
//!   (a copy thinned to every other row among them), refused naming both.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use sepval_common::scenario::{Flight, Scenario, hex_sha256};
use sepval_common::telemetry::Trajectory;
use sepval_common::telemetry::outliers::Policy;
use sepval_run::conditions::Quantity;
use sepval_run::inputs;

use sepval_common::scenario::Scenario as Base;
use sepval_envelope::grid::Grid;

use crate::CampaignError;
use crate::record::record_error;

/// What a release is read against: the campaign's scenario, the flags of its grid's axes and
/// its grid (a campaign's, `Campaign::against`, or those `init` is about to begin with, for a
/// pre-flight trajectory).
#[derive(Clone, Copy)]
pub struct Against<'a> {
    /// The scenario.
    pub scenario: &'a Base,
    /// The axes as given: (flag, `LO:HI:N`).
    pub axes: &'a [(String, String)],
    /// The grid.
    pub grid: &'a Grid,
}

/// A release to add, read and screened ([`NewRelease::read`]).
pub struct NewRelease {
    /// The file given.
    pub given: PathBuf,
    /// The SHA-256 of its bytes.
    pub sha256: String,
    /// Its samples (outliers dropped when asked).
    pub data: Trajectory,
    /// The campaign's scenario flown at its condition.
    pub scenario: Scenario,
    /// What is said of it first, and recorded with it: a condition outside the grid, another
    /// scenario accepted.
    pub notes: Vec<String>,
}

/// The metadata key of a quantity (the key `sepval simulate` writes).
pub fn key(q: Quantity) -> &'static str {
    match q {
        Quantity::Mach => "mach",
        Quantity::AltitudeM => "altitude_m",
        Quantity::AlphaDeg => "alpha_deg",
        Quantity::BetaDeg => "beta_deg",
        Quantity::GammaDeg => "gamma_deg",
    }
}

impl NewRelease {
    /// The release in `path`, read with `policy` (what it leaves out told through `tell`),
    /// flown at its own condition with the scenario of `c` (a campaign's, or the one `init`
    /// begins), whose store it must carry, and screened (module docs); `other_scenario`: a
    /// `# scenario_sha256` of another scenario is accepted with a note.
    pub fn read(
        path: &Path,
        c: Against<'_>,
        policy: Policy,
        other_scenario: bool,
        tell: inputs::Tell,
    ) -> Result<NewRelease, CampaignError> {
        let name = path.display().to_string();
        let input = |e: inputs::InputError| CampaignError::Inputs(Box::new(e));
        let bytes = std::fs::read(path).map_err(|e| record_error(path, e))?;
        let data = inputs::read(path, policy, tell).map_err(input)?;
        refuse_unstated(c, &data, &name)?;
        let flown = inputs::event_scenario(c.scenario, &data, &name).map_err(input)?;
        inputs::check_store(c.scenario, &data, &name, "the campaign's scenario").map_err(input)?;
        let mut notes = outside_grid(c, &flown.flight);
        if let Some(n) = other_scenario_note(&data, &flown, &name, other_scenario)? {
            notes.push(n);
        }
        Ok(NewRelease {
            given: path.to_path_buf(),
            sha256: hex_sha256(&bytes),
            data,
            scenario: flown,
            notes,
        })
    }
}

/// The quantities a campaign release must state: Mach, altitude and every axis of the grid.
fn required(c: Against<'_>) -> Vec<Quantity> {
    let mut q = vec![Quantity::Mach, Quantity::AltitudeM];
    for (flag, _) in c.axes {
        let axis = Quantity::ALL.iter().find(|a| a.flag() == flag);
        if let Some(a) = axis.filter(|a| !q.contains(a)) {
            q.push(*a);
        }
    }
    q
}

/// Refuses a release that does not state its condition (module docs).
fn refuse_unstated(c: Against<'_>, data: &Trajectory, name: &str) -> Result<(), CampaignError> {
    let missing: Vec<&str> = required(c)
        .into_iter()
        .map(key)
        .filter(|k| data.meta(k).is_none())
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    Err(crate::Refusal::Unstated {
        name: name.to_string(),
        missing: missing.into_iter().map(str::to_string).collect(),
    }
    .into())
}

/// The notes of a condition outside the campaign's grid: beyond an axis's range, or off the
/// value of a quantity the grid holds fixed.
fn outside_grid(c: Against<'_>, f: &Flight) -> Vec<String> {
    let conditions = &c.grid.conditions;
    let mut notes = Vec::new();
    for q in Quantity::ALL {
        let v = q.get(f);
        let axis = conditions.axes.iter().find(|(a, _)| *a == q);
        let (lo, hi) = match axis {
            Some((_, values)) => (values[0], values[values.len() - 1]),
            None => {
                let fixed = q.get(c.grid.flight(0));
                (fixed, fixed)
            }
        };
        let span = (hi - lo).abs().max(lo.abs()).max(1.0);
        if v < lo - 1e-9 * span || v > hi + 1e-9 * span {
            let (name, unit) = words(q);
            let grid = match axis {
                Some(_) => format!("{name} {}{unit} to {}{unit}", shown(lo), shown(hi)),
                None => format!("{name} {}{unit} at every condition", shown(lo)),
            };
            notes.push(format!(
                "{name} {}{unit} lies outside the campaign's grid ({grid}): the release is fitted and recorded, and the envelope is still predicted on the grid",
                shown(v)
            ));
        }
    }
    notes
}

/// A quantity's name and unit in a sentence.
fn words(q: Quantity) -> (&'static str, &'static str) {
    match q {
        Quantity::Mach => ("Mach", ""),
        Quantity::AltitudeM => ("altitude", " m"),
        Quantity::AlphaDeg => ("alpha", " deg"),
        Quantity::BetaDeg => ("beta", " deg"),
        Quantity::GammaDeg => ("gamma", " deg"),
    }
}

fn shown(v: f64) -> String {
    sepval_core::number_text::Shown(v).to_string()
}

/// The note (or the refusal) of a release whose `# scenario_sha256` names another scenario
/// than `flown`, the campaign's at its condition.
fn other_scenario_note(
    data: &Trajectory,
    flown: &Scenario,
    name: &str,
    accepted: bool,
) -> Result<Option<String>, CampaignError> {
    let Some(recorded) = data.meta("scenario_sha256") else {
        return Ok(None);
    };
    let ours = flown.content_hash();
    if recorded == ours {
        return Ok(None);
    }
    if accepted {
        Ok(Some(format!(
            "{name} was made with another scenario than the campaign's at its condition (its `# scenario_sha256` {recorded}, the campaign's {ours}): accepted as another simulation of the same store (--other-scenario)"
        )))
    } else {
        Err(crate::Refusal::OtherScenario {
            name: name.to_string(),
            recorded: recorded.to_string(),
            ours: ours.to_string(),
        }
        .into())
    }
}

/// One sample, bit for bit: its time and six values.
type SampleBits = [u64; 7];

fn sample_bits(t: &Trajectory) -> HashSet<SampleBits> {
    (0..t.len())
        .map(|i| {
            let mut b = [t.times_s[i].to_bits(), 0, 0, 0, 0, 0, 0];
            for k in 0..3 {
                b[1 + k] = t.pos_m[i][k].to_bits();
                b[4 + k] = t.att_deg[i][k].to_bits();
            }
            b
        })
        .collect()
}

/// The samples `a` and `b` share (time and every value, bit for bit), and whether they are
/// half or more of either's: the same flight, wholly or in part.
pub fn overlap(a: &Trajectory, b: &Trajectory) -> Option<usize> {
    let (small, large) = if a.len() <= b.len() { (a, b) } else { (b, a) };
    if small.is_empty() {
        return None;
    }
    let large = sample_bits(large);
    let shared = sample_bits(small)
        .iter()
        .filter(|s| large.contains(*s))
        .count();
    (2 * shared >= small.len()).then_some(shared)
}
