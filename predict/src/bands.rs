//! The bands (docs/prediction.md section 13.5): pointwise quantiles per channel of the samples
//! with every source added, and each source's share of the width.
//!
//! Sample s of model m_s has the trajectory y_s(t) (its factors drawn, [`crate::sampling`]);
//! the value whose quantiles make the band is
//!
//! ```text
//! v_s,c(t) = y_s,c(t) + a_s,c delta_c(t) + [with noise] b_s,c(t) sigma_c
//! ```
//!
//! with a_s,c one standard normal per sample and channel (the discrepancy is a smooth error
//! along the whole release, not white) and b_s,c(t) one per sample, channel and time (the
//! measurement noise is white), all from the sample's own generator (stream
//! [`crate::sampling::STREAM_BANDS`]). lo, mid and hi are the (1 - level)/2, 0.5 and
//! (1 + level)/2 quantiles of v over the samples that ran, interpolated between order
//! statistics (Hyndman and Fan's type 7).
//!
//! The shares: at each time and channel the variance of each source alone, *factors* the
//! weighted mean over the models of the variance of their samples, *rivals* the weighted
//! variance of the models' means, *discrepancy* delta_c(t)^2, *measurement* sigma_c^2 (with
//! noise); a source's share of a channel is its variance summed over time over the sum of all
//! four summed over time, and its share overall the mean of its shares over the six channels
//! (each channel counts alike, whatever its unit). The model form's share is that of the
//! rivals plus the discrepancy.

use serde::{Deserialize, Serialize};

use crate::discrepancy::{sigma, variance};
use crate::sampling::{STREAM_BANDS, normal, sample_rng};
use crate::simulate::GridTrajectory;
use sepval_fit::space::Noise;

/// One channel's band at every grid point.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ChannelBand {
    /// The lower quantile.
    pub lo: Vec<f64>,
    /// The median.
    pub mid: Vec<f64>,
    /// The upper quantile.
    pub hi: Vec<f64>,
}

/// Each source's share of the variance per channel (x, y, z, roll, pitch, yaw).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Shares {
    /// The factors' draws.
    pub factors: [f64; 6],
    /// The spread of the models' means (the rivals).
    pub rivals: [f64; 6],
    /// The discrepancy.
    pub discrepancy: [f64; 6],
    /// The measurement noise.
    pub measurement: [f64; 6],
}

impl Shares {
    /// The mean over the channels of one source's shares.
    pub fn overall(v: &[f64; 6]) -> f64 {
        v.iter().sum::<f64>() / 6.0
    }
}

/// The bands of a prediction.
#[derive(Debug, Clone)]
pub struct Bands {
    /// The six channels' bands.
    pub channels: [ChannelBand; 6],
    /// The shares of the sources.
    pub shares: Shares,
    /// Samples that ran (the others diverged or failed).
    pub used: usize,
}

/// What the bands are made of.
pub struct BandInputs<'a> {
    /// The models' weights.
    pub weights: &'a [f64],
    /// The discrepancy's standard deviation per grid point.
    pub discrepancy: &'a [[f64; 6]],
    /// The noise, when the measurement is a source.
    pub noise: Option<Noise>,
    /// The level.
    pub level: f64,
    /// The seed.
    pub seed: u64,
    /// Grid points.
    pub points: usize,
}

/// The bands and the shares of `samples` (per sample, its model and its trajectory, `None`
/// when it did not run), taken and turned into the values in place: the trajectories are held
/// once.
pub fn bands(inp: &BandInputs, samples: Vec<(usize, Option<GridTrajectory>)>) -> Bands {
    let ran: Vec<(u64, usize, GridTrajectory)> = samples
        .into_iter()
        .enumerate()
        .filter_map(|(s, (m, t))| t.map(|t| (s as u64, m, t)))
        .collect();
    let shares = shares(inp, &ran);
    let used = ran.len();
    let mut values: Vec<GridTrajectory> = Vec::with_capacity(used);
    for (s, _, mut v) in ran {
        let mut rng = sample_rng(inp.seed, s, STREAM_BANDS);
        let a: [f64; 6] = std::array::from_fn(|_| normal(&mut rng));
        for (k, p) in v.iter_mut().enumerate() {
            for c in 0..6 {
                p[c] += a[c] * inp.discrepancy[k][c];
                if let Some(noise) = inp.noise {
                    p[c] += normal(&mut rng) * sigma(noise, c);
                }
            }
        }
        values.push(v);
    }
    let (qlo, qhi) = ((1.0 - inp.level) / 2.0, (1.0 + inp.level) / 2.0);
    let mut channels: [ChannelBand; 6] = Default::default();
    let mut column = Vec::with_capacity(values.len());
    for k in 0..inp.points {
        for (c, band) in channels.iter_mut().enumerate() {
            column.clear();
            column.extend(values.iter().map(|v| v[k][c]));
            column.sort_by(f64::total_cmp);
            band.lo.push(quantile(&column, qlo));
            band.mid.push(quantile(&column, 0.5));
            band.hi.push(quantile(&column, qhi));
        }
    }
    Bands {
        channels,
        shares,
        used,
    }
}

/// The `q` quantile of sorted `v` (type 7: linear between order statistics).
pub fn quantile(v: &[f64], q: f64) -> f64 {
    match v.len() {
        0 => f64::NAN,
        1 => v[0],
        n => {
            let h = q * (n - 1) as f64;
            let i = (h.floor() as usize).min(n - 2);
            v[i] + (h - i as f64) * (v[i + 1] - v[i])
        }
    }
}

/// The shares of the sources (module docs).
fn shares(inp: &BandInputs, ran: &[(u64, usize, GridTrajectory)]) -> Shares {
    let models = inp.weights.len();
    let mut sums = [[0.0; 6]; 4];
    for k in 0..inp.points {
        for c in 0..6 {
            let mut means = Vec::with_capacity(models);
            let mut within = 0.0;
            let mut weight = 0.0;
            for m in 0..models {
                let vals: Vec<f64> = ran
                    .iter()
                    .filter(|(_, mm, _)| *mm == m)
                    .map(|(_, _, t)| t[k][c])
                    .collect();
                if vals.is_empty() {
                    continue;
                }
                let mean = vals.iter().sum::<f64>() / vals.len() as f64;
                within += inp.weights[m] * variance(vals.into_iter());
                weight += inp.weights[m];
                means.push((inp.weights[m], mean));
            }
            if weight <= 0.0 {
                continue;
            }
            let grand = means.iter().map(|(w, m)| w * m).sum::<f64>() / weight;
            let between = means
                .iter()
                .map(|(w, m)| w * (m - grand).powi(2))
                .sum::<f64>()
                / weight;
            sums[0][c] += within / weight;
            sums[1][c] += between;
            sums[2][c] += inp.discrepancy[k][c].powi(2);
            sums[3][c] += inp.noise.map_or(0.0, |n| sigma(n, c).powi(2));
        }
    }
    let share = |i: usize| -> [f64; 6] {
        std::array::from_fn(|c| {
            let total: f64 = sums.iter().map(|s| s[c]).sum();
            if total > 0.0 { sums[i][c] / total } else { 0.0 }
        })
    };
    Shares {
        factors: share(0),
        rivals: share(1),
        discrepancy: share(2),
        measurement: share(3),
    }
}
