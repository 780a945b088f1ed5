//! The candidate conditions: a grid over the ranges given for the flight condition's five
//! quantities (docs/model.md section 1, `[flight]`: Mach, altitude, aircraft alpha, beta and
//! flight-path angle), each axis not given held at the condition of the diagnosis's first
//! release. A range is checked before anything runs: LO <= HI, finite, within what the scenario
//! accepts (section 1: Mach > 0, the ISA troposphere, angles within +-90 deg) and within the
//! model's domain and the breakpoints of the scenario's tables in Mach, alpha and beta
//! ([`crate::domain`]: a table is held at its edge beyond them, so a planned release
//! there would fly on made-up aerodynamics).

use sepval_core::number_text::Shown;
use serde::{Deserialize, Serialize};

use sepval_common::scenario::{Flight, Scenario};

/// Points per axis when `--points` is not given.
pub const DEFAULT_POINTS: usize = 9;
/// The most conditions one plan evaluates (each is simulated with every model and every
/// parameter step).
pub const MAX_CONDITIONS: usize = 4096;

/// One quantity of the flight condition a plan may vary.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// Free-stream Mach number \[-\].
    Mach,
    /// Altitude \[m\].
    AltitudeM,
    /// Aircraft angle of attack \[deg\].
    AlphaDeg,
    /// Aircraft sideslip \[deg\].
    BetaDeg,
    /// Flight-path angle \[deg\].
    GammaDeg,
}

impl Quantity {
    /// Every quantity, in the order of `[flight]`.
    pub const ALL: [Quantity; 5] = [
        Quantity::Mach,
        Quantity::AltitudeM,
        Quantity::AlphaDeg,
        Quantity::BetaDeg,
        Quantity::GammaDeg,
    ];

    /// The command-line flag that gives its range.
    pub fn flag(self) -> &'static str {
        match self {
            Quantity::Mach => "--mach",
            Quantity::AltitudeM => "--altitude-m",
            Quantity::AlphaDeg => "--alpha-deg",
            Quantity::BetaDeg => "--beta-deg",
            Quantity::GammaDeg => "--gamma-deg",
        }
    }

    /// Its name in files (plan.json) and on figure axes.
    pub fn label(self) -> &'static str {
        match self {
            Quantity::Mach => "Mach [-]",
            Quantity::AltitudeM => "Altitude [m]",
            Quantity::AlphaDeg => "Aircraft alpha [deg]",
            Quantity::BetaDeg => "Aircraft beta [deg]",
            Quantity::GammaDeg => "Flight-path angle [deg]",
        }
    }

    /// Its value in a flight condition.
    pub fn get(self, f: &Flight) -> f64 {
        match self {
            Quantity::Mach => f.mach,
            Quantity::AltitudeM => f.altitude_m,
            Quantity::AlphaDeg => f.alpha_deg,
            Quantity::BetaDeg => f.beta_deg,
            Quantity::GammaDeg => f.gamma_deg,
        }
    }

    /// The quantity the model's domain bounds ([`crate::domain`]), if it is one.
    pub fn bounded(self) -> Option<crate::domain::Bounded> {
        use crate::domain::Bounded;
        match self {
            Quantity::Mach => Some(Bounded::Mach),
            Quantity::AlphaDeg => Some(Bounded::AlphaDeg),
            Quantity::BetaDeg => Some(Bounded::BetaDeg),
            Quantity::AltitudeM | Quantity::GammaDeg => None,
        }
    }

    fn set(self, f: &mut Flight, v: f64) {
        match self {
            Quantity::Mach => f.mach = v,
            Quantity::AltitudeM => f.altitude_m = v,
            Quantity::AlphaDeg => f.alpha_deg = v,
            Quantity::BetaDeg => f.beta_deg = v,
            Quantity::GammaDeg => f.gamma_deg = v,
        }
    }
}

/// A range given for one quantity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// The quantity.
    pub quantity: Quantity,
    /// Its lowest value.
    pub lo: f64,
    /// Its highest value.
    pub hi: f64,
}

