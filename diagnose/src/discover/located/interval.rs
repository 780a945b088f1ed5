//! The 95 % intervals of the locations from their profiles (`docs/discovery.md` section 11.5,
//! step 13): the Wald interval when it holds the profile's 95 % set, the set's hull otherwise,
//! not determined when the set reaches an end of the grid; a gust's onset and middle as the union
//! over the lengths the data allow; an oscillation's phase by the delta method.

use sepval_common::extension::Term;
use sepval_solve::identifiability::Identifiability;

use super::super::picked::EntryParams;
use super::{CHI2_95, Held, Profile, Z95};
use crate::Fitted;
use crate::found::Location;

/// The locations of entry `layout` from its profile `p`, at the model's values `at` and with
/// the model's identifiability `id`.
pub(super) fn located(
    p: &Profile,
    fitted: &Fitted,
    at: &[Term],
    layout: &EntryParams,
    id: &Identifiability,
) -> Vec<Location> {
    let lead = at[layout.terms.start];
    let se = |i: Option<usize>| i.and_then(|i| id.std_error(i));
    let set = Set::of(p, fitted.lm.cost, CHI2_95 * inflation(id, layout.locator()));
    match p.held {
        Held::Time => vec![one_d(
            "t_on_s",
            lead.locator[0],
            se(layout.locator()),
            p,
            &set,
        )],
        Held::Frequency => {
            let mut out = vec![one_d(
                "f_hz",
                lead.locator[0],
                se(layout.locator()),
                p,
                &set,
            )];
            out.extend(phase(at, layout, id));
            out
        }
        Held::Length => gust(p, &set, lead, layout, id),
    }
}

/// The square of the ratio of parameter `i`'s coloured standard error to its white one, at
/// least 1: how much wider than the white noise's the coloured residuals make a chi-square
/// difference (1 for a parameter the refit holds).
fn inflation(id: &Identifiability, i: Option<usize>) -> f64 {
    i.and_then(|i| id.parameters.get(i))
        .and_then(|p| Some((p.std_error? / p.std_error_white?).powi(2)))
        .filter(|s| s.is_finite())
        .map_or(1.0, |s| s.max(1.0))
}

/// A profile's 95 % set: the grid values whose profiled chi-square lies within the threshold
/// of the least (the model's own included).
struct Set {
    /// Indices of the values in the set, in grid order.
    inside: Vec<usize>,
    /// Whether the set reaches the grid's first value, and its last.
    reaches: (bool, bool),
    /// Whether the set has a gap: a value outside between two inside.
    gap: bool,
}

impl Set {
    /// The set of profile `p` about a model of chi-square `model_chi2`, at `threshold`.
    fn of(p: &Profile, model_chi2: f64, threshold: f64) -> Set {
        let least = p
            .points
            .iter()
            .flatten()
            .map(|q| q.chi2)
            .fold(model_chi2, f64::min);
        let inside: Vec<usize> = (0..p.values.len())
            .filter(|&k| p.points[k].is_some_and(|q| q.chi2 - least <= threshold))
            .collect();
        let n = p.values.len();
        let gap = inside.windows(2).any(|w| w[1] > w[0] + 1);
        Set {
            reaches: (inside.first() == Some(&0), inside.last() == Some(&(n - 1))),
            gap,
            inside,
        }
    }

    /// The hull of the set's values, each end widened to halfway to the next value outside
    /// (held at the grid's end where it reaches it), and `value` (the model's) within.
    fn hull(&self, values: &[f64], value: f64) -> (f64, f64) {
        let (Some(&a), Some(&b)) = (self.inside.first(), self.inside.last()) else {
            return (value, value);
        };
        let lo = if a > 0 {
            (values[a - 1] + values[a]) / 2.0
        } else {
            values[0]
        };
        let hi = if b + 1 < values.len() {
            (values[b] + values[b + 1]) / 2.0
        } else {
            values[b]
        };
        (lo.min(value), hi.max(value))
    }
}

