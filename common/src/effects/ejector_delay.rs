//! `ejector_delay` (docs/model.md sections 7 and 3a): hooks open at t = 0 and the store falls
//! freely; the feet push only from t = tau, when each foot whose s_i <= stroke turns on.

use super::{Effect, EffectError, ParamSpec, require};
use crate::model::RunSetup;

/// Delay between hook opening and ejector force.
pub struct EjectorDelay;

impl Effect for EjectorDelay {
    fn id(&self) -> &'static str {
        "ejector_delay"
    }
    fn adds(&self) -> &'static str {
        "ejector feet push only from t = tau (free fall before)"
    }
    fn params(&self) -> &'static [ParamSpec] {
        &[ParamSpec {
            name: "tau",
            unit: "s",
            neutral: 0.0,
            min: 0.0,
            max: 0.05,
            scale: 0.005,
        }]
    }
    fn apply(&self, p: &[f64], run: &mut RunSetup) -> Result<(), EffectError> {
        require(self, 0, p[0], p[0] >= 0.0, "must be >= 0")?;
        run.ejector_start_s = p[0];
        Ok(())
    }
}
