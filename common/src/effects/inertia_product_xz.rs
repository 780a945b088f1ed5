//! `inertia_product_xz` (docs/model.md section 7): I = [[Ixx, 0, -Ixz], [0, Iyy, 0], [-Ixz, 0, Izz]];
//! Ixz is not scaled by the inertia factors. A value that makes the tensor indefinite
//! (Ixz^2 >= Ixx Izz) is refused when the run is built.

use super::{Effect, EffectError, ParamSpec};
use crate::model::RunSetup;

/// Product of inertia Ixz.
pub struct InertiaProductXz;

impl Effect for InertiaProductXz {
    fn id(&self) -> &'static str {
        "inertia_product_xz"
    }
    fn adds(&self) -> &'static str {
        "product of inertia Ixz (I gains -Ixz off the diagonal, not scaled by the factors)"
    }
    fn params(&self) -> &'static [ParamSpec] {
        &[ParamSpec {
            name: "Ixz",
            unit: "kg m^2",
            neutral: 0.0,
            min: -100.0,
            max: 100.0,
            scale: 5.0,
        }]
    }
    fn apply(&self, p: &[f64], run: &mut RunSetup) -> Result<(), EffectError> {
        run.inertia_kg_m2[(0, 2)] -= p[0];
        run.inertia_kg_m2[(2, 0)] -= p[0];
        Ok(())
    }
}
