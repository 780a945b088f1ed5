//! `tracked_point_offset` (docs/model.md section 7): the measured position is of the body point
//! (l_x, 0, 0), relative to that point's carriage position: r + C_LB (l_x, 0, 0) - (l_x, 0, 0).

use super::{Effect, EffectError, ParamSpec};
use crate::model::RunSetup;

/// Tracked point away from the CG.
pub struct TrackedPointOffset;

impl Effect for TrackedPointOffset {
    fn id(&self) -> &'static str {
        "tracked_point_offset"
    }
    fn adds(&self) -> &'static str {
        "measured position is of the body point (l_x, 0, 0), not the CG"
    }
    fn params(&self) -> &'static [ParamSpec] {
        &[ParamSpec {
            name: "l_x",
            unit: "m",
            neutral: 0.0,
            min: -3.0,
            max: 3.0,
            scale: 0.1,
        }]
    }
    fn apply(&self, p: &[f64], run: &mut RunSetup) -> Result<(), EffectError> {
        run.tracked_point_b_m.x += p[0];
        Ok(())
    }
}
