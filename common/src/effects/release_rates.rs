//! `release_rates` (docs/model.md section 7): omega(0) = (p0, q0, r0) instead of zero (aircraft
//! manoeuvring at release). With a scenario that sets initial rates, these add to them.

use nalgebra::Vector3;

use super::{Effect, EffectError, ParamSpec};
use crate::model::RunSetup;

/// Body rates at release.
pub struct ReleaseRates;

const RATE: ParamSpec = ParamSpec {
    name: "",
    unit: "rad/s",
    neutral: 0.0,
    min: -3.0,
    max: 3.0,
    scale: 0.1,
};

impl Effect for ReleaseRates {
    fn id(&self) -> &'static str {
        "release_rates"
    }
    fn adds(&self) -> &'static str {
        "body rates at release: omega(0) = (p0, q0, r0)"
    }
    fn params(&self) -> &'static [ParamSpec] {
        &[
            ParamSpec { name: "p0", ..RATE },
            ParamSpec { name: "q0", ..RATE },
            ParamSpec { name: "r0", ..RATE },
        ]
    }
    fn apply(&self, p: &[f64], run: &mut RunSetup) -> Result<(), EffectError> {
        run.initial_rates_rad_s += Vector3::new(p[0], p[1], p[2]);
        Ok(())
    }
}
