//! What a release at one condition tells of another, read from the round's samples
//! (docs/campaign.md, "The next release"). The samples of a round are the same draws at every
//! condition (of the prior, or of the diagnosis's answer and rivals), so their trajectories at
//! condition c and their smallest clearances at condition u are draws of one joint
//! distribution. A release at c measures c's trajectory; what that says of u's clearance is the
//! linear-Gaussian (Bayes linear) adjustment of u's clearance by c's trajectory features
//! (Goldstein and Wooff, *Bayes Linear Statistics*, 2007, ch. 3; the ensemble Kalman update of
//! Evensen, *Data Assimilation*, 2nd ed., 2009, ch. 9, is the same formula on samples):
//!
//! - per sample s: y_s the smallest clearance at u on the factors' draws \[mm\] (a sample that
//!   did not run at u, which tumbles there, is read as 0: a failure), and f_s the trajectory at
//!   c at [`TIMES`] points (a third, two thirds and the end of the band's points), x, y, z over
//!   the position noise and roll, pitch, yaw over the attitude noise (the diagnosis's noise, or
//!   the synthetic flight test's before any release): [`FEATURES`] numbers in units of the
//!   noise, so the measurement's noise covariance is the identity (the first [`MAX_KEPT`]
//!   samples of a round are kept, so that a large round's record stays small);
//! - releases at the conditions S measure f = (f_c, c in S) with that noise: u's clearance
//!   variance left is Var(y) - Cov(y, f) (Cov(f) + I)^-1 Cov(f, y), over the samples that ran
//!   at every c of S;
//! - the share left, 1 - R^2, is read with the adjusted R^2's degrees of freedom, (1 - R^2)
//!   (n - 1) / (n - p - 1) with p the features, n the samples, and at most 1: a share learnt
//!   from n samples is not over-claimed.
//!
//! A release measures more than these features (every sample of its trajectory, where the fit
//! takes its factors from), so the share left is an upper bound of what a release leaves, within
//! the linear reading; the model form, which differs from one condition to another, is not in
//! the samples and is the reach rule's ([`crate::next`]).

use nalgebra::{DMatrix, DVector};
use sepval_common::noise::{SIGMA_ATT_DEG, SIGMA_POS_M};
use sepval_fit::space::Noise;
use sepval_predict::simulate::GridTrajectory;

/// The trajectory points a sample's features are taken at.
pub const TIMES: usize = 3;
/// The features of a sample's trajectory: six channels at [`TIMES`] points.
pub const FEATURES: usize = 6 * TIMES;

/// One sample at one condition: its smallest clearance on the factors' draws \[mm\], then its
/// trajectory's [`FEATURES`] in units of the noise, each rounded to [`RESOLUTION`] (a
/// thousandth of a millimetre, of the noise: far below what a release resolves) so that the
/// record stays short and reads back to the same bits.
pub type Sample = [f64; 1 + FEATURES];

/// What a [`Sample`]'s numbers are rounded to.
pub const RESOLUTION: f64 = 1e-3;

fn rounded(v: f64) -> f64 {
    (v / RESOLUTION).round() * RESOLUTION
}

/// The noise the features are measured in before any release: the synthetic flight test's.
pub const PRIOR_NOISE: Noise = Noise {
    pos_m: SIGMA_POS_M,
    att_deg: SIGMA_ATT_DEG,
};

/// The most samples kept per condition: the first of the round's draws (independent and
/// seeded, so the first are as fair a sample as any), enough for a batch of up to 100 releases'
/// features ([`MIN_SAMPLES_BEYOND_FEATURES`] beyond them) while an assessment of 100 000
/// samples a condition does not grow by gigabytes.
pub const MAX_KEPT: usize = 2_000;

/// Each sample's [`Sample`] at a condition, the first [`MAX_KEPT`]: `trajectories[s]` at the
/// band's points (`None`: it did not run), `closest_mm[s]` its smallest clearance on the
/// factors' draws.
pub fn samples(
    trajectories: &[Option<&GridTrajectory>],
    closest_mm: &[Option<f64>],
    noise: Noise,
) -> Vec<Option<Sample>> {
    trajectories
        .iter()
        .zip(closest_mm)
        .take(MAX_KEPT)
        .map(|(t, c)| {
            let t = (*t)?;
            if t.is_empty() {
                return None;
            }
            let mut s: Sample = [0.0; 1 + FEATURES];
            s[0] = rounded(c.filter(|c| c.is_finite()).unwrap_or(0.0));
            for j in 0..TIMES {
                let point = &t[(t.len() * (j + 1)).div_ceil(TIMES) - 1];
                for ch in 0..6 {
                    let sigma = if ch < 3 { noise.pos_m } else { noise.att_deg };
                    s[1 + 6 * j + ch] = rounded(point[ch] / sigma);
                }
            }
            s.iter().all(|v| v.is_finite()).then_some(s)
        })
        .collect()
}

/// The fewest samples, beyond the features, for a share to be read.
pub const MIN_SAMPLES_BEYOND_FEATURES: usize = 20;

