//! Exchanges (issue 60, "one release never a confident wrong answer"): each entry of the final
//! model that entered after the first step, replaced in turn by each entry whose verification
//! refit at that step came within [`RIVAL_MARGIN`] of its chi-square, refitted with the model's
//! other entries, as contenders of the rival search (`crate::rivals`).
//!
//! Forward selection fixes the earlier entries when it chooses a later one, and F-to-remove may
//! then take an earlier one out: a near-equal alternative of a later entry was only ever fitted
//! beside the earlier entries, never in place of the entry it lost to with the rest of the
//! answer (A. J. Miller, "Subset Selection in Regression", 2nd ed., Chapman & Hall/CRC, 2002,
//! chapter 3: forward selection misses subsets that a replacement of one variable at a time
//! finds). Roll damping 0.57 times the model's, one release (the first-release cases of
//! `plan/tests/closing/after.rs`, seed 0x9E37_79B9_7F4A_7C15, case 12): step 1 took a
//! roll-rate interference term, step 2 `Cl f(s; lambda=3 m)` at chi-square 1 068.6 against
//! 1 069.2 for the cause `Cl p d/2V`, F-to-remove took the first term out, and the answer,
//! `Cl f(s; lambda=3.06 m)` alone, had no rival holding the cause. The first step's entries
//! need no exchange of that kind: its refits, from the baseline, are contenders already.
//!
//! *Counterparts.* Every entry of the final model that is a flow angle or rate times the
//! interference's decay (`interference_flow_angle`: `Cl p d/2V*f(s; lambda)`) is also replaced
//! by the same flow angle or rate without the decay (`Cl p d/2V`, the limit of a long decay
//! length), whatever its step: the verification bounds the decay length to within 1.2 times the
//! library's, so the refit of the decaying term never reaches the constant one, and the
//! screening, linear about the baseline, can rank the constant one far below it. Roll damping
//! 0.52 times the model's on a random base, one release (the same cases, seed
//! 0xD1B5_4A32_D192_ED03, case 2): the answer `Cl p d/2V*f(s; lambda=1.08 m)` (screening X 64
//! for the library's lambda = 1.2 m, against 14.8 for the cause `Cl p d/2V`, which no step
//! refitted), named with no rival holding the cause.

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::Evaluator;
use sepval_common::extension::{Regressor, Term};
use sepval_fit::refine::refine_together;

use super::picked::Picked;
use super::search::{Near, Search, Trail};
use super::verify::{LastEntry, Refit, refit_run};
use crate::contender::Contender;
use crate::library::Entry;
use crate::{Fitted, RIVAL_MARGIN, Result};

/// The alternatives of the entry that entered at `step` (converged to `fitted`) among the
/// step's `refits` (the winner first), out of `pool` screened; none at the first step.
pub(super) fn near(step: usize, refits: &[Refit], fitted: &Fitted, pool: usize) -> Near {
    if step == 0 {
        return Near {
            entries: Vec::new(),
            pool,
        };
    }
    Near {
        entries: refits
            .iter()
            .skip(1)
            .filter(|r| r.fitted.lm.cost - fitted.lm.cost < RIVAL_MARGIN)
            .map(|r| r.entry.clone())
            .collect(),
        pool,
    }
}

/// Each entry of `picked` (the entries of `fitted`, at its values) replaced by each of its
/// `near` alternatives, refitted for at most the screening's iterations from `fitted`'s
/// factors and the other entries' values (all in one batch), into `trail`'s contenders. A
/// refit that does not simulate is left out, recorded in `trail`.
pub(super) fn exchanges(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    fitted: &Fitted,
    picked: &Picked,
    near: &[Near],
    trail: &mut Trail,
) -> Result<()> {
    let mut runs = Vec::new();
    let mut what = Vec::new();
    for (k, n) in near.iter().enumerate() {
        let own = &picked.entries()[k];
        let counterpart = counterpart(own).filter(|c| !n.entries.iter().any(|e| e.same_kind(c)));
        for alternative in n.entries.iter().chain(&counterpart) {
            let mut with = picked.clone();
            with.remove(k);
            let with = with.with(alternative.clone());
            let run = refit_run(
                search.job,
                fitted,
                &with,
                LastEntry::AtZero,
                search.noise,
                &search.screening,
            );
            runs.push(run);
            let origin = format!("{} in place of {}", alternative.label(), own.label());
            what.push((origin, n.pool));
        }
    }
    if runs.is_empty() {
        return Ok(());
    }
    refine_together(evaluator, &mut runs)?;
    for (run, (origin, pool)) in runs.into_iter().zip(what) {
        let terms = run.space().terms.clone();
        let failure = run.failure().map(ToString::to_string);
        let lm = run.finish();
        if let Some(reason) = failure {
            trail.skip("discovery's exchanges".into(), origin, reason);
            continue;
        }
        let f = Fitted {
            effects: EffectSet::NONE,
            terms,
            lm,
        };
        let origin = format!("discovery's exchange: {origin}");
        trail.contenders.push(Contender::new(&f, pool, origin));
    }
    Ok(())
}

/// The same flow angle or rate without the interference's decay, for an entry of the
/// `interference_flow_angle` family (the limit of its decay length growing); `None` otherwise.
fn counterpart(e: &Entry) -> Option<Entry> {
    let [t] = e.terms.as_slice() else {
        return None;
    };
    let regressor = match t.regressor {
        Regressor::FAlpha => Regressor::Alpha,
        Regressor::FBeta => Regressor::Beta,
        Regressor::FP => Regressor::P,
        Regressor::FQ => Regressor::Q,
        Regressor::FR => Regressor::R,
        _ => return None,
    };
    Some(Entry {
        terms: vec![Term {
            regressor,
            locator: [0.0; 2],
            ..*t
        }],
    })
}

#[cfg(test)]
mod tests {
    use sepval_common::extension::Axis;

    use super::*;

    fn entry(regressor: Regressor) -> Entry {
        Entry {
            terms: vec![Term {
                axis: Axis::Cl,
                regressor,
                locator: [1.2, 0.0],
                coefficient: 1e-3,
            }],
        }
    }

    #[test]
    fn a_decaying_flow_term_has_its_constant_counterpart_and_nothing_else_has() {
        for (decaying, constant) in [
            (Regressor::FAlpha, Regressor::Alpha),
            (Regressor::FBeta, Regressor::Beta),
            (Regressor::FP, Regressor::P),
            (Regressor::FQ, Regressor::Q),
            (Regressor::FR, Regressor::R),
        ] {
            let c = counterpart(&entry(decaying)).unwrap();
            assert_eq!(c.terms.len(), 1);
            assert_eq!(c.terms[0].regressor, constant);
            assert_eq!(c.terms[0].axis, Axis::Cl);
            assert!(
                c.terms[0].locator.iter().all(|v| v.abs() < 1e-300),
                "{:?}",
                c.terms[0].locator
            );
        }
        for other in [Regressor::F, Regressor::P, Regressor::Beta, Regressor::Step] {
            assert!(counterpart(&entry(other)).is_none(), "{other:?}");
        }
    }
}
