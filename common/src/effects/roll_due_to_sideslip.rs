//! `roll_due_to_sideslip`: Cl += Cl_beta * beta (docs/model.md section 7).

use super::{Effect, EffectError, MAX_EFFECT_PARAMS, ParamSpec};
use crate::model::{Coefficients, Flow, RunSetup};

/// Rolling moment due to sideslip.
pub struct RollDueToSideslip;

fn term(p: &[f64; MAX_EFFECT_PARAMS], flow: &Flow, c: &mut Coefficients) {
    c.cl += p[0] * flow.beta_rad;
}

impl Effect for RollDueToSideslip {
    fn id(&self) -> &'static str {
        "roll_due_to_sideslip"
    }
    fn adds(&self) -> &'static str {
        "rolling moment due to sideslip: Cl += Cl_beta * beta"
    }
    fn params(&self) -> &'static [ParamSpec] {
        &[ParamSpec {
            name: "Cl_beta",
            unit: "1/rad",
            neutral: 0.0,
            min: -5.0,
            max: 5.0,
            scale: 0.3,
        }]
    }
    fn as_term(&self) -> Option<(crate::extension::Axis, crate::extension::Regressor)> {
        Some((
            crate::extension::Axis::Cl,
            crate::extension::Regressor::Beta,
        ))
    }
    fn apply(&self, p: &[f64], run: &mut RunSetup) -> Result<(), EffectError> {
        run.add_coefficient_term(term, [p[0], 0.0, 0.0])
    }
}
