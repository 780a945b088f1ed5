//! `cg_offset` (docs/model.md section 7): the true CG lies dx_cg ahead of the nominal one, which
//! stays the aerodynamic moment reference. Foot arms become x_i - dx_cg; moments move to the
//! true CG (Cm += CZ dx_cg/d, Cn -= CY dx_cg/d, which is M += r_ref x F with
//! r_ref = (-dx_cg, 0, 0)); the state, f(s), the reported position and a tracked point refer to
//! the true CG; the inertias are about the true CG, unchanged.

use super::{Effect, EffectError, ParamSpec};
use crate::model::RunSetup;

/// Longitudinal CG offset.
pub struct CgOffset;

impl Effect for CgOffset {
    fn id(&self) -> &'static str {
        "cg_offset"
    }
    fn adds(&self) -> &'static str {
        "true CG dx_cg ahead of the nominal one (foot arms and aero moments move to it)"
    }
    fn params(&self) -> &'static [ParamSpec] {
        &[ParamSpec {
            name: "dx_cg",
            unit: "m",
            neutral: 0.0,
            min: -0.5,
            max: 0.5,
            scale: 0.05,
        }]
    }
    fn apply(&self, p: &[f64], run: &mut RunSetup) -> Result<(), EffectError> {
        let dx = p[0];
        for foot in run.feet.iter_mut() {
            foot.x_m -= dx;
        }
        run.aero_reference_x_m -= dx;
        Ok(())
    }
}
