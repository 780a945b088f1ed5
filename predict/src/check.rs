//! The post-flight check (docs/prediction.md section 13.6): a release flown at the condition
//! predicted (`--data FLOWN.csv`) against the bands. The bands of a check include the
//! measurement (telemetry is compared, not the truth). Per channel: the fraction of the data's
//! samples inside the band, and where the data first *leave* it: the start of the first run
//! of at least [`MIN_RUN_FRACTION`] of the samples (and at least [`MIN_RUN_POINTS`])
//! consecutively outside. Isolated samples outside are what a band at a level below 1 lets
//! through (5 % of them at 95 %); a run that long is not. The verdict is "inside the predicted
//! bands" when no channel leaves, else "outside from t = T s in CHANNEL: the model does not
//! hold at this condition", T the earliest departure.

use serde::{Deserialize, Serialize};

use crate::bands::ChannelBand;
use crate::simulate::GridTrajectory;

/// A run outside shorter than this fraction of the samples is not a departure.
pub const MIN_RUN_FRACTION: f64 = 0.05;
/// A run outside shorter than this many samples is not a departure.
pub const MIN_RUN_POINTS: usize = 3;

/// The channels' names in files, in the order of a sample's values.
pub const CHANNEL_NAMES: [&str; 6] = ["x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg"];
/// The channels in words.
pub const CHANNEL_WORDS: [&str; 6] = [
    "downrange x",
    "crossrange y",
    "down z",
    "roll",
    "pitch",
    "yaw",
];

/// One channel of the check.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelCheck {
    /// The channel (`x_m`, ..., `yaw_deg`).
    pub channel: String,
    /// The fraction of the data's samples inside the band.
    pub inside: f64,
    /// When the data first leave the band \[s\] (null: they do not).
    pub leaves_at_s: Option<f64>,
    /// By how much at that time: the data minus the nearer edge, in the channel's unit.
    pub by: Option<f64>,
}

/// The post-flight check.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Check {
    /// The flown release.
    pub data: String,
    /// Whether the data stay inside the bands.
    pub inside: bool,
    /// The verdict in one sentence.
    pub verdict: String,
    /// Per channel.
    pub channels: Vec<ChannelCheck>,
}

/// The check of `data` (at the grid's points) against `bands`.
pub fn check(name: &str, data: &GridTrajectory, t_s: &[f64], bands: &[ChannelBand; 6]) -> Check {
    let n = data.len();
    let min_run = ((MIN_RUN_FRACTION * n as f64).ceil() as usize).max(MIN_RUN_POINTS);
    let channels: Vec<ChannelCheck> = (0..6)
        .map(|c| {
            let b = &bands[c];
            let outside: Vec<bool> = (0..n)
                .map(|k| !(data[k][c] >= b.lo[k] && data[k][c] <= b.hi[k]))
                .collect();
            let inside = outside.iter().filter(|o| !**o).count() as f64 / n.max(1) as f64;
            let start = first_run(&outside, min_run);
            ChannelCheck {
                channel: CHANNEL_NAMES[c].to_string(),
                inside,
                leaves_at_s: start.map(|k| t_s[k]),
                by: start.map(|k| {
                    let v = data[k][c];
                    if v > b.hi[k] {
                        v - b.hi[k]
                    } else {
                        v - b.lo[k]
                    }
                }),
            }
        })
        .collect();
    let first = channels
        .iter()
        .enumerate()
        .filter_map(|(c, ch)| ch.leaves_at_s.map(|t| (t, c)))
        .min_by(|a, b| a.0.total_cmp(&b.0));
    let verdict = match first {
        None => "inside the predicted bands".to_string(),
        Some((t, c)) => format!(
            "outside from t = {t:.2} s in {}: the model does not hold at this condition",
            CHANNEL_WORDS[c]
        ),
    };
    Check {
        data: name.to_string(),
        inside: first.is_none(),
        verdict,
        channels,
    }
}

/// The start of the first run of at least `min_run` consecutive `true`s.
fn first_run(outside: &[bool], min_run: usize) -> Option<usize> {
    let mut start = None;
    for (k, &o) in outside.iter().enumerate() {
        match (o, start) {
            (true, None) => start = Some(k),
            (false, Some(_)) => start = None,
            _ => {}
        }
        if let Some(s) = start
            && k + 1 - s >= min_run
        {
            return Some(s);
        }
    }
    None
}
