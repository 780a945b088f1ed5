//! A run with the values of the scenario's corrections (docs/update.md): those over
//! Mach folded into the run's constants, the others kept for the force evaluation
//! (`equations.rs`, `add_corrections`).

use super::{ModelError, RunSetup};
use crate::correction::{CorrectionRun, CorrectionValues};
use crate::effects::EffectSet;
use crate::extension::TermSet;
use crate::factors::Factors;

use super::Model;

impl RunSetup {
    /// The run of `model` with `factors`, `effects`, the extension `terms` and the values of
    /// the scenario's corrections (docs/update.md): those over Mach folded into the
    /// run's constants at the flight Mach, the others kept for the force evaluation. Without
    /// values, the run of [`RunSetup::with_terms`], bit for bit.
    pub fn with_corrections(
        model: &Model,
        factors: &Factors,
        effects: &EffectSet,
        terms: &TermSet,
        values: &CorrectionValues,
    ) -> Result<Self, ModelError> {
        let mut run = Self::with_terms(model, factors, effects, terms)?;
        if values.is_empty() {
            return Ok(run);
        }
        let (corrections, folded) =
            CorrectionRun::new(&model.corrections, values, model.scenario.flight.mach)?;
        let a = &mut run.aero;
        let s = folded.statics;
        a.cx0 -= s[0];
        a.cy0 += s[1];
        a.cz0 += s[2];
        a.cl0 += s[3];
        a.cm0 += s[4];
        a.cn0 += s[5];
        let d = folded.derivatives;
        a.cz_alpha += d[0];
        a.cy_beta += d[1];
        a.cm_alpha += d[2];
        a.cn_beta += d[3];
        a.cl_p += d[4];
        a.cm_q += d[5];
        a.cn_r += d[6];
        run.corrections = corrections;
        Ok(run)
    }
}
