//! A baseline caught in a local optimum, found by the catalogue and restarted
//! (`docs/discovery.md` section 11.5, step 2a).
//!
//! Every test of the diagnosis measures an extension against the converged baseline. The
//! baseline's refinement starts where the genetic search left it, and with several releases
//! pooled (or a short search) that can be a local optimum of the 17 factors. A catalogue refit
//! refines the factors together with its effect and can then leave that optimum: the chi-square
//! drop it reports is the factors' escape, not the effect, and the catalogue names effects whose
//! values are near their neutral ones (seen on two releases of a lateral gust: four effects
//! named, each within two standard errors of zero, the baseline at 12 sigma).
//!
//! **The rule.** When the catalogue names effects, the baseline (effects off) is refined again
//! from the factors of the catalogue's model. When that reaches a BIC lower than the first
//! baseline's by more than [`RESTART_BIC`], the first sat in a local optimum: the new baseline
//! replaces it and the catalogue runs again from it, once. The diagnosis records the restart.
//! The BIC of section 11.5 (G. Schwarz, 1978) measures the drop, as every decision does.

use std::sync::Arc;

use sepval_common::evaluation::{Evaluator, Job};
use sepval_fit::space::Noise;
use sepval_solve::lm::LmSettings;

use super::catalogue::{self, CatalogueOutcome};
use super::{Fitted, Result, SkippedRefit, bic};

/// The BIC drop beyond which a baseline refined from the catalogue's factors replaces the
/// first: 2, "positive" evidence on R. E. Kass and A. E. Raftery's scale (JASA 90, 1995); a
/// smaller drop changes no decision of the diagnosis by more than its own margins.
pub const RESTART_BIC: f64 = 2.0;

/// The catalogue stage with its baseline restart.
pub(super) struct Catalogued {
    /// The converged baseline (the restarted one when it replaced the first).
    pub baseline: Fitted,
    /// The catalogue's selection from it.
    pub outcome: CatalogueOutcome,
    /// Why the first baseline was replaced, when it was.
    pub restart: Option<String>,
}

/// The catalogue's forward selection from `baseline`, then the restart rule (module docs):
/// when it names effects and the baseline refined from their model's factors beats the first
/// by more than [`RESTART_BIC`], the selection again from that baseline.
pub(super) fn catalogue(
    evaluator: &mut dyn Evaluator,
    job: &Arc<Job>,
    baseline: Fitted,
    noise: Noise,
    settings: &LmSettings,
    skipped: &mut Vec<SkippedRefit>,
) -> Result<Catalogued> {
    let outcome = catalogue::select(evaluator, job, &baseline, noise, settings, skipped)?;
    let kept = |baseline, outcome| {
        Ok(Catalogued {
            baseline,
            outcome,
            restart: None,
        })
    };
    if outcome.chosen.is_empty() {
        return kept(baseline, outcome);
    }
    // The extension's parameters follow the baseline's in its vector (catalogue.rs).
    let from = &outcome.fitted.lm.x[..baseline.lm.x.len()];
    let (lm, failure) = catalogue::refine_from(evaluator, job, &baseline, from, noise, settings)?;
    if let Some(reason) = failure {
        skipped.push(SkippedRefit {
            stage: "baseline restart".into(),
            model: "baseline".into(),
            reason,
        });
        return kept(baseline, outcome);
    }
    let (k, m) = (baseline.lm.x.len(), 6 * job.sample_count());
    let drop = bic(baseline.lm.cost, k, m) - bic(lm.cost, k, m);
    if drop.is_nan() || drop <= RESTART_BIC {
        return kept(baseline, outcome);
    }
    let restart = format!(
        "the first baseline fit sat in a local optimum: refined again from the factors of the \
         catalogue's selection, it fits better (chi-square {:.1} -> {:.1}, BIC {:.1} lower), and \
         the catalogue ran again from it",
        baseline.lm.cost, lm.cost, drop
    );
    let baseline = Fitted { lm, ..baseline };
    let outcome = catalogue::select(evaluator, job, &baseline, noise, settings, skipped)?;
    Ok(Catalogued {
        baseline,
        outcome,
        restart: Some(restart),
    })
}