/// A location profiled directly (a step's time, a frequency): the Wald interval when it holds
/// the profile's 95 % set, the set's hull otherwise, not determined when the set reaches an
/// end of the grid.
fn one_d(quantity: &str, value: f64, se: Option<f64>, p: &Profile, set: &Set) -> Location {
    let (lo, hi) = set.hull(&p.values, value);
    let (first, last) = (p.values[0], p.values[p.values.len() - 1]);
    let determined = !set.reaches.0 && !set.reaches.1;
    let wald = se.map(|s| (value - Z95 * s, value + Z95 * s));
    let inside_wald = |w: (f64, f64)| {
        set.inside
            .iter()
            .all(|&k| w.0 <= p.values[k] && p.values[k] <= w.1)
    };
    let (low, high, basis) = match wald {
        _ if !determined => (
            lo,
            hi,
            format!(
                "not determined by the data: the profile's 95 % set reaches the edge of the range tried ({first:.4} to {last:.4})"
            ),
        ),
        Some(w) if !set.gap && inside_wald(w) => (
            w.0,
            w.1,
            "the estimate ± 1.96 standard errors (the refit's Jacobian); the profile's 95 % set lies within".to_string(),
        ),
        w => {
            let why = if set.gap {
                "the cost has more than one minimum within the threshold"
            } else {
                "the cost is not quadratic about the estimate"
            };
            let (a, b) = w.map_or((lo, hi), |w| (lo.min(w.0), hi.max(w.1)));
            (a, b, format!("the profile's 95 % set ({why})"))
        }
    };
    Location {
        quantity: quantity.to_string(),
        value,
        std_error: se.filter(|_| determined),
        low,
        high,
        determined,
        basis,
    }
}

/// A gust's onset, middle and length from its length's profile `p` (95 % set `set`): the
/// length's set; the middle's and the onset's intervals as the union over the lengths in the
/// set of each refit's middle +- 1.96 SE (less half the length, for the onset).
fn gust(
    p: &Profile,
    set: &Set,
    lead: Term,
    layout: &EntryParams,
    id: &Identifiability,
) -> Vec<Location> {
    let [onset, rise_s] = lead.locator;
    let middle = onset + rise_s / 2.0;
    let param = |i: Option<usize>| i.and_then(|i| id.parameters.get(i));
    let se_middle = param(layout.locator()).and_then(|p| p.std_error);
    let se_length = param(layout.length())
        .filter(|p| p.identifiable)
        .and_then(|p| p.std_error);
    // (the middle, its standard error, the length) of the model and of each refit in the set.
    let mut fits = vec![(middle, se_middle, rise_s)];
    for &k in &set.inside {
        if let Some((m, se)) = p.points[k].and_then(|q| q.middle) {
            fits.push((m, se.or(se_middle), p.values[k]));
        }
    }
    let union = |shift: f64| {
        fits.iter().fold(
            (f64::INFINITY, f64::NEG_INFINITY),
            |(lo, hi), &(m, se, t)| {
                let (c, w) = (m - shift * t, Z95 * se.unwrap_or(0.0));
                (lo.min(c - w), hi.max(c + w))
            },
        )
    };
    let longest = p.values[p.values.len() - 1];
    let length_determined = !set.reaches.1;
    let (len_lo, len_hi) = set.hull(&p.values, rise_s);
    let allowed = format!(
        "over every length the data allow ({:.3} to {:.3} s)",
        len_lo, len_hi
    );
    let open = format!(
        "not determined by the data: lengths up to the longest tried ({longest:.3} s) fit as well"
    );
    let onset_se = match (se_middle, se_length, layout.locator(), layout.length()) {
        (Some(sm), Some(sl), Some(i), Some(j)) => {
            let rho = id.rho(i, j);
            Some((sm * sm + sl * sl / 4.0 - rho * sm * sl).max(0.0).sqrt())
        }
        _ => None,
    };
    let (o_lo, o_hi) = union(0.5);
    let (m_lo, m_hi) = union(0.0);
    vec![
        Location {
            quantity: "t_on_s".into(),
            value: onset,
            std_error: onset_se.filter(|_| length_determined),
            low: o_lo,
            high: o_hi,
            determined: length_determined,
            basis: if length_determined {
                format!("the middle's 95 % interval less half the length, {allowed}")
            } else {
                format!("{open}; the middle's 95 % interval less half the length, {allowed}")
            },
        },
        Location {
            quantity: "t_mid_s".into(),
            value: middle,
            std_error: se_middle,
            low: m_lo,
            high: m_hi,
            determined: se_middle.is_some(),
            basis: format!("the middle ± 1.96 standard errors (the refit's Jacobian), {allowed}"),
        },
        Location {
            quantity: "rise_s".into(),
            value: rise_s,
            std_error: se_length.filter(|_| length_determined),
            low: len_lo,
            high: len_hi,
            determined: length_determined,
            basis: if length_determined {
                "the profile's 95 % set of lengths".into()
            } else {
                open
            },
        },
    ]
}