/// A condition range that cannot be planned over. Each names the flag at fault.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ConditionError {
    /// A range that is not `LO:HI` with finite numbers and LO <= HI.
    #[error("{flag} {}:{}: {message}", Shown(*lo), Shown(*hi))]
    Range {
        /// The flag.
        flag: &'static str,
        /// Its low end.
        lo: f64,
        /// Its high end.
        hi: f64,
        /// What is wrong.
        message: String,
    },
    /// A flag given twice.
    #[error("{flag} given twice: give each range once")]
    Repeated {
        /// The flag.
        flag: &'static str,
    },
    /// `--points` 0, or a grid of too many conditions.
    #[error("--points {points}: {message}")]
    Points {
        /// Points per axis.
        points: usize,
        /// What is wrong.
        message: String,
    },
}

/// One release condition of the grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Condition {
    /// The flight condition.
    pub flight: Flight,
}

/// The grid of candidate conditions.
#[derive(Debug, Clone)]
pub struct Conditions {
    /// The conditions, the last varied axis fastest.
    pub list: Vec<Condition>,
    /// The quantities varied (given with LO < HI), in [`Quantity::ALL`] order, with the values
    /// of each.
    pub axes: Vec<(Quantity, Vec<f64>)>,
    /// The condition of the first release (the value of every axis not varied).
    pub base: Flight,
}

impl Conditions {
    /// The grid over `ranges` with `points` per varied axis around `base` (the scenario of the
    /// first release), each range checked against `base`'s scenario.
    pub fn grid(
        base: &Scenario,
        ranges: &[Range],
        points: usize,
    ) -> Result<Conditions, ConditionError> {
        if points == 0 {
            return Err(ConditionError::Points {
                points,
                message: "expected at least 1 point per axis".into(),
            });
        }
        let per_axis: Vec<(Range, usize)> = ranges.iter().map(|&r| (r, points)).collect();
        Conditions::grid_per_axis(base, &per_axis)
    }

    /// The grid over `ranges`, each with its own number of points (at least 1; a range of one
    /// point, or with LO = HI, is held at LO), around `base`.
    pub fn grid_per_axis(
        base: &Scenario,
        ranges: &[(Range, usize)],
    ) -> Result<Conditions, ConditionError> {
        let mut axes: Vec<(Quantity, Vec<f64>)> = Vec::new();
        let mut points = 0;
        for q in Quantity::ALL {
            let given: Vec<&(Range, usize)> =
                ranges.iter().filter(|(r, _)| r.quantity == q).collect();
            let Some(&&(r, n)) = given.first() else {
                continue;
            };
            if given.len() > 1 {
                return Err(ConditionError::Repeated { flag: q.flag() });
            }
            if n == 0 {
                return Err(ConditionError::Points {
                    points: n,
                    message: format!("{}: expected at least 1 point", q.flag()),
                });
            }
            check_range(base, &r)?;
            if n == 1 && r.hi > r.lo {
                return Err(ConditionError::Points {
                    points: n,
                    message: format!(
                        "{} {}:{} with 1 point would be held at LO and drop HI: give 2 or more points to sweep it, or LO:LO to hold it",
                        q.flag(),
                        Shown(r.lo),
                        Shown(r.hi)
                    ),
                });
            }
            let n = if r.hi > r.lo { n } else { 1 };
            points = points.max(n);
            let values = (0..n)
                .map(|i| {
                    if n == 1 {
                        r.lo
                    } else {
                        r.lo + (r.hi - r.lo) * i as f64 / (n - 1) as f64
                    }
                })
                .collect();
            axes.push((q, values));
        }
        let total = axes
            .iter()
            .try_fold(1usize, |acc, (_, v)| acc.checked_mul(v.len()));
        match total {
            Some(t) if t <= MAX_CONDITIONS => {}
            _ => {
                return Err(ConditionError::Points {
                    points,
                    message: format!(
                        "{} axes of {points} points exceed {MAX_CONDITIONS} conditions: give fewer points or fewer ranges",
                        axes.len()
                    ),
                });
            }
        }
        let mut list = vec![Condition {
            flight: base.flight.clone(),
        }];
        for (q, values) in &axes {
            list = list
                .iter()
                .flat_map(|c| {
                    values.iter().map(move |&v| {
                        let mut f = c.flight.clone();
                        q.set(&mut f, v);
                        Condition { flight: f }
                    })
                })
                .collect();
        }
        Ok(Conditions {
            list,
            axes: axes.into_iter().filter(|(_, v)| v.len() > 1).collect(),
            base: base.flight.clone(),
        })
    }

