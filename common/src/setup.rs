//! A run set up: the model's run with the factors ([`RunSetup`] in `model`), the catalogue's
//! effects applied (docs/model.md section 7), the extension's terms (docs/discovery.md) and the
//! values of the scenario's corrections (docs/update.md): those over Mach folded into the
//! run's constants, the others kept for the force evaluation (`model/equations.rs`,
//! `add_corrections`).
//!
//! Here, apart from `model`, so that the model does not know the effect catalogue whose
//! plug-ins change its runs (`effects/`): the catalogue depends on the model, the model on
//! neither.

use sepval_core::factors::Factors;

use crate::correction::{CorrectionError, CorrectionRun, CorrectionValues};
use crate::effects::EffectSet;
use crate::extension::TermSet;
use crate::model::{Model, ModelError, RunSetup};

impl RunSetup {
    /// The run of `model` with `factors` (checked against the scenario's factor table) and
    /// `effects` applied.
    pub fn new(model: &Model, factors: &Factors, effects: &EffectSet) -> Result<Self, ModelError> {
        Self::with_terms(model, factors, effects, &TermSet::NONE)
    }

    /// The run of `model` with `factors`, `effects` and the extension `terms` (added to the
    /// scenario's own) applied.
    pub fn with_terms(
        model: &Model,
        factors: &Factors,
        effects: &EffectSet,
        terms: &TermSet,
    ) -> Result<Self, ModelError> {
        model.scenario().factors.check(factors)?;
        let mut run = Self::new_unchecked_bounds(model, factors, effects)?;
        run.terms = model.extension.merged(terms)?;
        Ok(run)
    }

    /// As [`RunSetup::new`], but factors need only be finite (not within the table's bounds):
    /// for studies that step outside the search box on purpose.
    pub fn new_unchecked_bounds(
        model: &Model,
        factors: &Factors,
        effects: &EffectSet,
    ) -> Result<Self, ModelError> {
        let mut run = Self::base(model, factors)?;
        effects.apply(&mut run)?;
        run.finish()
    }

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
            CorrectionRun::new(&model.corrections, values, model.scenario().flight.mach)?;
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
        if let Some(field) = run.flowfield {
            // The field acts through the store's slopes, corrected (model.md section 3b).
            let field = field.with_slope_change([d[0], d[2], d[1], d[3]]);
            let changed = field
                .with_change(folded.field)
                .and_then(|f| f.with_shape_table_change(&folded.shape));
            run.flowfield = Some(changed.map_err(CorrectionError::FieldChange)?);
        }
        run.corrections = corrections;
        Ok(run)
    }
}
