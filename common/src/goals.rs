//! The two goals of the fit, both minimised.
//!
//! Source: `docs/model.md` section 5. Over the N telemetry samples:
//!
//! ```text
//! J_pos = sqrt( sum_k (dx^2 + dy^2 + dz^2) / (3N) )        [m]
//! J_att = sqrt( sum_k (dphi^2 + dtheta^2 + dpsi^2) / (3N) )  [deg], angle differences wrapped to (-180, 180]
//! ```
//!
//! Several events pool their samples: the sums and N run over all of them.

use crate::frames::wrap_deg;
use crate::model::StateVector;
use crate::propagator::{Observation, SampleSink};
use crate::telemetry::Trajectory;
pub use sepval_core::outcome::Goals;

/// Sums of squared differences, to be pooled and turned into goals.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GoalSums {
    /// Sum over samples of dx^2 + dy^2 + dz^2 [m^2].
    pub pos_m2: f64,
    /// Sum over samples of dphi^2 + dtheta^2 + dpsi^2 [deg^2].
    pub att_deg2: f64,
    /// Number of samples.
    pub samples: usize,
}

impl GoalSums {
    /// Adds the differences of one sample.
    #[inline]
    pub fn add(&mut self, sim: &Observation, pos_m: &[f64; 3], att_deg: &[f64; 3]) {
        let (d_pos, d_att) = residual(sim, pos_m, att_deg);
        self.pos_m2 += d_pos.iter().map(|d| d * d).sum::<f64>();
        self.att_deg2 += d_att.iter().map(|d| d * d).sum::<f64>();
        self.samples += 1;
    }

    /// Pools two sums.
    pub fn merge(&mut self, other: &GoalSums) {
        self.pos_m2 += other.pos_m2;
        self.att_deg2 += other.att_deg2;
        self.samples += other.samples;
    }

    /// The goals of the pooled samples.
    pub fn goals(&self) -> Goals {
        let n3 = 3.0 * self.samples as f64;
        Goals {
            j_pos_m: (self.pos_m2 / n3).sqrt(),
            j_att_deg: (self.att_deg2 / n3).sqrt(),
        }
    }
}

/// Differences simulated minus measured of one sample: position \[m\], and attitude \[deg\] with
/// each angle difference wrapped to (-180, 180].
#[inline]
pub fn residual(sim: &Observation, pos_m: &[f64; 3], att_deg: &[f64; 3]) -> ([f64; 3], [f64; 3]) {
    (
        [
            sim.pos_m[0] - pos_m[0],
            sim.pos_m[1] - pos_m[1],
            sim.pos_m[2] - pos_m[2],
        ],
        [
            wrap_deg(sim.att_deg[0] - att_deg[0]),
            wrap_deg(sim.att_deg[1] - att_deg[1]),
            wrap_deg(sim.att_deg[2] - att_deg[2]),
        ],
    )
}

/// A [`SampleSink`] that accumulates the goal sums against measured data, sample by sample,
/// without storing the simulated trajectory.
pub struct GoalAccumulator<'a> {
    measured: &'a Trajectory,
    /// The sums so far.
    pub sums: GoalSums,
}

impl<'a> GoalAccumulator<'a> {
    /// An accumulator against `measured`.
    pub fn new(measured: &'a Trajectory) -> Self {
        GoalAccumulator {
            measured,
            sums: GoalSums::default(),
        }
    }
}

impl SampleSink for GoalAccumulator<'_> {
    #[inline]
    fn record(&mut self, index: usize, obs: &Observation, _x: &StateVector) {
        self.sums.add(
            obs,
            &self.measured.pos_m[index],
            &self.measured.att_deg[index],
        );
    }
}

/// Errors comparing two trajectories.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum CompareError {
    /// Different numbers of samples.
    #[error("the trajectories have {a} and {b} samples: they must share their sample times")]
    Length {
        /// Samples in the first.
        a: usize,
        /// Samples in the second.
        b: usize,
    },
    /// Different sample times.
    #[error("sample {index} is at t = {a} s in one trajectory and t = {b} s in the other")]
    Time {
        /// Sample index (0-based).
        index: usize,
        /// Time in the first.
        a: f64,
        /// Time in the second.
        b: f64,
    },
    /// Goals beyond the range of f64.
    #[error("the goals are not finite numbers (J_pos = {j_pos_m} m, J_att = {j_att_deg} deg)")]
    NotFinite {
        /// J_pos \[m\].
        j_pos_m: f64,
        /// J_att \[deg\].
        j_att_deg: f64,
    },
}

/// Goals of `sim` against `data` (same sample times, within 1e-9 s).
pub fn goals_between(data: &Trajectory, sim: &Trajectory) -> Result<Goals, CompareError> {
    if data.len() != sim.len() {
        return Err(CompareError::Length {
            a: data.len(),
            b: sim.len(),
        });
    }
    let mut sums = GoalSums::default();
    for k in 0..data.len() {
        if (data.times_s[k] - sim.times_s[k]).abs() > 1e-9 {
            return Err(CompareError::Time {
                index: k,
                a: data.times_s[k],
                b: sim.times_s[k],
            });
        }
        let obs = Observation {
            pos_m: sim.pos_m[k],
            att_deg: sim.att_deg[k],
        };
        sums.add(&obs, &data.pos_m[k], &data.att_deg[k]);
    }
    let g = sums.goals();
    if !(g.j_pos_m.is_finite() && g.j_att_deg.is_finite()) {
        return Err(CompareError::NotFinite {
            j_pos_m: g.j_pos_m,
            j_att_deg: g.j_att_deg,
        });
    }
    Ok(g)
}
