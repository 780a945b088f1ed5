//! The campaign's records (docs/campaign.md, "Files"): CAMP/campaign.json (the settings, the
//! grid, the releases flown, the rounds: the program's record, written last by every command
//! that changes it, so that it is the commit), each round's CAMP/rounds/NN/assessment.json,
//! CAMP/next.json (each sealed part by part, [`crate::seal`], and refused when edited) and
//! CAMP/status.json (derived, never read back). campaign.json records the SHA-256 of each
//! release's copy and of each round's assessment, so that a copy edited or an assessment
//! replaced by another (itself sealed) is refused too.

use std::path::Path;

use serde::{Deserialize, Serialize};

use sepval_core::atomic_file::write_atomically;
use sepval_predict::record::ConditionRecord;

use crate::CampaignError;
use crate::begin::Narrowing;
use crate::next::Planned;
use crate::prior::Prior;
use crate::state::{Assessed, Counts};

/// The format of campaign.json.
pub const CAMPAIGN_FORMAT: &str = "sepval-campaign/1";
/// The format of next.json.
pub const NEXT_FORMAT: &str = "sepval-campaign-next/1";
/// The format of status.json.
pub const STATUS_FORMAT: &str = "sepval-campaign-status/1";
/// The format of a round's assessment.json.
pub const ASSESSMENT_FORMAT: &str = "sepval-campaign-assessment/1";

/// A file the campaign reads each time, with its SHA-256 when the campaign began.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InputRecord {
    /// Its absolute path.
    pub path: String,
    /// Its SHA-256.
    pub sha256: String,
}

/// The settings of the campaign, fixed by `init`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SettingsRecord {
    /// The scenario (none: the embedded default).
    pub scenario: Option<InputRecord>,
    /// The aircraft's geometry.
    pub aircraft: InputRecord,
    /// The store's shape (none: the scenario's default shape).
    pub store_shape: Option<InputRecord>,
    /// The axes as given: (flag, `LO:HI:N`).
    pub axes: Vec<(String, String)>,
    /// The clearance criterion \[mm\].
    pub clearance_mm: f64,
    /// The largest probability of failing at which a condition is cleared (and of clearing at
    /// which it fails).
    pub allowed: f64,
    /// The largest probability of failing at which a release may be flown.
    pub fly_risk: f64,
    /// Samples per condition.
    pub samples: usize,
    /// The seed.
    pub seed: u64,
    /// GA generations of each round's fit.
    pub generations: usize,
    /// The prior.
    pub prior: Prior,
}

/// A release flown.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReleaseRecord {
    /// Its copy in the campaign (`releases/NN.csv`, as read: outliers dropped when asked).
    pub file: String,
    /// The file it was given as.
    pub given: String,
    /// The SHA-256 of the file given.
    pub sha256: String,
    /// The SHA-256 of its copy in the campaign (`file`), checked whenever it is read.
    pub copy_sha256: String,
    /// Its condition.
    pub condition: ConditionRecord,
    /// The round that added it.
    pub round: usize,
    /// Whether it stayed inside the bands the campaign predicted for it.
    pub inside: bool,
    /// The post-flight check in one sentence.
    pub check: String,
    /// What `add` said of it first: a condition outside the grid, a release made with
    /// another scenario (empty when nothing).
    pub notes: Vec<String>,
}

/// One round: the envelope after a number of releases.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RoundRecord {
    /// Its number (0: the prior's).
    pub round: usize,
    /// Releases flown by then.
    pub releases_flown: usize,
    /// The counts of its states.
    pub counts: Counts,
    /// Whether the envelope was settled.
    pub settled: bool,
    /// Its directory in the campaign (`rounds/NN`).
    pub dir: String,
    /// The SHA-256 of its `assessment.json`, checked whenever it is read.
    pub assessment_sha256: String,
    /// Samples its envelope flew: conditions times samples (the diagnosis's, the discrepancy's
    /// calibration's and the post-flight check's simulations are not counted).
    pub evaluations: u64,
    /// Wall time \[s\].
    pub wall_s: f64,
}

/// CAMP/campaign.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CampaignFile {
    /// [`CAMPAIGN_FORMAT`].
    pub format: String,
    /// The settings.
    pub settings: SettingsRecord,
    /// The grid's conditions, in grid order.
    pub grid: Vec<ConditionRecord>,
    /// The releases flown, in order.
    pub releases: Vec<ReleaseRecord>,
    /// The rounds, in order.
    pub rounds: Vec<RoundRecord>,
    /// Whether the envelope is settled.
    pub settled: bool,
    /// What is settled or not, in words.
    pub words: String,
    /// The version of sepval that wrote it.
    pub version: String,
}

/// CAMP/status.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StatusFile {
    /// [`STATUS_FORMAT`].
    pub format: String,
    /// Releases flown.
    pub releases_flown: usize,
    /// Conditions.
    pub conditions: usize,
    /// Cleared.
    pub cleared: usize,
    /// Failing.
    pub fails: usize,
    /// Undecided.
    pub undecided: usize,
    /// Settled.
    pub settled: bool,
}

/// CAMP/next.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NextFile {
    /// [`NEXT_FORMAT`].
    pub format: String,
    /// The round planned from.
    pub round: usize,
    /// The releases to fly, best first.
    pub releases: Vec<Planned>,
    /// When none is safe to fly: the least risky condition.
    pub least_risky: Option<Planned>,
    /// Whether the envelope is settled.
    pub settled: bool,
    /// In words.
    pub words: String,
    /// When none is safe to fly under the prior: what would make the least risky safe to fly.
    #[serde(default)]
    pub narrowing: Option<Narrowing>,
}

/// The error of a file or directory of the campaign.
pub fn record_error(path: &Path, message: impl std::fmt::Display) -> CampaignError {
    CampaignError::Record {
        path: path.display().to_string(),
        message: message.to_string(),
    }
}

/// A round's CAMP/rounds/NN/assessment.json: every condition of the grid, in grid order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AssessmentFile {
    /// [`ASSESSMENT_FORMAT`].
    pub format: String,
    /// The conditions.
    pub conditions: Vec<Assessed>,
    /// Under the prior with no condition safe to fly: what would make the least risky safe to
    /// fly ([`crate::begin`]).
    #[serde(default)]
    pub narrowing: Option<Narrowing>,
}

/// Writes `value` as pretty JSON to `path`, atomically (an output no command reads back).
pub fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<(), CampaignError> {
    let text = serde_json::to_string_pretty(value).map_err(|e| record_error(path, e))? + "\n";
    write_atomically(path, text.as_bytes()).map_err(|e| record_error(path, e))
}

/// Refuses the file at `path` unless its SHA-256 is `recorded` (campaign.json's): a release's
/// copy or a round's assessment changed or replaced since the campaign wrote it.
pub fn check_recorded(path: &Path, recorded: &str) -> Result<Vec<u8>, CampaignError> {
    let bytes = std::fs::read(path).map_err(|e| record_error(path, e))?;
    let now = sepval_common::scenario::hex_sha256(&bytes);
    if now != recorded {
        return Err(CampaignError::Changed {
            path: path.display().to_string(),
            recorded: recorded.to_string(),
            now,
        });
    }
    Ok(bytes)
}