    /// The scenario of condition `k`: `base` flown at it.
    pub fn scenario(&self, base: &Scenario, k: usize) -> Scenario {
        let mut s = base.clone();
        s.flight = self.list[k].flight.clone();
        s
    }
}

/// Checks one range: finite, ordered, accepted by the scenario at both ends (the other
/// quantities at the base condition) and within the model's domain and its tables'
/// breakpoints ([`crate::domain`]).
fn check_range(base: &Scenario, r: &Range) -> Result<(), ConditionError> {
    let bad = |message: String| ConditionError::Range {
        flag: r.quantity.flag(),
        lo: r.lo,
        hi: r.hi,
        message,
    };
    if !(r.lo.is_finite() && r.hi.is_finite()) {
        return Err(bad("expected finite numbers".into()));
    }
    if r.lo > r.hi {
        return Err(bad("LO is above HI".into()));
    }
    for v in [r.lo, r.hi] {
        let mut s = base.clone();
        r.quantity.set(&mut s.flight, v);
        s.validate("the planned condition").map_err(|e| {
            bad(format!(
                "{} is not a condition the scenario can fly: {e}",
                Shown(v)
            ))
        })?;
    }
    if let Some(q) = r.quantity.bounded() {
        for v in [r.lo, r.hi] {
            crate::domain::check_value(base, q, v).map_err(|e| bad(e.to_string()))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn range(quantity: Quantity, lo: f64, hi: f64) -> Range {
        Range { quantity, lo, hi }
    }

    #[test]
    fn a_grid_varies_the_given_axes_and_holds_the_others() {
        let s = Scenario::embedded_default();
        let c = Conditions::grid(
            &s,
            &[
                range(Quantity::Mach, 0.6, 0.9),
                range(Quantity::AlphaDeg, 2.0, 2.0),
            ],
            4,
        )
        .unwrap();
        assert_eq!(c.list.len(), 4);
        assert_eq!(c.axes.len(), 1);
        assert!((c.list[3].flight.mach - 0.9).abs() < 1e-12);
        assert!(
            c.list
                .iter()
                .all(|k| (k.flight.alpha_deg - 2.0).abs() < 1e-12)
        );
        assert!(
            c.list
                .iter()
                .all(|k| (k.flight.altitude_m - s.flight.altitude_m).abs() < 1e-12)
        );
    }

    #[test]
    fn bad_ranges_name_their_flag() {
        let s = Scenario::embedded_default();
        let e = |r: Range| Conditions::grid(&s, &[r], 3).unwrap_err().to_string();
        assert!(e(range(Quantity::Mach, 0.9, 0.6)).contains("--mach 0.9:0.6: LO is above HI"));
        assert!(e(range(Quantity::Mach, -0.5, 0.6)).starts_with("--mach -0.5:0.6"));
        assert!(e(range(Quantity::AltitudeM, 0.0, f64::NAN)).contains("finite"));
        assert!(e(range(Quantity::AlphaDeg, 0.0, 95.0)).starts_with("--alpha-deg"));
        let one = Conditions::grid(&s, &[range(Quantity::Mach, 0.5, 0.9)], 1).unwrap_err();
        assert_eq!(
            one.to_string(),
            "--points 1: --mach 0.5:0.9 with 1 point would be held at LO and drop HI: give 2 or more points to sweep it, or LO:LO to hold it"
        );
        let held = Conditions::grid(&s, &[range(Quantity::Mach, 0.7, 0.7)], 1).unwrap();
        assert_eq!(held.list.len(), 1);
        let points = Conditions::grid(&s, &[range(Quantity::Mach, 0.5, 0.9)], 0).unwrap_err();
        assert!(points.to_string().starts_with("--points 0"), "{points}");
        let five: Vec<Range> = Quantity::ALL.iter().map(|&q| range(q, 0.5, 0.6)).collect();
        let many = Conditions::grid(&s, &five, 10).unwrap_err().to_string();
        assert!(many.contains("exceed"), "{many}");
    }
}
