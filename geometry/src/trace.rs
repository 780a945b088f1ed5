//! The clearance along one trajectory and its smallest value in free flight.
//!
//! The rule (docs/geometry.md, "The smallest clearance"): the distance is computed at every
//! sample, but its smallest value and the time of it are taken from the first sample at which
//! the store's CG has moved at least `free_after_m` (the ejector's stroke) from carriage,
//! |r| >= free_after_m, onwards: during the stroke the ejector holds the store and its gap to
//! the rack is the rack's business; MIL-STD-1289D's criterion concerns free flight. When no
//! sample gets that far, every sample is assessed.

use crate::clearance::{Closest, Geometry, Pose};
use crate::{GeometryError, Stop};

/// The clearance along one trajectory.
#[derive(Clone, Debug, PartialEq)]
pub struct Trace {
    /// The clearance at every sample (m).
    pub distance_m: Vec<f64>,
    /// The first sample assessed: the first with |r| >= `free_after_m`, or 0 when none is.
    pub assessed_from: usize,
    /// Whether any sample reached |r| >= `free_after_m` (false: all samples were assessed).
    pub free_flight_reached: bool,
    /// The smallest clearance from `assessed_from` on (the first sample of it on a tie).
    pub min: Closest,
    /// The sample of `min`.
    pub index_min: usize,
    /// Its time (s).
    pub t_min_s: f64,
}

impl Geometry {
    /// The clearance at each of `poses`, sampled at times `t_s`, and its smallest value after
    /// the CG has moved `free_after_m` from carriage (the module's rule). Refuses different
    /// lengths, no sample, a negative or non-finite `free_after_m`, and a time or pose that is
    /// not finite (naming the sample): a diverged trajectory is an error, never a NaN minimum.
    pub fn trace(
        &self,
        t_s: &[f64],
        poses: &[Pose],
        free_after_m: f64,
    ) -> Result<Trace, GeometryError> {
        self.trace_until(t_s, poses, free_after_m, &|| false)
    }

    /// [`Geometry::trace`], asking `stop` before each pose ([`GeometryError::Interrupted`]
    /// when it says stop).
    pub fn trace_until(
        &self,
        t_s: &[f64],
        poses: &[Pose],
        free_after_m: f64,
        stop: Stop,
    ) -> Result<Trace, GeometryError> {
        check(t_s, poses, free_after_m)?;
        let free = first_free(poses, free_after_m);
        let assessed_from = free.unwrap_or(0);
        let mut distance_m = Vec::with_capacity(poses.len());
        let mut min = Closest {
            distance_m: f64::INFINITY,
            ..self.clearance(&poses[0])
        };
        let mut index_min = assessed_from;
        for (k, pose) in poses.iter().enumerate() {
            if stop() {
                return Err(interrupted());
            }
            let c = self.clearance(pose);
            distance_m.push(c.distance_m);
            if k >= assessed_from && c.distance_m < min.distance_m {
                min = c;
                index_min = k;
            }
        }
        Ok(Trace {
            distance_m,
            assessed_from,
            free_flight_reached: free.is_some(),
            min,
            index_min,
            t_min_s: t_s[index_min],
        })
    }

    /// The smallest clearance of [`Geometry::trace`] (the same bits: `min`, `index_min` and
    /// `t_min_s` equal the trace's), without the clearance at every sample: a sample whose
    /// lower bound (bounding spheres, boxes and planes) is not below the smallest clearance
    /// found so far is not measured, which spares most of a trajectory that moves away. What
    /// an envelope needs of each of its samples.
    pub fn smallest(
        &self,
        t_s: &[f64],
        poses: &[Pose],
        free_after_m: f64,
    ) -> Result<Smallest, GeometryError> {
        self.smallest_until(t_s, poses, free_after_m, &|| false)
    }

    /// [`Geometry::smallest`], asking `stop` before each pose measured
    /// ([`GeometryError::Interrupted`] when it says stop).
    pub fn smallest_until(
        &self,
        t_s: &[f64],
        poses: &[Pose],
        free_after_m: f64,
        stop: Stop,
    ) -> Result<Smallest, GeometryError> {
        check(t_s, poses, free_after_m)?;
        let free = first_free(poses, free_after_m);
        let assessed_from = free.unwrap_or(0);
        let mut min = Closest {
            distance_m: f64::INFINITY,
            ..self.clearance(&poses[assessed_from])
        };
        let mut index_min = assessed_from;
        for (k, pose) in poses.iter().enumerate().skip(assessed_from) {
            if self.pose_lower_bound(pose) >= min.distance_m {
                continue;
            }
            if stop() {
                return Err(interrupted());
            }
            let c = self.clearance(pose);
            if c.distance_m < min.distance_m {
                min = c;
                index_min = k;
            }
        }
        Ok(Smallest {
            assessed_from,
            free_flight_reached: free.is_some(),
            min,
            index_min,
            t_min_s: t_s[index_min],
        })
    }
}

/// The smallest clearance along one trajectory ([`Geometry::smallest`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Smallest {
    /// The first sample assessed (as [`Trace::assessed_from`]).
    pub assessed_from: usize,
    /// Whether any sample reached the stroke.
    pub free_flight_reached: bool,
    /// The smallest clearance from `assessed_from` on (the first sample of it on a tie).
    pub min: Closest,
    /// The sample of `min`.
    pub index_min: usize,
    /// Its time (s).
    pub t_min_s: f64,
}

fn interrupted() -> GeometryError {
    GeometryError::Interrupted {
        what: "computing the clearance along a trajectory".into(),
    }
}

/// The first sample at which the CG has moved `free_after_m` from carriage.
fn first_free(poses: &[Pose], free_after_m: f64) -> Option<usize> {
    let moved = |p: &Pose| p.position_m.iter().map(|x| x * x).sum::<f64>().sqrt();
    poses.iter().position(|p| moved(p) >= free_after_m)
}

/// Refuses different lengths, no sample, a negative or non-finite `free_after_m`, and a time
/// or pose that is not finite (naming the sample).
fn check(t_s: &[f64], poses: &[Pose], free_after_m: f64) -> Result<(), GeometryError> {
    let refuse = |what: String| GeometryError::Trajectory { what };
    if t_s.len() != poses.len() {
        return Err(refuse(format!(
            "{} times but {} poses",
            t_s.len(),
            poses.len()
        )));
    }
    if poses.is_empty() {
        return Err(refuse("no sample".into()));
    }
    if !(free_after_m.is_finite() && free_after_m >= 0.0) {
        return Err(refuse(format!(
            "free_after_m = {free_after_m} must be finite and not negative"
        )));
    }
    for (k, (t, p)) in t_s.iter().zip(poses).enumerate() {
        if !t.is_finite()
            || !p
                .position_m
                .iter()
                .chain(&p.euler_deg)
                .all(|v| v.is_finite())
        {
            return Err(refuse(format!(
                "sample {k} (t = {t} s): the time or pose is not finite: {p:?}"
            )));
        }
    }
    Ok(())
}
