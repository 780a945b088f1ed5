//! Located terms estimated (`docs/discovery.md` section 11.5, step 13; issue 60, item 3): the
//! location of each discovered term that has one in time or frequency (a step's onset; a gust's
//! onset, middle and length; an oscillation's frequency and phase) reported as an estimate with
//! its standard error and 95 % interval, or said not to be determined by the data.
//!
//! The estimate is the value in the answer's model, whose output-error refit estimates the
//! step's time, the gust's middle and (once they earn their place) the gust's length and the
//! oscillation's frequency as bounded continuous parameters; the standard error is that refit's
//! (the inverse Fisher information of its Jacobian, corrected for coloured residuals: Morelli
//! and Klein, *Aircraft System Identification*, 2nd ed., 2016, section 6.8, as every
//! coefficient's). A Wald interval, value +- 1.96 SE, is only as good as the quadratic
//! approximation of the cost it rests on, which a location can break (a flat valley, a second
//! minimum one spacing away). So each location is also **profiled** (the cost minimised over
//! every other parameter with the location held at each value of a grid; Venzon and
//! Moolgavkar, "A method for computing profile-likelihood-based confidence intervals", *Applied
//! Statistics* 37, 1988): the 95 % set is the grid values whose profiled chi-square lies within
//! 3.84 s of the least (the chi-square quantile of one degree of freedom, s the square of the
//! ratio of the coloured to the white standard error, at least 1). The Wald interval stands when
//! it holds the whole set; otherwise the interval is the set's hull, widened by half a grid step
//! on each side. A set that reaches either end of the grid is **not determined**: the data allow
//! values beyond what was tried, and no standard error is given.
//!
//! A gust's onset t_on = t_mid - T/2 is placed by its middle and its length together. The length
//! is profiled (held at lengths from [`library::SHORTEST_GUST_S`] to four times the model's, the
//! middle free within [`REACH_S`]); the onset's interval is the union, over every length in the
//! length's 95 % set, of that refit's middle interval less half the length (a projection of the
//! joint region: conservative). When the length's set reaches the longest length tried, the
//! onset is not determined either. An oscillation's phase atan2(b, a) of its sine and cosine
//! coefficients has the delta method's standard error, at the frequency estimated.

use std::sync::Arc;

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::Evaluator;
use sepval_common::extension::{Family, Term};
use sepval_core::factors::FACTOR_COUNT;
use sepval_fit::refine::{ModelLm, refine_together};
use sepval_fit::space::{FreeTerm, ParamSpace};
use sepval_solve::identifiability::{Identifiability, identifiability};
use sepval_solve::lm::LmSettings;

use super::picked::{EntryParams, Picked};
use super::search::{Search, Trail};
use crate::found::Location;
use crate::library;
use crate::{Fitted, Result};
use interval::located;

mod interval;

/// The two-sided 95 % quantile of the standard normal distribution.
const Z95: f64 = 1.959_963_984_540_054;

/// The 95 % quantile of the chi-square distribution of one degree of freedom (Z95^2).
const CHI2_95: f64 = 3.841_458_820_694_124;

/// How far a profile reaches on each side of a time's estimate \[s\]: two library spacings.
pub(super) const REACH_S: f64 = 2.0 * library::STEP_SPACING_S;

/// Grid values on each side of the estimate of a time or a frequency (the locator zoom's
/// eight: a step of a quarter spacing for a time, an eighth for a frequency).
const SIDE: i32 = 8;

/// A gust's profiled lengths, as fractions of the model's length (then at least
/// [`library::SHORTEST_GUST_S`]).
const LENGTH_FRACTIONS: [f64; 11] = [0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0];

/// Most iterations of one profile refit: it starts at the optimum, one value of the grid away.
const PROFILE_ITERATIONS: usize = 100;

/// What is profiled of one entry.
#[derive(Clone, Copy, PartialEq)]
enum Held {
    /// A step's time, held at each grid value.
    Time,
    /// A gust's length, held at each grid value, its middle free.
    Length,
    /// An oscillation's frequency, held at each grid value.
    Frequency,
}

