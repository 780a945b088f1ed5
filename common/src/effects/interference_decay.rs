//! `interference_decay` (docs/model.md section 7): lambda becomes k_lambda * 0.6 m (generally:
//! k_lambda times the scenario's lambda); s_end is unchanged. With a flowfield (section 3b), its
//! depth L_z scales by k_lambda.

use super::{Effect, EffectError, ParamSpec, require};
use crate::model::{InterferenceDecay, RunSetup};

/// Scaled interference decay length.
pub struct InterferenceDecayFactor;

impl Effect for InterferenceDecayFactor {
    fn id(&self) -> &'static str {
        "interference_decay"
    }
    fn adds(&self) -> &'static str {
        "interference decay length scaled: lambda = k_lambda * 0.6 m"
    }
    fn params(&self) -> &'static [ParamSpec] {
        &[ParamSpec {
            name: "k_lambda",
            unit: "-",
            neutral: 1.0,
            min: 0.2,
            max: 5.0,
            scale: 0.2,
        }]
    }
    fn apply(&self, p: &[f64], run: &mut RunSetup) -> Result<(), EffectError> {
        require(self, 0, p[0], p[0] > 0.0, "must be > 0")?;
        run.decay = InterferenceDecay::new(p[0] * run.decay.lambda_m, run.decay.s_end_m);
        // With an aircraft flowfield (docs/model.md section 3b), its depth L_z scales instead.
        if let Some(field) = run.flowfield.as_mut() {
            field.half_depth_m *= p[0];
            if let Some(t) = field.shape.as_mut() {
                t.scale_depth(p[0]);
            }
            field.inv_depth_scale /= p[0];
        }
        Ok(())
    }
}