/// Releases at the conditions `at` measured; the share of each condition `u`'s factors'
/// variance of its smallest clearance they leave, from each condition's joint samples `joint`
/// (an assessment's [`crate::state::Assessed::joint`]; module docs). `None` when a condition
/// holds no joint samples (a record written before they were kept) or too few samples ran at
/// every condition of `at`.
pub fn left_after(joint: &[&[Option<Sample>]], at: &[usize], u: &[usize]) -> Option<Vec<f64>> {
    if at.is_empty() {
        return Some(vec![1.0; u.len()]);
    }
    let n_samples = joint[at[0]].len();
    let all = at.iter().chain(u);
    if n_samples == 0 || all.clone().any(|&k| joint[k].len() != n_samples) {
        return None;
    }
    // The samples that ran at every release's condition.
    let rows: Vec<usize> = (0..n_samples)
        .filter(|&s| at.iter().all(|&c| joint[c][s].is_some()))
        .collect();
    let (n, p) = (rows.len(), FEATURES * at.len());
    if n < p + MIN_SAMPLES_BEYOND_FEATURES {
        return None;
    }
    let mut f = DMatrix::<f64>::from_fn(n, p, |i, j| {
        let sample = joint[at[j / FEATURES]][rows[i]].expect("ran");
        sample[1 + j % FEATURES]
    });
    for mut col in f.column_iter_mut() {
        let mean = col.mean();
        col.add_scalar_mut(-mean);
    }
    let dof = (n - 1) as f64;
    let cov = (f.transpose() * &f) / dof + DMatrix::identity(p, p);
    let chol = cov.cholesky()?;
    let shares = u
        .iter()
        .map(|&k| {
            let mut y = DVector::<f64>::from_fn(n, |i, _| {
                // A sample that did not run at u tumbles there: a failure, 0 mm.
                joint[k][rows[i]].map_or(0.0, |s| s[0])
            });
            let mean = y.mean();
            y.add_scalar_mut(-mean);
            let var = y.norm_squared() / dof;
            if var <= 0.0 {
                return 1.0;
            }
            let b = f.transpose() * &y / dof;
            let explained = b.dot(&chol.solve(&b));
            let left = (1.0 - explained / var).max(0.0);
            (left * dof / (n - p - 1) as f64).min(1.0)
        })
        .collect();
    Some(shares)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn share_left(joint: &[Vec<Option<Sample>>], at: &[usize], u: &[usize]) -> Option<Vec<f64>> {
        let joint: Vec<&[Option<Sample>]> = joint.iter().map(Vec::as_slice).collect();
        left_after(&joint, at, u)
    }

    /// Two conditions whose clearance and first feature are `a x + b z` and `c x + d z` for
    /// draws x, z (a feature in units of the noise, so large against 1).
    fn pair(a: f64, b: f64, c: f64, d: f64) -> Vec<Vec<Option<Sample>>> {
        // Two low-discrepancy sequences (the golden ratio's and the plastic number's), unrelated.
        let draws: Vec<(f64, f64)> = (0..400)
            .map(|k| {
                let k = k as f64;
                (
                    2.0 * (k * 0.618_033_988_75).fract() - 1.0,
                    2.0 * (k * 0.754_877_666_25).fract() - 1.0,
                )
            })
            .collect();
        let of = |p: f64, q: f64| {
            draws
                .iter()
                .map(|(x, z)| {
                    let mut s = [0.0; 1 + FEATURES];
                    s[0] = p * x + q * z;
                    s[1] = 100.0 * (p * x + q * z);
                    Some(s)
                })
                .collect()
        };
        vec![of(a, b), of(c, d)]
    }

    #[test]
    fn a_release_tells_what_it_shares_with_another_condition_and_nothing_else() {
        // The same combination at both: a release at one leaves almost nothing at the other.
        let a = pair(1.0, 0.5, 2.0, 1.0);
        let left = share_left(&a, &[0], &[1]).unwrap()[0];
        assert!(left < 0.01, "{left}");
        // Independent combinations: a release at one leaves nearly everything at the other.
        let a = pair(1.0, 0.0, 0.0, 1.0);
        let left = share_left(&a, &[0], &[1]).unwrap()[0];
        assert!(left > 0.9, "{left}");
        // Half shared: about half left (cos^2 of 45 deg).
        let a = pair(1.0, 0.0, 1.0, 1.0);
        let left = share_left(&a, &[0], &[1]).unwrap()[0];
        assert!((0.4..0.6).contains(&left), "{left}");
        // Nothing measured: everything left; no joint samples: no answer.
        assert_eq!(share_left(&a, &[], &[1]), Some(vec![1.0]));
        assert_eq!(share_left(&[Vec::new(), Vec::new()], &[0], &[1]), None);
    }

    #[test]
    fn features_are_taken_at_a_third_two_thirds_and_the_end_in_units_of_the_noise() {
        let t: GridTrajectory = (0..9).map(|k| [k as f64; 6]).collect();
        let noise = Noise {
            pos_m: 0.5,
            att_deg: 2.0,
        };
        let s = samples(&[Some(&t), None], &[Some(12.0), None], noise);
        let first = s[0].unwrap();
        assert_eq!(&first[..1], &[12.0]);
        assert_eq!(&first[1..4], &[4.0, 4.0, 4.0]); // point 2 over 0.5 m
        assert_eq!(&first[4..7], &[1.0, 1.0, 1.0]); // point 2 over 2 deg
        assert_eq!(&first[7..8], &[10.0]); // point 5
        assert_eq!(&first[13..14], &[16.0]); // point 8, the end
        assert_eq!(s[1], None);
        // A large round keeps its first MAX_KEPT samples.
        let many = vec![Some(&t); MAX_KEPT + 500];
        let closest = vec![Some(1.0); MAX_KEPT + 500];
        assert_eq!(samples(&many, &closest, noise).len(), MAX_KEPT);
    }
}
