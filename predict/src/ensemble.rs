//! The models a prediction draws from and their weights (docs/prediction.md section 13.2): the
//! source's answer and each of its rivals, rebuilt from their model records
//! (`sepval_run::model_spec`) with the free parameters their refits move (the 17 factors, the
//! effects' parameters, the terms' coefficients, as `sepval plan` rebuilds them), weighted by
//! their evidence: w_m = exp(-delta_BIC_m / 2), normalised to sum 1 (the BIC approximation of
//! the posterior probability of each model with equal prior odds: R. E. Kass and A. E.
//! Raftery, JASA 90, 1995, section 4.1; A. E. Raftery, Sociological Methodology 25, 1995).
//!
//! The answer's parameters are drawn from the source's covariance ([`crate::sampling`]); a
//! rival has no covariance of its own in the files, so its 17 factors take the answer's draws
//! of the factors as deviations from its own values (the factors mean the same thing in every
//! model) and its other parameters stay at their values.

use sepval_common::evaluation::Candidate;
use sepval_core::factors::{FACTOR_COUNT, FactorTable};
use sepval_fit::rebuild::{Rebuilt, rebuild};
use sepval_fit::space::ParamSpace;

use crate::source::Source;

/// A model of the source that cannot be rebuilt.
pub use sepval_fit::rebuild::RebuildError as EnsembleError;

/// One model with its weight and free parameters.
#[derive(Debug, Clone)]
pub struct Member {
    /// Its name in reports: its effects and terms (`baseline` when it has none).
    pub name: String,
    /// Whether it is the source's answer.
    pub answer: bool,
    /// Its BIC minus the answer's on the releases fitted.
    pub delta_bic: f64,
    /// Its weight (the weights sum to 1).
    pub weight: f64,
    /// Its candidate at its estimate.
    pub candidate: Candidate,
    /// Its free parameters (names, bounds).
    pub space: ParamSpace,
    /// Their values at its estimate.
    pub x: Vec<f64>,
}

/// The answer and its rivals.
#[derive(Debug, Clone)]
pub struct Ensemble {
    /// The answer first, then the rivals.
    pub members: Vec<Member>,
}

impl Ensemble {
    /// The models of `source`, their factors checked against `table` (the factor table of the
    /// releases fitted). The answer's estimate is the source's identifiability record's values
    /// where it names a parameter.
    pub fn of(source: &Source, table: &FactorTable) -> Result<Ensemble, EnsembleError> {
        let raw: Vec<f64> = source
            .models
            .iter()
            .map(|m| (-0.5 * m.delta_bic).exp())
            .collect();
        let total: f64 = raw.iter().sum();
        let mut members = Vec::with_capacity(raw.len());
        for (i, (m, w)) in source.models.iter().zip(&raw).enumerate() {
            let which = if i == 0 {
                "the answer".to_string()
            } else {
                format!("rival {i}")
            };
            let Rebuilt {
                name, space, mut x, ..
            } = rebuild(&m.spec, &which, table)?;
            if i == 0 {
                sepval_fit::rebuild::at_estimate(&space, &mut x, &source.identifiability);
            }
            let candidate = space.candidate(&x).map_err(|e| EnsembleError::Factors {
                which: which.clone(),
                message: e.to_string(),
            })?;
            members.push(Member {
                name: if i == 0 {
                    name
                } else {
                    format!("{name} (rival {i})")
                },
                answer: i == 0,
                delta_bic: m.delta_bic,
                weight: if total > 0.0 && total.is_finite() {
                    w / total
                } else {
                    f64::from(u8::from(i == 0))
                },
                candidate,
                space,
                x,
            });
        }
        Ok(Ensemble { members })
    }

    /// The answer.
    pub fn answer(&self) -> &Member {
        &self.members[0]
    }

    /// Whether there are rivals.
    pub fn has_rivals(&self) -> bool {
        self.members.len() > 1
    }
}

/// The number of factors every model shares (the first parameters of every space).
pub const SHARED: usize = FACTOR_COUNT;
