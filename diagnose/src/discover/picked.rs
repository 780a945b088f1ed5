//! The library entries discovery has taken into the model, and where their parameters sit in the
//! parameter vector of the extended model (`docs/discovery.md` section 11.5): the factors first, then
//! each free term's coefficient followed by its locator when the locator is refitted too. This is
//! the one place that knows that layout; the refits, F-to-remove and the naming of the found
//! terms all read it from here.

use std::ops::Range;

use sepval_common::evaluation::Job;
use sepval_common::extension::{Family, Term};
use sepval_core::factors::FACTOR_COUNT;
use sepval_fit::space::FreeTerm;

use crate::library::{self, Entry};
use crate::{Fitted, Result};

/// The entries taken in, in the order they entered; their terms are the model's free terms, in
/// the same order.
#[derive(Debug, Clone, Default)]
pub(super) struct Picked {
    entries: Vec<Entry>,
    /// Per entry, whether the locator the verification holds (a gust's length, an
    /// oscillation's frequency) has earned its place and is estimated too.
    held_free: Vec<bool>,
}

/// Where one picked entry sits in its model.
pub(super) struct EntryParams {
    /// Its free terms, as indices into the model's terms.
    pub terms: Range<usize>,
    /// Each of its terms' parameters: the coefficient, then the locator and a gust's length
    /// when refitted.
    pub params: Vec<Range<usize>>,
    /// Each of its terms' locators refitted: (locator, length).
    refitted: Vec<(bool, bool)>,
}

impl EntryParams {
    /// Each of its terms' coefficient position.
    pub fn coefficients(&self) -> Vec<usize> {
        self.params.iter().map(|r| r.start).collect()
    }

    /// The position of its refitted locator (a step's or gust's time, a frequency, a decay
    /// length; an oscillation's sine carries the frequency its cosine shares).
    pub fn locator(&self) -> Option<usize> {
        self.params
            .iter()
            .zip(&self.refitted)
            .find(|(_, (locator, _))| *locator)
            .map(|(r, _)| r.start + 1)
    }

    /// The position of its refitted gust length.
    pub fn length(&self) -> Option<usize> {
        self.params
            .iter()
            .zip(&self.refitted)
            .find(|(_, (_, length))| *length)
            .map(|(r, (locator, _))| r.start + 1 + usize::from(*locator))
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
        let mut out = self.clone();
        out.entries.push(entry);
        out.held_free.push(false);
        out
    }

    /// These entries, with entry `k`'s held locator estimated too.
    pub fn with_held_free(&self, k: usize) -> Picked {
        let mut out = self.clone();
        out.held_free[k] = true;
        out
    }

    /// Entry `k` leaves.
    pub fn remove(&mut self, k: usize) {
        self.entries.remove(k);
        self.held_free.remove(k);
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
        Ok(Picked {
            entries,
            held_free: self.held_free.clone(),
        })
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
                let own = &terms[range.clone()];
                let params = own
                    .iter()
                    .map(|t| {
                        let n = t.param_count();
                        param += n;
                        param - n..param
                    })
                    .collect();
                EntryParams {
                    terms: range,
                    params,
                    refitted: own
                        .iter()
                        .map(|t| (t.locator.is_some(), t.length.is_some()))
                        .collect(),
                }
            })
            .collect()
    }

    /// The free terms of these entries: coefficients bounded to ten times their estimate; step
    /// times, decay lengths and a gust's middle free near their refined values
    /// ([`locator_bounds`]); a gust's length ([`length_bounds`]) and an oscillation's frequency
    /// only once they have earned their place ([`Picked::with_held_free`]).
    pub fn free_terms(&self) -> Vec<FreeTerm> {
        self.entries
            .iter()
            .zip(&self.held_free)
            .flat_map(|(e, &held_free)| {
                let single = e.terms.len() == 1;
                e.terms.iter().enumerate().map(move |(k, t)| {
                    let b = 10.0 * t.coefficient.abs().max(1e-12);
                    let oscillation = t.regressor.family() == Family::Oscillation;
                    let own_locator = single || (held_free && oscillation && k == 0);
                    FreeTerm {
                        term: *t,
                        coefficient: (-b, b),
                        locator: if own_locator { locator_bounds(t) } else { None },
                        length: if single && held_free {
                            length_bounds(t)
                        } else {
                            None
                        },
                        tied: held_free && oscillation && k > 0,
                    }
                })
            })
            .collect()
    }
}

