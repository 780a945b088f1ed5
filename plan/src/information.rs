//! The information a release at each condition adds (docs/planning.md section 12.3): the
//! D-optimal criterion on the answer's free parameters. The Fisher information of the
//! normalised residuals is J^T J (J: the sensitivities of every sample's six channels over
//! their noise, each parameter in units of its range, so that the determinant does not hang on
//! units), plus a unit prior of one range per parameter ([`crate::refit`]) so that parameters
//! one release leaves undetermined keep it finite. The gain of a condition is
//! `ln det(I_flown + J_k^T J_k) - ln det(I_flown)`: how much the release would shrink the volume
//! of the parameters' confidence region, pooled with the releases flown (a gain of ln 2 halves
//! it).

use nalgebra::DMatrix;

use crate::refit::log_det_with_prior;
use crate::simulate::{Missing, Simulated};

/// The information of the answer's parameters.
#[derive(Debug, Clone)]
pub struct Information {
    /// ln det of the information of the releases flown (with the prior).
    pub flown_log_det: f64,
    /// Per condition: the gain in ln det, or why the answer's sensitivities are missing.
    pub gains: Vec<Result<f64, Missing>>,
}

/// The information gain of every condition (the answer is model 0).
pub fn information(sims: &Simulated) -> Information {
    let runs = &sims.runs[0];
    let p = runs.normal[0].as_ref().map_or(0, |n| n.gram.nrows());
    let mut flown = DMatrix::zeros(p, p);
    for e in 0..sims.flown {
        if let Ok(n) = &runs.normal[e] {
            flown += &n.gram;
        }
    }
    let flown_log_det = log_det_with_prior(&flown);
    let gains = runs.normal[sims.flown..]
        .iter()
        .map(|n| {
            let n = n.as_ref().map_err(|r| Missing::Model {
                model: "the answer".into(),
                why: Box::new(r.clone()),
            })?;
            Ok(log_det_with_prior(&(&flown + &n.gram)) - flown_log_det)
        })
        .collect();
    Information {
        flown_log_det,
        gains,
    }
}