/// One entry's profile: the values held and each refit's chi-square, middle and middle's
/// standard error (`None` where a refit did not simulate).
struct Profile {
    entry: usize,
    held: Held,
    values: Vec<f64>,
    points: Vec<Option<Point>>,
    /// A held gust's middle: its index in the profile refits' parameters.
    middle: Option<usize>,
}

/// One profile refit's outcome.
#[derive(Clone, Copy)]
struct Point {
    chi2: f64,
    /// A gust's middle there, with its standard error.
    middle: Option<(f64, Option<f64>)>,
}

/// Each entry of `fitted` (made of `picked`, at its values) with its locations, in the order of
/// the entries (empty for an entry without one). The profiles of every entry share one batch of
/// simulations; a profile refit that does not simulate is left out and recorded in `trail`.
pub(super) fn locations(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    fitted: &Fitted,
    picked: &Picked,
    trail: &mut Trail,
) -> Result<Vec<Vec<Location>>> {
    let job = search.job;
    let space = fitted.space(job);
    let at = space.terms_at(&fitted.lm.x)?;
    let layout = picked.params(&fitted.terms);
    let settings = LmSettings {
        max_iterations: search.settings.max_iterations.min(PROFILE_ITERATIONS),
        ..search.settings.clone()
    };
    let mut profiles = Vec::new();
    let mut runs = Vec::new();
    for (k, e) in picked.entries().iter().enumerate() {
        let lead = at[layout[k].terms.start];
        let (held, values) = match e.family() {
            Family::Step => (
                Held::Time,
                around(lead.locator[0], library::STEP_SPACING_S / 4.0),
            ),
            Family::Wind => (Held::Length, lengths(lead.locator[1])),
            Family::Oscillation => (
                Held::Frequency,
                around(lead.locator[0], library::FREQUENCY_SPACING_HZ / 8.0)
                    .into_iter()
                    .filter(|f| *f > 0.0)
                    .collect(),
            ),
            _ => continue,
        };
        let mut middle = None;
        for &v in &values {
            let terms = held_at(fitted, &at, &layout[k], held, v);
            let first = layout[k].terms.start;
            middle = (held == Held::Length).then(|| {
                FACTOR_COUNT
                    + terms[..first]
                        .iter()
                        .map(FreeTerm::param_count)
                        .sum::<usize>()
                    + 1
            });
            runs.push(run_of(search, fitted, terms, &settings));
        }
        profiles.push(Profile {
            entry: k,
            held,
            points: Vec::with_capacity(values.len()),
            values,
            middle,
        });
    }
    if !runs.is_empty() {
        refine_together(evaluator, &mut runs)?;
    }
    // The runs are in the profiles' order, one per value.
    let mut runs = runs.into_iter();
    for p in &mut profiles {
        let values = p.values.clone();
        for (v, run) in values.into_iter().zip(runs.by_ref()) {
            let q = point(search, run, p, v, picked, trail);
            p.points.push(q);
        }
    }
    let id = model_identifiability(search, fitted);
    let mut out = vec![Vec::new(); picked.len()];
    for p in &profiles {
        let entry = &layout[p.entry];
        let mut ls = located(p, fitted, &at, entry, &id);
        // The location the refit estimates: a gust's middle, the first otherwise.
        let refitted = match p.held {
            Held::Length => ls.iter_mut().find(|l| l.quantity == "t_mid_s"),
            _ => ls.first_mut(),
        };
        if let (Some(i), Some(first)) = (entry.locator(), refitted) {
            let (lo, hi, x) = (space.params.lo[i], space.params.hi[i], fitted.lm.x[i]);
            if x - lo <= 1e-6 * (hi - lo) || hi - x <= 1e-6 * (hi - lo) {
                first.basis.push_str(&format!(
                    "; the refit's estimate lies at a bound of its range ({lo:.4} to {hi:.4})"
                ));
            }
        }
        out[p.entry] = ls;
    }
    Ok(out)
}

