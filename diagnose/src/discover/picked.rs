//! The library entries discovery has taken into the model, and where their parameters sit in the
//! parameter vector of the extended model (`docs/discovery.md` section 11.5): the factors first, then
//! each free term's coefficient followed by its locator when the locator is refitted too. This is
//! the one place that knows that layout; the refits, F-to-remove and the naming of the found
//! terms all read it from here.

use std::ops::Range;

use sepval_common::evaluation::Job;
use sepval_common::extension::{Family, Term};
use sepval_common::factors::FACTOR_COUNT;
use sepval_fit::space::FreeTerm;

use crate::library::{self, Entry};
use crate::{Fitted, Result};

/// The entries taken in, in the order they entered; their terms are the model's free terms, in
/// the same order.
#[derive(Debug, Clone, Default)]
pub(super) struct Picked {
    entries: Vec<Entry>,
}

/// Where one picked entry sits in its model.
pub(super) struct EntryParams {
    /// Its free terms, as indices into the model's terms.
    pub terms: Range<usize>,
    /// Each of its terms' parameters: the coefficient, then the locator when refitted.
    pub params: Vec<Range<usize>>,
}

impl EntryParams {
    /// Each of its terms' coefficient position.
    pub fn coefficients(&self) -> Vec<usize> {
        self.params.iter().map(|r| r.start).collect()
    }

    /// The position of its (last) refitted locator.
    pub fn locator(&self) -> Option<usize> {
        self.params
            .iter()
            .rfind(|r| r.len() == 2)
            .map(|r| r.start + 1)
    }
}

impl Picked {
    /// The entries, in the order they entered.
    pub fn entries(&self) -> &[Entry] {
        &self.entries
    }

    /// How many entries.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// No entry yet.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Terms of all the entries.
    pub fn term_count(&self) -> usize {
        self.entries.iter().map(|e| e.terms.len()).sum()
    }

    /// These entries and `entry` after them.
    pub fn with(&self, entry: Entry) -> Picked {
        let mut entries = self.entries.clone();
        entries.push(entry);
        Picked { entries }
    }

    /// Entry `k` leaves.
    pub fn remove(&mut self, k: usize) {
        self.entries.remove(k);
    }

    /// The entries at the values `fitted` (made of them) estimated.
    pub fn at(&self, job: &Job, fitted: &Fitted) -> Result<Picked> {
        let terms = fitted.space(job).terms_at(&fitted.lm.x)?;
        let mut at = 0;
        let entries = self
            .entries
            .iter()
            .map(|e| {
                let n = e.terms.len();
                let out = Entry {
                    terms: terms[at..at + n].to_vec(),
                };
                at += n;
                out
            })
            .collect();
        Ok(Picked { entries })
    }

    /// Where each entry sits among `terms`, the free terms of a model made of these entries.
    pub fn params(&self, terms: &[FreeTerm]) -> Vec<EntryParams> {
        let mut term = 0;
        let mut param = FACTOR_COUNT;
        self.entries
            .iter()
            .map(|e| {
                let range = term..term + e.terms.len();
                term = range.end;
                let params = terms[range.clone()]
                    .iter()
                    .map(|t| {
                        let n = 1 + usize::from(t.locator.is_some());
                        param += n;
                        param - n..param
                    })
                    .collect();
                EntryParams {
                    terms: range,
                    params,
                }
            })
            .collect()
    }

    /// The free terms of these entries: coefficients bounded to ten times their estimate, step
    /// and gust times and decay lengths free near their refined values (a gust's length stays
    /// at the library's).
    pub fn free_terms(&self) -> Vec<FreeTerm> {
        self.entries
            .iter()
            .flat_map(|e| {
                let single = e.terms.len() == 1;
                e.terms.iter().map(move |t| {
                    let b = 10.0 * t.coefficient.abs().max(1e-12);
                    FreeTerm {
                        term: *t,
                        coefficient: (-b, b),
                        locator: if single { locator_bounds(t) } else { None },
                    }
                })
            })
            .collect()
    }
}

/// Bounds of a refitted locator around its refined value.
fn locator_bounds(term: &Term) -> Option<(f64, f64)> {
    let l = term.locator[0];
    match term.regressor.family() {
        Family::Step | Family::Wind => Some((
            l - library::STEP_SPACING_S / 4.0,
            l + library::STEP_SPACING_S / 4.0,
        )),
        Family::Interference | Family::InterferenceFlowAngle => Some((l / 1.2, l * 1.2)),
        _ => None,
    }
}
