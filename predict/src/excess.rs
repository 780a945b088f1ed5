//! The excess of one release over time (docs/prediction.md section 13.4, steps 2 to 5 of
//! [`crate::discrepancy`]'s rule): squared errors beyond the factor band and the noise,
//! smoothed by a moving window that is empty at carriage and symmetric after release, with what
//! the noise and the fit's own factor spread alone would give each window's mean, and read at
//! any time after release.

use sepval_fit::space::Noise;

/// How many standard deviations of noise alone the smoothed excess must exceed to count.
pub const SIGNIFICANCE: f64 = 2.0;

/// The noise of channel `c`.
pub fn sigma(noise: Noise, c: usize) -> f64 {
    if c < 3 { noise.pos_m } else { noise.att_deg }
}

/// The excess of one release, smoothed, on its own times, with what noise and the factors'
/// spread alone would give it.
pub(crate) struct Excess {
    /// Its times \[s\].
    pub t_s: Vec<f64>,
    /// The smoothed excess at each time.
    pub value: Vec<[f64; 6]>,
    /// At each point, [`SIGNIFICANCE`] standard deviations of its window's mean of
    /// e^2 - v - sigma^2 when the model's form is right ([`threshold`]; 0 where nothing is
    /// subtracted).
    pub threshold: Vec<[f64; 6]>,
}

impl Excess {
    /// `raw` on times `t_s` smoothed ([`smooth`]), with the thresholds ([`threshold`]) of noise
    /// `noise` (none when `None`) and of the factor variance `v` at each point (none when
    /// `None`: the answer's own misfit on the releases it was fitted to).
    pub(crate) fn smoothed(
        t_s: &[f64],
        raw: &[[f64; 6]],
        noise: Option<Noise>,
        v: Option<&[[f64; 6]]>,
    ) -> Excess {
        let (value, widths) = smooth(t_s, raw);
        let v_bar = v.map(|v| smooth(t_s, v).0);
        let threshold = widths
            .iter()
            .enumerate()
            .map(|(k, &w)| {
                std::array::from_fn(|c| {
                    let s2 = noise.map_or(0.0, |n| sigma(n, c).powi(2));
                    let v = v_bar.as_ref().map_or(0.0, |v| v[k][c].max(0.0));
                    threshold(s2, v, w)
                })
            })
            .collect();
        Excess {
            t_s: t_s.to_vec(),
            value,
            threshold,
        }
    }
}

/// [`SIGNIFICANCE`] standard deviations of a window's mean of e^2 - v - sigma^2 (W points,
/// `w`) when the model's form is right: e = a + n, the factors' error a ~ N(0, v) and the
/// noise n ~ N(0, sigma^2) white. The noise averages over the window (2 sigma^4 / W), but a is
/// one draw of the fit's parameters, smooth in time, nearly the same across the window: its
/// a^2 - v keeps its variance 2 v^2 whatever W, and the cross term gives 4 v sigma^2 / W. So
/// SIGNIFICANCE sqrt(2 v^2 + (2 sigma^4 + 4 v sigma^2) / W); with v = 0, the noise's
/// SIGNIFICANCE sigma^2 sqrt(2 / W) as before; 0 for an empty window (issue 37: without the
/// 2 v^2, one refit's parameter error at a release left out, a draw from its own band, counted
/// as the model's form, and the bands of a model whose form is right were 17 to 65 times its
/// error).
pub fn threshold(sigma2: f64, v: f64, w: f64) -> f64 {
    if w <= 0.0 {
        return 0.0;
    }
    SIGNIFICANCE * (2.0 * v * v + (2.0 * sigma2 * sigma2 + 4.0 * v * sigma2) / w).sqrt()
}

/// The mean of `excesses` at time `t` on channel `c` less what chance gives it, the noise and
/// the fits' own factor spread (their mean [`threshold`] over the square root of their
/// number), at least 0; 0 without any.
pub(crate) fn beyond_chance(excesses: &[Excess], t: f64, c: usize) -> f64 {
    if excesses.is_empty() {
        return 0.0;
    }
    let j = excesses.len() as f64;
    let mean = excesses
        .iter()
        .map(|e| at_time(&e.t_s, &e.value, t, c))
        .sum::<f64>()
        / j;
    let tau = excesses
        .iter()
        .map(|e| at_time(&e.t_s, &e.threshold, t, c))
        .sum::<f64>()
        / j;
    (mean - tau / j.sqrt()).max(0.0)
}

/// The moving average of each channel of `raw` (on times `t_s`) over +-10 % of the points (at
/// least one), and each point's window width in points. At and before release (t <= 0) the
/// state is known (carriage): 0 there, width 0. After it the window stays symmetric, narrowing
/// towards the first point after release, so that what the model gets wrong later does not
/// leak back to the release; near the end it is cut off one-sided.
fn smooth(t_s: &[f64], raw: &[[f64; 6]]) -> (Vec<[f64; 6]>, Vec<f64>) {
    let n = raw.len();
    let h = (n / 10).max(1);
    let first = t_s.partition_point(|&t| t <= 0.0);
    let mut prefix = vec![[0.0; 6]; n + 1];
    for k in 0..n {
        for c in 0..6 {
            prefix[k + 1][c] = prefix[k][c] + raw[k][c];
        }
    }
    (0..n)
        .map(|k| {
            if k < first {
                return ([0.0; 6], 0.0);
            }
            let half = h.min(k - first);
            let (a, b) = (k - half, (k + half + 1).min(n));
            let mean = std::array::from_fn(|c| (prefix[b][c] - prefix[a][c]) / (b - a) as f64);
            (mean, (b - a) as f64)
        })
        .unzip()
}

/// The excess of channel `c` at time `t` (linear between points, held beyond the ends).
fn at_time(t_s: &[f64], series: &[[f64; 6]], t: f64, c: usize) -> f64 {
    let n = t_s.len();
    if n == 0 {
        return 0.0;
    }
    let k = t_s.partition_point(|&s| s < t);
    if k == 0 {
        return series[0][c];
    }
    if k >= n {
        return series[n - 1][c];
    }
    let (t0, t1) = (t_s[k - 1], t_s[k]);
    let w = if t1 > t0 { (t - t0) / (t1 - t0) } else { 1.0 };
    series[k - 1][c] * (1.0 - w) + series[k][c] * w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_threshold_is_the_noises_without_factor_spread_and_keeps_the_spread_in_long_windows() {
        // No spread: the noise's SIGNIFICANCE sigma^2 sqrt(2 / W).
        let (s2, w) = (0.01_f64, 40.0);
        let noise_only = threshold(s2, 0.0, w);
        assert!((noise_only - SIGNIFICANCE * s2 * (2.0 / w).sqrt()).abs() < 1e-15);
        // A factor spread v: its 2 v^2 does not average away however long the window.
        let v = 0.04;
        for w in [10.0, 1e3, 1e9] {
            assert!(threshold(s2, v, w) >= SIGNIFICANCE * 2f64.sqrt() * v);
        }
        assert!((threshold(s2, v, 1e12) - SIGNIFICANCE * 2f64.sqrt() * v).abs() < 1e-9);
        // An empty window (at carriage) subtracts nothing.
        assert_eq!(threshold(s2, v, 0.0).to_bits(), 0.0_f64.to_bits());
    }
}
