//! The rivals still open, as the planning sees them at one condition (docs/campaign.md, "The
//! next release"): how far apart their predictions of the smallest clearance lie, and how well
//! a release there would tell them apart.
//!
//! The samples of a round are drawn from the diagnosis's answer or one of its rivals by their
//! weights ([`sepval_predict::Sampler`]), so at condition c each model m has its share w_m of
//! the samples. Both measures are computed on the factors' draws alone (no model-form band):
//!
//! - the rivals' spread of the smallest clearance, sqrt(sum_m w_m (d_m - d)^2), d_m the median
//!   smallest clearance of m's samples and d their weighted mean: the part of a condition's
//!   spread that only telling the rivals apart removes;
//! - their separation at c, a signal-to-noise ratio: per channel, the rivals' mean
//!   trajectories' weighted spread Delta(t) against what a single release cannot resolve within
//!   a model, the measurement noise and the spread of the model's own samples,
//!   S_ch^2 = mean_t Delta^2 / (sigma_noise^2 + sigma_within^2), and S = max_ch S_ch. The mean
//!   over time (not a sum over the samples) reads a release as one correlated observation, the
//!   cautious reading.
//!
//! A release at c is a linear-Gaussian measurement of which model holds: it leaves
//! 1 / (1 + S^2) of the rivals' variance at every condition ([`left_after`]), since the same
//! model holds everywhere (the normal model of the rival choice; Gelman et al., *Bayesian Data
//! Analysis*, 3rd ed., section 2.5, the posterior of a normal mean with known variance).

use sepval_fit::space::Noise;
use sepval_predict::simulate::GridTrajectory;

/// The fewest samples of a model for its median and mean to count.
pub const MIN_SAMPLES: usize = 5;

/// The rivals' spread of the smallest clearance \[mm\] (module docs): `models[s]` the model of
/// sample s, `closest_mm[s]` its smallest clearance on the factors' draws (`None`: it did not
/// run). 0 with one model.
pub fn clearance_spread(models: &[usize], closest_mm: &[Option<f64>]) -> f64 {
    let mut medians: Vec<(f64, f64)> = Vec::new();
    for m in distinct(models) {
        let mut d: Vec<f64> = models
            .iter()
            .zip(closest_mm)
            .filter(|(k, _)| **k == m)
            .filter_map(|(_, c)| *c)
            .filter(|c| c.is_finite())
            .collect();
        if d.len() < MIN_SAMPLES {
            continue;
        }
        d.sort_by(f64::total_cmp);
        medians.push((d.len() as f64, d[d.len() / 2]));
    }
    weighted_sd(&medians)
}

/// The rivals' separation S at a condition (module docs): `models[s]` the model of sample s,
/// `trajectories[s]` its trajectory at the band's points on the factors' draws (`None`: it did
/// not run), `noise` the measurement's. 0 with one model.
pub fn separation(models: &[usize], trajectories: &[Option<&GridTrajectory>], noise: Noise) -> f64 {
    let groups: Vec<Vec<&GridTrajectory>> = distinct(models)
        .into_iter()
        .map(|m| {
            models
                .iter()
                .zip(trajectories)
                .filter(|(k, _)| **k == m)
                .filter_map(|(_, t)| *t)
                .collect::<Vec<_>>()
        })
        .filter(|g| g.len() >= MIN_SAMPLES)
        .collect();
    let Some(points) = groups.first().map(|g| g[0].len()) else {
        return 0.0;
    };
    if groups.len() < 2 || points == 0 {
        return 0.0;
    }
    let sigma = [
        noise.pos_m,
        noise.pos_m,
        noise.pos_m,
        noise.att_deg,
        noise.att_deg,
        noise.att_deg,
    ];
    let mut best = 0.0_f64;
    for (ch, noise_sd) in sigma.iter().enumerate() {
        let mut sum = 0.0;
        for t in 0..points {
            // Per model: (its samples, their mean, their variance) at (t, ch).
            let stats: Vec<(f64, f64, f64)> = groups
                .iter()
                .map(|g| {
                    let v: Vec<f64> = g.iter().map(|x| x[t][ch]).collect();
                    let n = v.len() as f64;
                    let mean = v.iter().sum::<f64>() / n;
                    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
                    (n, mean, var)
                })
                .collect();
            let means: Vec<(f64, f64)> = stats.iter().map(|(n, m, _)| (*n, *m)).collect();
            let total: f64 = stats.iter().map(|s| s.0).sum();
            let within = stats.iter().map(|(n, _, v)| n * v).sum::<f64>() / total;
            let delta = weighted_sd(&means);
            let denominator = noise_sd * noise_sd + within;
            if denominator > 0.0 && delta.is_finite() {
                sum += delta * delta / denominator;
            }
        }
        best = best.max(sum / points as f64);
    }
    if best.is_finite() { best.sqrt() } else { 0.0 }
}