/// The grid of a time or a frequency: `2 SIDE + 1` values `step` apart, centred on `value`.
fn around(value: f64, step: f64) -> Vec<f64> {
    (-SIDE..=SIDE)
        .map(|k| value + step * f64::from(k))
        .collect()
}

/// The lengths a gust of length `rise_s` is profiled at: the shortest a gust can be (the
/// domain's end, so a set reaching it is closed there), then the fractions of the model's own
/// beyond it.
fn lengths(rise_s: f64) -> Vec<f64> {
    let shortest = library::SHORTEST_GUST_S;
    std::iter::once(shortest)
        .chain(
            LENGTH_FRACTIONS
                .iter()
                .map(|f| f * rise_s)
                .filter(|l| *l > shortest * (1.0 + 1e-9)),
        )
        .collect()
}

/// The free terms of `fitted` at its values `at`, the entry at `entry` held as `held` says at
/// `value`: a step's time or an oscillation's frequency fixed; a gust's length fixed, its
/// middle (where the model has it) free within [`REACH_S`].
fn held_at(
    fitted: &Fitted,
    at: &[Term],
    entry: &EntryParams,
    held: Held,
    value: f64,
) -> Vec<FreeTerm> {
    let mut terms: Vec<FreeTerm> = fitted
        .terms
        .iter()
        .zip(at)
        .map(|(f, t)| FreeTerm { term: *t, ..*f })
        .collect();
    for t in &mut terms[entry.terms.clone()] {
        match held {
            Held::Time | Held::Frequency => {
                t.term.locator[0] = value;
                t.locator = None;
            }
            Held::Length => {
                let middle = t.term.locator[0] + t.term.locator[1] / 2.0;
                t.term.locator = [middle - value / 2.0, value];
                t.locator = Some((middle - REACH_S, middle + REACH_S));
                t.length = None;
            }
        }
    }
    terms
}

/// The refit of `terms` with the factors, from `fitted`'s factors and the terms' values.
fn run_of(
    search: &Search,
    fitted: &Fitted,
    terms: Vec<FreeTerm>,
    settings: &LmSettings,
) -> ModelLm {
    let job = search.job;
    let space = ParamSpace::with_terms(job.factor_table(), &EffectSet::NONE, &terms);
    let mut x0 = fitted.lm.x[..FACTOR_COUNT].to_vec();
    for t in &terms {
        x0.extend(t.start());
    }
    ModelLm::new(space, Arc::clone(job), &x0, search.noise, settings.clone())
}

/// A profile refit's outcome, or `None` (recorded in `trail`) when it did not simulate.
fn point(
    search: &Search,
    run: ModelLm,
    profile: &Profile,
    value: f64,
    picked: &Picked,
    trail: &mut Trail,
) -> Option<Point> {
    let space = run.space().clone();
    let failure = run.failure().map(ToString::to_string);
    let lm = run.finish();
    if let Some(reason) = failure {
        let what = match profile.held {
            Held::Time => "time",
            Held::Length => "length",
            Held::Frequency => "frequency",
        };
        let model = picked
            .entries()
            .iter()
            .map(|e| e.label())
            .collect::<Vec<_>>()
            .join(" + ");
        trail.skip(
            "locations".into(),
            format!("{model} with a {what} held at {value}"),
            reason,
        );
        return None;
    }
    let middle = profile.middle.map(|i| {
        let events: Vec<usize> = search.job.events().iter().map(|e| e.data.len()).collect();
        let id = identifiability(&space.params, &lm.x, &lm.residuals, &lm.jacobian, &events);
        (lm.x[i], id.parameters[i].std_error)
    });
    Some(Point {
        chi2: lm.cost,
        middle,
    })
}

/// The identifiability of `fitted`'s refit.
fn model_identifiability(search: &Search, fitted: &Fitted) -> Identifiability {
    let space = fitted.space(search.job);
    let events: Vec<usize> = search.job.events().iter().map(|e| e.data.len()).collect();
    identifiability(
        &space.params,
        &fitted.lm.x,
        &fitted.lm.residuals,
        &fitted.lm.jacobian,
        &events,
    )
}
