//! `ejector_cant` (docs/model.md section 7): each foot's force is turned by kappa about the L x
//! axis: F_i (0, -sin kappa, cos kappa).

use nalgebra::Vector3;

use super::{Effect, EffectError, ParamSpec};
use crate::elementary::sin_cos;
use crate::model::RunSetup;

/// Ejector force direction canted about the launch-frame x axis.
pub struct EjectorCant;

impl Effect for EjectorCant {
    fn id(&self) -> &'static str {
        "ejector_cant"
    }
    fn adds(&self) -> &'static str {
        "ejector force turned by kappa about L x: F_i (0, -sin kappa, cos kappa)"
    }
    fn params(&self) -> &'static [ParamSpec] {
        &[ParamSpec {
            name: "kappa",
            unit: "rad",
            neutral: 0.0,
            min: -0.5,
            max: 0.5,
            scale: 0.05,
        }]
    }
    fn apply(&self, p: &[f64], run: &mut RunSetup) -> Result<(), EffectError> {
        let (s, c) = sin_cos(p[0]);
        run.ejector_direction_l = Vector3::new(0.0, -s, c);
        Ok(())
    }
}
