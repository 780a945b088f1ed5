//! The library's contenders of a diagnosis's rival search (`crate::rivals`), gathered at
//! discovery's first step, where the sensitivities about the baseline are at hand: the step's
//! verification refits, and the library terms that best reproduce a signature (what the
//! catalogue's answer changes in the residuals), the best of each family by F-to-enter beyond
//! the model's own sensitivities, each located and refitted as the step's own entries are.

use sepval_common::evaluation::Evaluator;
use sepval_common::extension::Family;

use super::picked::Picked;
use super::screen::Screening;
use super::search::{Search, Trail};
use super::verify::{Refit, refit_candidates};
use super::{damping, locate};
use crate::classes::{ClassInfo, class_of};
use crate::contender::Contender;
use crate::{Fitted, Result, stepwise};

/// Library terms tried as mimics of a signature, at most (one per family).
pub const MIMICS: usize = 3;

/// A step's refit as a contender of the rival search.
fn contender(r: &Refit, pool_size: usize, origin: &str, classes: &[ClassInfo]) -> Contender {
    Contender::new(
        &r.fitted,
        pool_size,
        format!("{origin}: {}", r.entry.label()),
    )
    .in_class(class_of(classes, &r.entry))
}

/// The first step's verification refits as contenders.
pub(super) fn from_refits(s: &Screening, refits: &[Refit], trail: &mut Trail) {
    let n = s.entries.len();
    let tagged: Vec<Contender> = refits
        .iter()
        .map(|r| contender(r, n, "discovery's first-step refit", &trail.classes))
        .collect();
    trail.contenders.extend(tagged);
}

/// The entries of `s` that best reproduce `signature` (full residual vector), one per family,
/// skipping the kinds in `exclude`; best first.
fn rank(s: &Screening, search: &Search, signature: &[f64], exclude: &[usize]) -> Vec<usize> {
    let sig = search.on_rows(signature);
    let scores = stepwise::screen(&sig, &s.linear.fixed, &s.lib_cols, &s.entry_cols);
    let mut families: Vec<Family> = Vec::new();
    let mut out = Vec::new();
    for sc in scores {
        let e = &s.entries[sc.entry];
        if exclude.iter().any(|&x| s.entries[x].same_kind(e)) || families.contains(&e.family()) {
            continue;
        }
        families.push(e.family());
        out.push(sc.entry);
        if out.len() == MIMICS {
            break;
        }
    }
    out
}

/// Each moment axis's own damping (`discover/damping.rs`), located and refitted about the
/// baseline `current` as a contender of the rival search whatever it screens, unless the step
/// verifies it anyway (`exclude`).
pub(super) fn dampings(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    s: &Screening,
    current: &Fitted,
    exclude: &[usize],
    trail: &mut Trail,
) -> Result<()> {
    let picked: Vec<usize> = (0..s.entries.len())
        .filter(|&k| {
            let e = &s.entries[k];
            damping::is_damping(e) && !exclude.iter().any(|&x| s.entries[x].same_kind(e))
        })
        .collect();
    as_contenders(
        evaluator,
        (search, s, current),
        &picked,
        "the axis's own damping",
        trail,
    )
}

/// The library's best mimics of `signature` about the baseline `current`, located and
/// refitted, as contenders.
pub(super) fn mimics(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    s: &Screening,
    current: &Fitted,
    signature: &[f64],
    exclude: &[usize],
    trail: &mut Trail,
) -> Result<()> {
    let picked = rank(s, search, signature, exclude);
    as_contenders(
        evaluator,
        (search, s, current),
        &picked,
        "library mimic of the catalogue's answer",
        trail,
    )
}

/// The entries `picked` of the screening `s`, located and refitted alone about the model
/// `current` (the baseline at the first step), as contenders of the rival search whose origin
/// says `origin`; each tagged with its rival class.
pub(super) fn as_contenders(
    evaluator: &mut dyn Evaluator,
    (search, s, current): (&Search, &Screening, &Fitted),
    picked: &[usize],
    origin: &str,
    trail: &mut Trail,
) -> Result<()> {
    if picked.is_empty() {
        return Ok(());
    }
    let located = locate::locate(evaluator, search, s, current, picked)?;
    let refits = refit_candidates(
        evaluator,
        search,
        current,
        &Picked::default(),
        located,
        trail,
    )?;
    let n = s.entries.len();
    let tagged: Vec<Contender> = refits
        .iter()
        .map(|r| contender(r, n, origin, &trail.classes))
        .collect();
    trail.contenders.extend(tagged);
    Ok(())
}
