//! Discovery's part of the rival classes (`crate::classes`): at the first step, the classes of
//! the entries the screening cannot tell from the best, and a refit of the lead of each class
//! that no verification refit or mimic represents (at most [`CLASS_REFITS`]), as contenders of
//! the rival search.

use nalgebra::DMatrix;
use sepval_common::evaluation::Evaluator;

use super::mimic;
use super::screen::Screening;
use super::search::{Search, Trail};
use crate::classes::{self, CLASS_REFITS, ClassInfo};
use crate::{Fitted, Result, stepwise};

/// The first step's classes, from its screening, into `trail`: of the entries passing the
/// screening's threshold or, when the catalogue names an answer, the level it met
/// ([`crate::catalogue_level`]), whichever is the larger; and, with that answer, of the entries
/// the screening cannot tell from it (`signature`: what the answer changes in the residuals,
/// full residual vector, screened as an entry is; [`classes::candidates`]).
pub(super) fn gather(s: &Screening, search: &Search, trail: &mut Trail, signature: Option<&[f64]>) {
    let threshold = signature.map_or(s.threshold, |_| crate::catalogue_level().max(s.threshold));
    let answer = signature.map(|sig| answer_statistic(s, search, sig));
    let candidates = classes::candidates(&s.scores, &s.entry_cols, threshold, answer);
    trail.classes = classes::classes(
        &s.linear.r0,
        &s.linear.fixed,
        &s.lib_cols,
        &s.entry_cols,
        &candidates,
    )
    .iter()
    .map(|c| ClassInfo::new(c, &s.entries))
    .collect();
}

/// The screening statistic X (dof F, one degree of freedom) of the answer's `signature` as
/// a column beyond the model's own sensitivities, as each library entry's is.
fn answer_statistic(s: &Screening, search: &Search, signature: &[f64]) -> f64 {
    let sig = search.on_rows(signature);
    let column = DMatrix::from_column_slice(sig.len(), 1, sig.as_slice());
    stepwise::screen(&s.linear.r0, &s.linear.fixed, &column, &[vec![0]])
        .first()
        .map_or(0.0, |x| x.f)
}

/// Refits the lead of each class without a contender yet (the best classes first, at most
/// [`CLASS_REFITS`]) about the baseline `current`, as contenders.
pub(super) fn refit_leads(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    s: &Screening,
    current: &Fitted,
    trail: &mut Trail,
) -> Result<()> {
    let leads: Vec<usize> = (0..trail.classes.len())
        .filter(|&k| !trail.contenders.iter().any(|c| c.class == Some(k)))
        .map(|k| trail.classes[k].lead)
        .take(CLASS_REFITS)
        .collect();
    mimic::as_contenders(
        evaluator,
        (search, s, current),
        &leads,
        "rival class",
        trail,
    )
}
