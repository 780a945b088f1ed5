//! Outliers in telemetry: samples of one channel that depart from the trend of their neighbours
//! by far more than the channel's noise (issue 33, item 7: one sample 10 m off steered an
//! update). Found before any fit, named (file, line, channel, size), then refused or dropped.
//!
//! The rule (docs/model.md section 6, "Outliers"), per channel (x, y, z, roll, pitch, yaw; the
//! angles unwrapped across +-180 deg first):
//! 1. Each sample is predicted by the least-squares quadratic in time through its
//!    [`NEIGHBOURS`] nearest samples not yet found to be outliers (three on each side, more on
//!    one side at the ends), itself left out: its *departure* r is the value minus that
//!    prediction. Divided by the square root of 1 + the prediction's variance factor (the
//!    deleted residual's standard deviation in units of the noise), it is the sample's *score*.
//! 2. The channel's noise scale s is 1.4826 times the median absolute deviation of the scores
//!    (a robust sigma: a few wild samples do not move it).
//! 3. A sample is an outlier when its score exceeds [`K_SIGMA`] s *and* its departure exceeds
//!    the channel's floor ([`FLOOR_POSITION_M`], [`FLOOR_ANGLE_DEG`]); the floor keeps
//!    noise-free records (s near 0) and the few samples beside a kink of the motion (the end of
//!    the ejector stroke) from being called outliers.
//! 4. The sample that exceeds its threshold most is taken out and its neighbours' departures
//!    computed again without it (a spike also pulls the trend of the samples beside it), until
//!    none exceeds, or a tenth of the channel's samples have been taken out.
//!
//! Records of fewer than `NEIGHBOURS + 1` samples are not screened.

use super::Trajectory;

/// Samples that predict each one (three on each side).
pub const NEIGHBOURS: usize = 6;
/// Robust sigmas a sample's score must exceed to be an outlier.
pub const K_SIGMA: f64 = 8.0;
/// The least departure from the trend of a position sample that is an outlier \[m\].
pub const FLOOR_POSITION_M: f64 = 0.5;
/// The least departure from the trend of an angle sample that is an outlier \[deg\].
pub const FLOOR_ANGLE_DEG: f64 = 5.0;

/// The six channels of a sample, by their names in SI.
pub const CHANNELS: [&str; 6] = ["x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg"];

/// What to do with outliers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Policy {
    /// Refuse the record, naming them.
    #[default]
    Refuse,
    /// Leave out every row that holds one (the sample's time, in every channel).
    Drop,
}

impl Policy {
    /// Whether this is the default ([`Policy::Refuse`]).
    pub fn is_refuse(&self) -> bool {
        *self == Policy::Refuse
    }
}

/// One outlier: a sample of one channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outlier {
    /// The sample (0-based).
    pub sample: usize,
    /// The channel (index into [`CHANNELS`]).
    pub channel: usize,
    /// Its value \[m or deg\].
    pub value: f64,
    /// Its departure from the trend of its neighbours \[m or deg\].
    pub departure: f64,
    /// The departure beyond which it is an outlier \[m or deg\].
    pub threshold: f64,
}

impl Outlier {
    /// The channel's unit.
    pub fn unit(&self) -> &'static str {
        if self.channel < 3 { "m" } else { "deg" }
    }
}

/// The outliers of `t`, in sample order (then channel).
pub fn find(t: &Trajectory) -> Vec<Outlier> {
    let mut found = Vec::new();
    if t.len() <= NEIGHBOURS {
        return found;
    }
    for channel in 0..6 {
        let values: Vec<f64> = (0..t.len())
            .map(|k| {
                if channel < 3 {
                    t.pos_m[k][channel]
                } else {
                    t.att_deg[k][channel - 3]
                }
            })
            .collect();
        let unwrapped = if channel < 3 {
            values.clone()
        } else {
            unwrap_deg(&values)
        };
        let floor = if channel < 3 {
            FLOOR_POSITION_M
        } else {
            FLOOR_ANGLE_DEG
        };
        for (sample, departure, threshold) in in_channel(&t.times_s, &unwrapped, floor) {
            found.push(Outlier {
                sample,
                channel,
                value: values[sample],
                departure,
                threshold,
            });
        }
    }
    found.sort_by_key(|o| (o.sample, o.channel));
    found
}

/// `t` without the rows of `outliers`.
pub fn without(t: &Trajectory, outliers: &[Outlier]) -> Trajectory {
    let mut out = Trajectory {
        metadata: t.metadata.clone(),
        comments: t.comments.clone(),
        ..Trajectory::default()
    };
    let mut dropped = vec![false; t.len()];
    for o in outliers {
        if let Some(d) = dropped.get_mut(o.sample) {
            *d = true;
        }
    }
    for k in (0..t.len()).filter(|&k| !dropped[k]) {
        out.times_s.push(t.times_s[k]);
        out.pos_m.push(t.pos_m[k]);
        out.att_deg.push(t.att_deg[k]);
    }
    out
}

/// Angles made continuous: each step taken the short way round.
pub fn unwrap_deg(values: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(values.len());
    for (k, &v) in values.iter().enumerate() {
        match k {
            0 => out.push(v),
            _ => {
                let step = (v - values[k - 1] + 180.0).rem_euclid(360.0) - 180.0;
                out.push(out[k - 1] + step);
            }
        }
    }
    out
}

