//! `telemetry_time_offset` (docs/model.md section 7): the measured sample labelled t shows the store
//! at t + dt_tm (the carriage state where t + dt_tm < 0; the simulation runs past the last
//! sample where needed).

use super::{Effect, EffectError, ParamSpec};
use crate::model::RunSetup;

/// Offset of the telemetry clock.
pub struct TelemetryTimeOffset;

impl Effect for TelemetryTimeOffset {
    fn id(&self) -> &'static str {
        "telemetry_time_offset"
    }
    fn adds(&self) -> &'static str {
        "telemetry clock offset: the sample labelled t shows the store at t + dt_tm"
    }
    fn params(&self) -> &'static [ParamSpec] {
        &[ParamSpec {
            name: "dt_tm",
            unit: "s",
            neutral: 0.0,
            min: -0.05,
            max: 0.05,
            scale: 0.005,
        }]
    }
    fn apply(&self, p: &[f64], run: &mut RunSetup) -> Result<(), EffectError> {
        run.time_offset_s += p[0];
        Ok(())
    }
}
