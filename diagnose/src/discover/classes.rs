//! Discovery's part of the rival classes (`crate::classes`): at the first step, the classes of
//! the entries the screening cannot tell from the best, and a refit of the lead of each class
//! that no verification refit or mimic represents (at most [`CLASS_REFITS`]), as contenders of
//! the rival search.

use sepval_common::evaluation::Evaluator;

use super::mimic;
use super::screen::Screening;
use super::search::{Search, Trail};
use crate::classes::{self, CLASS_REFITS, ClassInfo};
use crate::{Fitted, Result};

/// The first step's classes, from its screening, into `trail`: of the entries passing the
/// screening's threshold or, when the catalogue names an answer, the level it met (`level`,
/// [`crate::catalogue_level`]), whichever is the larger.
pub(super) fn gather(s: &Screening, trail: &mut Trail, level: Option<f64>) {
    let threshold = level.map_or(s.threshold, |l| l.max(s.threshold));
    let candidates = classes::candidates(&s.scores, &s.entry_cols, threshold);
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