/// The outliers of one channel: (sample, departure, threshold).
fn in_channel(times: &[f64], values: &[f64], floor: f64) -> Vec<(usize, f64, f64)> {
    let n = values.len();
    let mut valid = vec![true; n];
    let fits: Vec<Option<Fit>> = (0..n).map(|k| fit(times, values, &valid, k)).collect();
    let mut scores: Vec<f64> = fits.iter().flatten().map(|f| f.score()).collect();
    let s = 1.4826 * median_absolute_deviation(&mut scores);
    let threshold = |f: &Fit| (K_SIGMA * s * f.spread).max(floor);
    // Candidates by how far they exceed their threshold (a ratio > 1 orders as its bits).
    let exceeds = |f: &Fit| {
        let ratio = f.departure.abs() / threshold(f);
        (ratio > 1.0).then(|| ratio.to_bits())
    };
    let mut heap: std::collections::BinaryHeap<(u64, usize)> = fits
        .iter()
        .enumerate()
        .filter_map(|(k, f)| f.as_ref().and_then(&exceeds).map(|r| (r, k)))
        .collect();
    let mut found = Vec::new();
    while let Some((ratio, k)) = heap.pop() {
        if found.len() >= n / 10 {
            break;
        }
        if !valid[k] {
            continue;
        }
        // Its neighbours may have changed since it was queued: judged on its fit now.
        let Some(f) = fit(times, values, &valid, k) else {
            continue;
        };
        match exceeds(&f) {
            Some(now) if now == ratio => {}
            Some(now) => {
                heap.push((now, k));
                continue;
            }
            None => continue,
        }
        found.push((k, f.departure, threshold(&f)));
        valid[k] = false;
        // The samples whose neighbours may include k: queued again if they exceed now (two
        // wild samples side by side hide each other until one is out).
        let (mut lo, mut hi, mut left, mut right) = (k, k, 0, 0);
        while lo > 0 && left < NEIGHBOURS {
            lo -= 1;
            left += usize::from(valid[lo]);
        }
        while hi + 1 < n && right < NEIGHBOURS {
            hi += 1;
            right += usize::from(valid[hi]);
        }
        for j in lo..=hi {
            if valid[j] {
                if let Some(r) = fit(times, values, &valid, j).as_ref().and_then(&exceeds) {
                    heap.push((r, j));
                }
            }
        }
    }
    found.sort_by_key(|f| f.0);
    found
}

/// A sample's departure from the quadratic through its neighbours, and the standard deviation
/// of that departure in units of the noise (sqrt(1 + the prediction's variance factor)).
#[derive(Debug, Clone, Copy)]
pub struct Fit {
    /// The value minus the quadratic's prediction.
    pub departure: f64,
    /// The departure's standard deviation in units of the noise.
    pub spread: f64,
}

impl Fit {
    /// The departure in units of its spread.
    pub fn score(&self) -> f64 {
        self.departure / self.spread
    }
}

/// The fit of sample `k` from its [`NEIGHBOURS`] nearest valid samples (none when there are
/// too few, or the quadratic is not determined).
pub fn fit(times: &[f64], values: &[f64], valid: &[bool], k: usize) -> Option<Fit> {
    let mut before = (0..k).rev().filter(|&j| valid[j]);
    let mut after = (k + 1..values.len()).filter(|&j| valid[j]);
    let mut picked: Vec<usize> = Vec::with_capacity(NEIGHBOURS);
    picked.extend(before.by_ref().take(NEIGHBOURS / 2));
    picked.extend(after.by_ref().take(NEIGHBOURS / 2));
    let short = NEIGHBOURS - picked.len();
    picked.extend(before.take(short));
    let short = NEIGHBOURS - picked.len();
    picked.extend(after.take(short));
    if picked.len() < NEIGHBOURS {
        return None;
    }
    let span = picked
        .iter()
        .map(|&j| (times[j] - times[k]).abs())
        .fold(0.0, f64::max);
    if span <= 0.0 {
        return None;
    }
    // Normal equations of y = a + b u + c u^2, u = (t - t_k) / span.
    let mut m = [[0.0; 3]; 3];
    let mut rhs = [0.0; 3];
    for &j in &picked {
        let u = (times[j] - times[k]) / span;
        let basis = [1.0, u, u * u];
        for r in 0..3 {
            for c in 0..3 {
                m[r][c] += basis[r] * basis[c];
            }
            rhs[r] += basis[r] * values[j];
        }
    }
    let inverse = invert3(&m)?;
    let a: f64 = (0..3).map(|c| inverse[0][c] * rhs[c]).sum();
    Some(Fit {
        departure: values[k] - a,
        spread: (1.0 + inverse[0][0]).sqrt(),
    })
}

/// The inverse of a 3x3 matrix (none when it is singular to working precision).
fn invert3(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let cof =
        |r0: usize, r1: usize, c0: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    let adj = [
        [cof(1, 2, 1, 2), -cof(0, 2, 1, 2), cof(0, 1, 1, 2)],
        [-cof(1, 2, 0, 2), cof(0, 2, 0, 2), -cof(0, 1, 0, 2)],
        [cof(1, 2, 0, 1), -cof(0, 2, 0, 1), cof(0, 1, 0, 1)],
    ];
    let det: f64 = (0..3).map(|c| m[0][c] * adj[c][0]).sum();
    let scale = m.iter().flatten().fold(0.0_f64, |a, v| a.max(v.abs()));
    if !det.is_finite() || det.abs() <= 1e-12 * scale.powi(3) {
        return None;
    }
    Some(adj.map(|row| row.map(|v| v / det)))
}

/// The median absolute deviation from the median of `x` (reordered; 0 when empty).
fn median_absolute_deviation(x: &mut [f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    let centre = median(x);
    for v in x.iter_mut() {
        *v = (*v - centre).abs();
    }
    median(x)
}

fn median(x: &mut [f64]) -> f64 {
    let mid = x.len() / 2;
    let (_, m, _) = x.select_nth_unstable_by(mid, f64::total_cmp);
    *m
}
