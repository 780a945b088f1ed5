//! The measurement noise that weights the goals: given by the user, or estimated from the data.

use sepval_common::evaluation::Job;
use sepval_common::noise::estimate_noise;
use serde::{Deserialize, Serialize};

/// Noise levels that weight the goals.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sigma {
    /// Position \[m\].
    pub pos_m: f64,
    /// Attitude \[deg\].
    pub att_deg: f64,
    /// Where they came from.
    pub source: String,
}

/// Noise levels that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SigmaError {
    /// Too few samples to estimate the noise.
    #[error(
        "event {event}: {samples} samples are too few to estimate the noise (5 at least); give both noise levels"
    )]
    TooFewSamples {
        /// The event.
        event: String,
        /// Its samples.
        samples: usize,
    },
    /// A level that is not a finite number > 0.
    #[error(
        "{name} = {value}: the noise level must be a finite number > 0 (data without noise? give both noise levels)"
    )]
    NotPositive {
        /// Which level.
        name: &'static str,
        /// Its value.
        value: f64,
    },
}

impl Sigma {
    /// The given sigmas; any not given is estimated from the data (pooled over events by sample
    /// count). When both are given the data are not looked at, so any number of samples fits.
    pub fn resolve(
        job: &Job,
        pos_m: Option<f64>,
        att_deg: Option<f64>,
    ) -> Result<Sigma, SigmaError> {
        let (pos, att) = match (pos_m, att_deg) {
            (Some(p), Some(a)) => (p, a),
            _ => {
                let (est_p, est_a) = estimated(job)?;
                (pos_m.unwrap_or(est_p), att_deg.unwrap_or(est_a))
            }
        };
        for (name, value) in [("sigma_pos_m", pos), ("sigma_att_deg", att)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(SigmaError::NotPositive { name, value });
            }
        }
        let source = match (pos_m, att_deg) {
            (Some(_), Some(_)) => "given".to_string(),
            (None, None) => "estimated from the data (second differences)".to_string(),
            _ => "partly given, partly estimated from the data".to_string(),
        };
        Ok(Sigma {
            pos_m: pos,
            att_deg: att,
            source,
        })
    }

    /// The noise that normalises a fit's residuals.
    pub fn noise(&self) -> crate::space::Noise {
        crate::space::Noise {
            pos_m: self.pos_m,
            att_deg: self.att_deg,
        }
    }

    /// Weights (1/sigma_pos, 1/sigma_att).
    pub fn weights(&self) -> [f64; 2] {
        [1.0 / self.pos_m, 1.0 / self.att_deg]
    }
}

/// The noise estimated from every event, pooled by sample count.
fn estimated(job: &Job) -> Result<(f64, f64), SigmaError> {
    let (mut p2, mut a2, mut n) = (0.0, 0.0, 0usize);
    for e in job.events() {
        let (p, a) = estimate_noise(&e.data).ok_or_else(|| SigmaError::TooFewSamples {
            event: e.name.clone(),
            samples: e.data.len(),
        })?;
        let k = e.data.len();
        p2 += p * p * k as f64;
        a2 += a * a * k as f64;
        n += k;
    }
    let n = n as f64;
    Ok(((p2 / n).sqrt(), (a2 / n).sqrt()))
}
