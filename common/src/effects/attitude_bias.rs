//! `attitude_bias` (docs/model.md section 7): measured Euler angles carry constant biases (roll and
//! yaw rewrapped to (-180, 180] after adding).

use super::{Effect, EffectError, ParamSpec};
use crate::model::RunSetup;

/// Constant Euler-angle measurement biases.
pub struct AttitudeBias;

const BIAS: ParamSpec = ParamSpec {
    name: "",
    unit: "rad",
    neutral: 0.0,
    min: -0.2,
    max: 0.2,
    scale: 0.01,
};

impl Effect for AttitudeBias {
    fn id(&self) -> &'static str {
        "attitude_bias"
    }
    fn adds(&self) -> &'static str {
        "constant biases on the measured Euler angles (roll, pitch, yaw)"
    }
    fn params(&self) -> &'static [ParamSpec] {
        &[
            ParamSpec {
                name: "phi_b",
                ..BIAS
            },
            ParamSpec {
                name: "theta_b",
                ..BIAS
            },
            ParamSpec {
                name: "psi_b",
                ..BIAS
            },
        ]
    }
    fn apply(&self, p: &[f64], run: &mut RunSetup) -> Result<(), EffectError> {
        for (b, v) in run.attitude_bias_rad.iter_mut().zip(p) {
            *b += v;
        }
        Ok(())
    }
}