/// An oscillation's phase atan2(b, a) of its sine's and cosine's coefficients a and b, with the
/// delta method's standard error: var = (b^2 var_a + a^2 var_b - 2 a b cov_ab) / (a^2 + b^2)^2.
fn phase(at: &[Term], layout: &EntryParams, id: &Identifiability) -> Option<Location> {
    let c = layout.coefficients();
    let (&i, &j) = (c.first()?, c.get(1)?);
    let (a, b) = (
        at[layout.terms.start].coefficient,
        at[layout.terms.start + 1].coefficient,
    );
    let value = b.atan2(a).to_degrees();
    let amp2 = a * a + b * b;
    let se_deg = match (id.std_error(i), id.std_error(j)) {
        (Some(sa), Some(sb)) if amp2 > 0.0 => {
            let rho = id.rho(i, j);
            let var =
                (b * b * sa * sa + a * a * sb * sb - 2.0 * a * b * rho * sa * sb) / (amp2 * amp2);
            Some(var.max(0.0).sqrt().to_degrees())
        }
        _ => None,
    };
    let determined = se_deg.is_some_and(|s| Z95 * s < 180.0);
    let half = se_deg.filter(|_| determined).map_or(180.0, |s| Z95 * s);
    Some(Location {
        quantity: "phase_deg".into(),
        value,
        std_error: se_deg.filter(|_| determined),
        low: value - half,
        high: value + half,
        determined,
        basis: if determined {
            "the estimate ± 1.96 standard errors (the delta method on the sine's and cosine's coefficients), at the frequency estimated".into()
        } else {
            "not determined by the data: 1.96 standard errors of the phase exceed 180 deg (the amplitude is not clear of its own error)".into()
        },
    })
}

#[cfg(test)]
mod tests {
    use sepval_common::extension::{Axis, Regressor};
    use sepval_solve::identifiability::ParamEstimate;

    use super::super::super::picked::Picked;
    use super::super::{Point, around, lengths};
    use super::*;
    use crate::library::Entry;
    use sepval_core::factors::FACTOR_COUNT;

    /// The least chi-square of the tests' profiles.
    const LEAST: f64 = 1200.0;

    fn profile(held: Held, values: Vec<f64>, chi2: impl Fn(f64) -> f64) -> Profile {
        let points = values
            .iter()
            .map(|&v| {
                Some(Point {
                    chi2: chi2(v),
                    middle: (held == Held::Length).then_some((0.44, Some(0.012))),
                })
            })
            .collect();
        Profile {
            entry: 0,
            held,
            values,
            points,
            middle: None,
        }
    }

    /// A step's time whose profile is the quadratic its standard error says: the Wald interval,
    /// determined, with its standard error.
    #[test]
    fn a_quadratic_profile_keeps_the_wald_interval() {
        let p = profile(Held::Time, around(0.43, 0.00625), |v| {
            LEAST + ((v - 0.43) / 0.003).powi(2)
        });
        let set = Set::of(&p, LEAST, CHI2_95);
        let l = one_d("t_on_s", 0.43, Some(0.003), &p, &set);
        assert!(l.determined && l.std_error == Some(0.003), "{l:?}");
        assert!((l.low - (0.43 - Z95 * 0.003)).abs() < 1e-12, "{l:?}");
        assert!((l.high - (0.43 + Z95 * 0.003)).abs() < 1e-12, "{l:?}");
    }

    /// A flat profile reaches the grid's ends: not determined, no standard error, the whole
    /// range tried as its interval, however narrow the Jacobian's standard error.
    #[test]
    fn a_flat_profile_is_not_determined() {
        let p = profile(Held::Time, around(0.43, 0.00625), |_| LEAST + 0.5);
        let set = Set::of(&p, LEAST, CHI2_95);
        let l = one_d("t_on_s", 0.43, Some(0.003), &p, &set);
        assert!(!l.determined && l.std_error.is_none(), "{l:?}");
        assert_eq!((l.low, l.high), (p.values[0], p.values[16]));
        assert!(l.basis.starts_with("not determined"), "{}", l.basis);
    }

    /// A second minimum within the threshold, outside the Wald interval: the interval is the
    /// set's hull, reaching halfway to the next value outside beyond it.
    #[test]
    fn a_second_minimum_widens_the_interval_to_the_profiles_set() {
        let values = around(0.43, 0.00625);
        let far = values[3];
        let p = profile(Held::Time, values.clone(), |v| {
            if (v - 0.43).abs() < 1e-9 {
                LEAST
            } else if (v - far).abs() < 1e-9 {
                LEAST + 1.0
            } else {
                LEAST + 50.0
            }
        });
        let set = Set::of(&p, LEAST, CHI2_95);
        assert!(set.gap);
        let l = one_d("t_on_s", 0.43, Some(0.003), &p, &set);
        assert!(l.determined, "{l:?}");
        assert!(
            (l.low - (values[2] + values[3]) / 2.0).abs() < 1e-12,
            "{l:?}"
        );
        assert!(l.high >= 0.43 + Z95 * 0.003, "{l:?}");
        assert!(l.basis.contains("more than one minimum"), "{}", l.basis);
    }

