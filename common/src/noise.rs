//! Measurement noise for synthetic flight tests.
//!
//! Source: `docs/model.md` section 4: Gaussian, sigma 0.003 m on each position and 0.1 deg
//! on each Euler angle, "from the project's own seeded generator". The generator is ChaCha8
//! (`rand_chacha`), seeded with `seed_from_u64`, and the normal deviates come from
//! `rand_distr::StandardNormal`: both portable across platforms, so a seed gives the same file
//! everywhere. Deviates are drawn sample by sample in the order x, y, z, roll, pitch, yaw; roll
//! and yaw are rewrapped to (-180, 180] after adding.
//!
//! Unlike the simulation (docs/model.md section 9), the noise may use the standard library's
//! elementary functions (`rand_distr`'s ziggurat calls `exp` and `ln` on its rare slow paths):
//! a noisy flight test is made once, on the coordinator's host, and workers receive its data,
//! never regenerate it.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::frames::wrap_deg;
use crate::telemetry::Trajectory;

/// Position noise of the default synthetic flight test \[m\].
pub const SIGMA_POS_M: f64 = 0.003;
/// Attitude noise of the default synthetic flight test \[deg\].
pub const SIGMA_ATT_DEG: f64 = 0.1;

/// Adds Gaussian noise with the given sigmas, from a generator seeded with `seed`.
pub fn add_noise(traj: &mut Trajectory, sigma_pos_m: f64, sigma_att_deg: f64, seed: u64) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
    for k in 0..traj.len() {
        for v in traj.pos_m[k].iter_mut() {
            *v += sigma_pos_m * normal();
        }
        for v in traj.att_deg[k].iter_mut() {
            *v += sigma_att_deg * normal();
        }
        traj.att_deg[k][0] = wrap_deg(traj.att_deg[k][0]);
        traj.att_deg[k][2] = wrap_deg(traj.att_deg[k][2]);
    }
}

/// Estimates the noise sigmas (position \[m\], attitude \[deg\]) of a trajectory from its second
/// differences: for a smooth signal sampled densely, x_{k+1} - 2 x_k + x_{k-1} is dominated by
/// noise, whose variance it multiplies by 6. Each channel's estimate uses the median absolute
/// second difference (robust to the few samples where the motion itself is not smooth, such as
/// the ejector cut-off), scaled by 1.4826 / sqrt(6); channels are pooled by RMS.
pub fn estimate_noise(traj: &Trajectory) -> Option<(f64, f64)> {
    let n = traj.len();
    if n < 5 {
        return None;
    }
    let channel = |get: &dyn Fn(usize) -> f64| -> f64 {
        let mut d: Vec<f64> = (1..n - 1)
            .map(|k| (get(k + 1) - 2.0 * get(k) + get(k - 1)).abs())
            .collect();
        d.sort_by(f64::total_cmp);
        let median = d[d.len() / 2];
        1.4826 * median / 6f64.sqrt()
    };
    let rms3 = |s: [f64; 3]| ((s[0] * s[0] + s[1] * s[1] + s[2] * s[2]) / 3.0).sqrt();
    let pos = rms3([0, 1, 2].map(|j| channel(&|k| traj.pos_m[k][j])));
    let att = rms3([0, 1, 2].map(|j| channel(&|k| traj.att_deg[k][j])));
    Some((pos, att))
}
