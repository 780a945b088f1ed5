//! `pitch_stiffness_cubic`: Cm += Cm_alpha3 * alpha^3 (docs/model.md section 7).

use super::{Effect, EffectError, MAX_EFFECT_PARAMS, ParamSpec};
use crate::model::{Coefficients, Flow, RunSetup};

/// Non-linear (cubic) pitch stiffness.
pub struct PitchStiffnessCubic;

fn term(p: &[f64; MAX_EFFECT_PARAMS], flow: &Flow, c: &mut Coefficients) {
    let a = flow.alpha_rad;
    c.cm += p[0] * (a * a * a);
}

impl Effect for PitchStiffnessCubic {
    fn id(&self) -> &'static str {
        "pitch_stiffness_cubic"
    }
    fn adds(&self) -> &'static str {
        "cubic pitch stiffness: Cm += Cm_alpha3 * alpha^3"
    }
    fn params(&self) -> &'static [ParamSpec] {
        &[ParamSpec {
            name: "Cm_alpha3",
            unit: "1/rad^3",
            neutral: 0.0,
            min: -1000.0,
            max: 1000.0,
            scale: 20.0,
        }]
    }
    fn as_term(&self) -> Option<(crate::extension::Axis, crate::extension::Regressor)> {
        Some((
            crate::extension::Axis::Cm,
            crate::extension::Regressor::Alpha3,
        ))
    }
    fn apply(&self, p: &[f64], run: &mut RunSetup) -> Result<(), EffectError> {
        run.add_coefficient_term(term, [p[0], 0.0, 0.0])
    }
}