/// Whether `entry` has a locator the verification holds at the library's value (a gust's
/// length, an oscillation's frequency), which a refit may then estimate.
pub(super) fn has_held_locator(entry: &Entry) -> bool {
    matches!(entry.family(), Family::Wind | Family::Oscillation)
}

/// Bounds of a refitted locator around its refined value: a quarter of the library's spacing
/// for a step's time, a gust's middle ([`FreeTerm::locator`]) and an oscillation's frequency,
/// a factor 1.2 for a decay length.
fn locator_bounds(term: &Term) -> Option<(f64, f64)> {
    let [l, rise_s] = term.locator;
    let quarter = library::STEP_SPACING_S / 4.0;
    match term.regressor.family() {
        Family::Step => Some((l - quarter, l + quarter)),
        Family::Wind => {
            let middle = l + rise_s / 2.0;
            Some((middle - quarter, middle + quarter))
        }
        Family::Oscillation => {
            let quarter = library::FREQUENCY_SPACING_HZ / 4.0;
            Some(((l - quarter).max(quarter), l + quarter))
        }
        Family::Interference | Family::InterferenceFlowAngle => Some((l / 1.2, l * 1.2)),
        _ => None,
    }
}

/// Bounds of a gust's refitted length: from [`library::SHORTEST_GUST_S`] to four times the
/// library's length (a gust shorter than the telemetry's few samples is seen only as its
/// impulse, and its standard error says so).
fn length_bounds(term: &Term) -> Option<(f64, f64)> {
    (term.regressor.family() == Family::Wind)
        .then(|| (library::SHORTEST_GUST_S, 4.0 * term.locator[1]))
}

#[cfg(test)]
mod tests {
    use sepval_common::extension::{Axis, Regressor};

    use super::*;

    fn term(axis: Axis, regressor: Regressor, locator: [f64; 2], coefficient: f64) -> Term {
        Term {
            axis,
            regressor,
            locator,
            coefficient,
        }
    }

    /// A gust and an oscillation pair: while competing, the gust refits its middle and the pair
    /// its coefficients only; once their held locators are freed, the gust refits its length
    /// too and the pair its frequency (the sine's parameter, the cosine tied to it), and the
    /// layout says where each sits.
    #[test]
    fn held_locators_join_the_layout_only_once_freed() {
        let gust = Entry {
            terms: vec![term(Axis::WindY, Regressor::WindStep, [0.4, 0.1], 3.0)],
        };
        let pair = Entry {
            terms: vec![
                term(Axis::CY, Regressor::Sin, [7.0, 0.0], 0.01),
                term(Axis::CY, Regressor::Cos, [7.0, 0.0], -0.02),
            ],
        };
        let picked = Picked::default().with(gust).with(pair);
        let held = picked.free_terms();
        assert_eq!(
            held.iter().map(FreeTerm::param_count).collect::<Vec<_>>(),
            [2, 1, 1]
        );
        let (lo, hi) = held[0].locator.unwrap();
        assert!(
            lo < 0.45 && 0.45 < hi,
            "the gust's middle 0.45 s in ({lo}, {hi})"
        );
        let at = picked.params(&held);
        assert_eq!(
            (at[0].locator(), at[0].length()),
            (Some(FACTOR_COUNT + 1), None)
        );
        assert_eq!(
            (at[1].locator(), at[1].coefficients()),
            (None, vec![19, 20])
        );

        let freed = picked.with_held_free(0).with_held_free(1);
        let terms = freed.free_terms();
        assert_eq!(
            terms.iter().map(FreeTerm::param_count).collect::<Vec<_>>(),
            [3, 2, 1]
        );
        assert!(terms[2].tied && !terms[1].tied);
        assert_eq!(terms[0].length, Some((library::SHORTEST_GUST_S, 0.4)));
        let at = freed.params(&terms);
        assert_eq!(
            (at[0].locator(), at[0].length()),
            (Some(FACTOR_COUNT + 1), Some(FACTOR_COUNT + 2))
        );
        assert_eq!(
            (at[1].locator(), at[1].coefficients()),
            (Some(FACTOR_COUNT + 4), vec![20, 22])
        );
        // An entry that leaves takes its flag with it.
        let mut fewer = freed.clone();
        fewer.remove(0);
        assert_eq!(fewer.free_terms().len(), 2);
        assert!(fewer.free_terms()[1].tied);
    }
}