/// The share of the rivals' variance a release of separation `s` leaves (module docs).
pub fn left_after(s: f64) -> f64 {
    if s.is_finite() {
        1.0 / (1.0 + s * s)
    } else {
        1.0
    }
}

/// The models that occur in `models`, in order.
fn distinct(models: &[usize]) -> Vec<usize> {
    let mut m: Vec<usize> = models.to_vec();
    m.sort_unstable();
    m.dedup();
    m
}

/// The standard deviation of values weighted by counts: `(count, value)`.
fn weighted_sd(v: &[(f64, f64)]) -> f64 {
    let total: f64 = v.iter().map(|(w, _)| w).sum();
    if v.len() < 2 || total <= 0.0 {
        return 0.0;
    }
    let mean = v.iter().map(|(w, x)| w * x).sum::<f64>() / total;
    let var = v.iter().map(|(w, x)| w * (x - mean).powi(2)).sum::<f64>() / total;
    var.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    const NOISE: Noise = Noise {
        pos_m: 0.001,
        att_deg: 0.1,
    };

    /// `n` trajectories of `points` points at `z` m with a spread of `sd` m in z.
    fn model(n: usize, points: usize, z: f64, sd: f64) -> Vec<GridTrajectory> {
        (0..n)
            .map(|k| {
                let e = sd * if k % 2 == 0 { 1.0 } else { -1.0 };
                vec![[0.0, 0.0, z + e, 0.0, 0.0, 0.0]; points]
            })
            .collect()
    }

    #[test]
    fn one_model_has_no_spread_and_no_separation() {
        let t = model(10, 4, 0.1, 0.001);
        let refs: Vec<Option<&GridTrajectory>> = t.iter().map(Some).collect();
        let models = vec![0; 10];
        // Exactly nothing: one model has no rival to tell apart.
        assert!(separation(&models, &refs, NOISE).abs() < f64::MIN_POSITIVE);
        assert!(clearance_spread(&models, &[Some(30.0); 10]).abs() < f64::MIN_POSITIVE);
        assert!((left_after(0.0) - 1.0).abs() < f64::EPSILON);
    }

    #[test]
    fn rivals_far_apart_beyond_the_noise_are_told_apart_and_close_ones_are_not() {
        let models: Vec<usize> = (0..20).map(|k| usize::from(k >= 10)).collect();
        let far: Vec<GridTrajectory> = [model(10, 4, 0.10, 0.0), model(10, 4, 0.12, 0.0)].concat();
        let near: Vec<GridTrajectory> =
            [model(10, 4, 0.10, 0.0), model(10, 4, 0.1001, 0.0)].concat();
        fn refs(v: &[GridTrajectory]) -> Vec<Option<&GridTrajectory>> {
            v.iter().map(Some).collect()
        }
        // 10 mm apart each way of the mean against 1 mm of noise: S = 10.
        let s_far = separation(&models, &refs(&far), NOISE);
        assert!((s_far - 10.0).abs() < 1e-9, "{s_far}");
        assert!(left_after(s_far) < 0.01);
        let s_near = separation(&models, &refs(&near), NOISE);
        assert!(s_near < 0.1 && left_after(s_near) > 0.99, "{s_near}");
        // The models' own spread hides their difference as the noise does.
        let wide: Vec<GridTrajectory> =
            [model(10, 4, 0.10, 0.05), model(10, 4, 0.12, 0.05)].concat();
        assert!(separation(&models, &refs(&wide), NOISE) < 0.25);
        // Medians 20 and 40 mm, half the samples each: a spread of 10 mm.
        let closest: Vec<Option<f64>> = (0..20)
            .map(|k| Some(if k >= 10 { 40.0 } else { 20.0 }))
            .collect();
        assert!((clearance_spread(&models, &closest) - 10.0).abs() < 1e-12);
    }
}