    /// A gust at (middle 0.44 s, length 0.1 s) with a model standard error of 12 ms on its
    /// middle: the onset is placed by the lengths the profile allows.
    fn gust_locations(chi2: impl Fn(f64) -> f64) -> Vec<Location> {
        let term = Term {
            axis: Axis::WindY,
            regressor: Regressor::WindStep,
            locator: [0.39, 0.1],
            coefficient: 10.0,
        };
        let picked = Picked::default().with(Entry { terms: vec![term] });
        let layout = picked.params(&picked.free_terms()).remove(0);
        let estimate = |value: f64, se: f64| ParamEstimate {
            name: String::new(),
            unit: String::new(),
            value,
            std_error: Some(se),
            std_error_white: Some(se),
            identifiable: true,
        };
        let mut parameters = vec![estimate(0.5, 0.01); FACTOR_COUNT];
        parameters.extend([estimate(10.0, 0.4), estimate(0.44, 0.012)]);
        let id = Identifiability {
            parameters,
            names: Vec::new(),
            correlation: Vec::new(),
            compensating: Vec::new(),
            not_identifiable: Vec::new(),
            max_lag: 0,
        };
        let p = profile(Held::Length, lengths(0.1), chi2);
        let set = Set::of(&p, LEAST, CHI2_95);
        gust(&p, &set, term, &layout, &id)
    }

    /// Every length fitting as well: the onset is not determined, its interval reaches from
    /// the longest length's onset to the shortest's, and it has no standard error.
    #[test]
    fn a_gust_whose_length_is_free_has_no_determined_onset() {
        let ls = gust_locations(|_| LEAST + 0.3);
        let (onset, middle, length) = (&ls[0], &ls[1], &ls[2]);
        assert_eq!(onset.quantity, "t_on_s");
        assert!(!onset.determined && onset.std_error.is_none(), "{onset:?}");
        assert!(
            (onset.low - (0.44 - 0.2 - Z95 * 0.012)).abs() < 1e-12,
            "{onset:?}"
        );
        assert!(
            (onset.high - (0.44 - 0.0025 + Z95 * 0.012)).abs() < 1e-12,
            "{onset:?}"
        );
        assert!(
            middle.determined && middle.std_error == Some(0.012),
            "{middle:?}"
        );
        assert!(!length.determined && (length.low, length.high) == (0.005, 0.4));
    }

    /// Only short lengths fitting: the length is determined (its set ends at 40 ms, the
    /// interval reaching the model's own 0.1 s, which it always holds), and so is the onset,
    /// within the middle's interval less half of those lengths.
    #[test]
    fn a_gust_whose_length_is_short_has_its_onset_determined() {
        let ls = gust_locations(|t| LEAST + if t <= 0.03 { 0.0 } else { 30.0 });
        let (onset, length) = (&ls[0], &ls[2]);
        assert!(onset.determined && length.determined, "{ls:?}");
        assert!((length.low, length.high) == (0.005, 0.1), "{length:?}");
        // The model's own length (0.1 s) is kept in the union: the estimate is in its interval.
        assert!(onset.low <= 0.39 && 0.44 - 0.0025 < onset.high, "{onset:?}");
    }

    /// An oscillation's phase: a sin + b cos with a = b = 1, each ± 0.1 and uncorrelated, is
    /// A sin(2 pi f t + 45 deg) with the delta method's standard error sqrt(0.02) / 2 rad.
    #[test]
    fn an_oscillations_phase_has_the_delta_methods_standard_error() {
        let term = |regressor, coefficient| Term {
            axis: Axis::Cl,
            regressor,
            locator: [6.25, 0.0],
            coefficient,
        };
        let terms = vec![term(Regressor::Sin, 1.0), term(Regressor::Cos, 1.0)];
        let picked = Picked::default().with(Entry {
            terms: terms.clone(),
        });
        let layout = picked.params(&picked.free_terms()).remove(0);
        let estimate = |se: f64| ParamEstimate {
            name: String::new(),
            unit: String::new(),
            value: 0.0,
            std_error: Some(se),
            std_error_white: Some(se),
            identifiable: true,
        };
        let n = FACTOR_COUNT + 2;
        let id = Identifiability {
            parameters: vec![estimate(0.1); n],
            names: Vec::new(),
            correlation: vec![vec![0.0; n]; n],
            compensating: Vec::new(),
            not_identifiable: Vec::new(),
            max_lag: 0,
        };
        let l = phase(&terms, &layout, &id).unwrap();
        let se = 0.02_f64.sqrt() / 2.0;
        assert!((l.value - 45.0).abs() < 1e-9, "{l:?}");
        assert!(
            (l.std_error.unwrap() - se.to_degrees()).abs() < 1e-9,
            "{l:?}"
        );
        assert!(l.determined && (l.high - l.low - 2.0 * Z95 * se.to_degrees()).abs() < 1e-9);
    }
}
