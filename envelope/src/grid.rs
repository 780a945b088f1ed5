//! The envelope's grid: each axis given as `LO:HI:N` (N values from LO to HI, evenly spaced;
//! N = 1 holds the axis at LO, and so is refused unless LO = HI: `0.6:1.2:1` would drop HI), the conditions their product around the condition of the
//! source's first release (an axis not given stays there), each range checked as a plan's is
//! (`sepval_run::conditions`: finite, ordered, a condition the scenario can fly, within the
//! model's domain and its tables' breakpoints, `sepval_run::domain`). At most [`MAX_CONDITIONS`] conditions and [`MAX_POINTS`]
//! per axis.
//!
//! The map shows the first two varied axes in the order Mach, altitude, alpha, beta, gamma;
//! with more than two varied, a cell shows the worst of the conditions it covers (the
//! highest probability of failing to clear).

use sepval_common::scenario::{Flight, Scenario};
use sepval_run::conditions::{ConditionError, Conditions, Quantity, Range};

/// The most conditions of one envelope.
pub const MAX_CONDITIONS: usize = 2500;
/// The most values of one axis.
pub const MAX_POINTS: usize = 100;

/// An axis that cannot be swept.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GridError {
    /// Not `LO:HI:N`.
    #[error("{flag} {text}: {message}")]
    Syntax {
        /// The flag.
        flag: &'static str,
        /// What was given.
        text: String,
        /// What is wrong.
        message: String,
    },
    /// A range the scenario cannot fly, or a grid too large.
    #[error(transparent)]
    Condition(#[from] ConditionError),
    /// Too many conditions.
    #[error(
        "the grid has {conditions} conditions, above the limit of {MAX_CONDITIONS}: give fewer points"
    )]
    TooMany {
        /// Conditions asked for.
        conditions: usize,
    },
}

/// One axis as given: its range and number of values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    /// The range.
    pub range: Range,
    /// Values.
    pub points: usize,
}

impl Axis {
    /// Parses `LO:HI:N` given with `quantity`'s flag.
    pub fn parse(quantity: Quantity, text: &str) -> Result<Axis, GridError> {
        let flag = quantity.flag();
        let bad = |message: &str| GridError::Syntax {
            flag,
            text: text.to_string(),
            message: message.to_string(),
        };
        let parts: Vec<&str> = text.split(':').map(str::trim).collect();
        let [lo, hi, n] = parts.as_slice() else {
            return Err(bad("expected LO:HI:N, e.g. 0.6:0.95:8"));
        };
        let number = |s: &str, what: &str| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| bad(&format!("{what} `{s}` is not a finite number")))
        };
        let (lo, hi) = (number(lo, "LO")?, number(hi, "HI")?);
        let points: usize = n
            .parse()
            .map_err(|_| bad(&format!("N `{n}` is not a whole number")))?;
        if points == 0 || points > MAX_POINTS {
            return Err(bad(&format!("N must be from 1 to {MAX_POINTS}")));
        }
        if points > 1 && lo >= hi {
            return Err(bad("with N > 1, LO must be below HI"));
        }
        if points == 1 && lo.to_bits() != hi.to_bits() {
            let (lo_text, hi_text) = (parts[0], parts[1]);
            return Err(bad(&format!(
                "N = 1 holds the axis at one value, so HI {hi_text} would be dropped: give \
                 {lo_text}:{lo_text}:1 to hold it at {lo_text}, or N of 2 or more to sweep from \
                 {lo_text} to {hi_text}"
            )));
        }
        Ok(Axis {
            range: Range { quantity, lo, hi },
            points,
        })
    }
}

/// The conditions of an envelope.
#[derive(Debug, Clone)]
pub struct Grid {
    /// The conditions (the last varied axis fastest).
    pub conditions: Conditions,
    /// The axes of the map: indices into `conditions.axes` (none, one or two).
    pub shown: Vec<usize>,
}

impl Grid {
    /// The grid over `axes` around `base` (the source's first release).
    pub fn of(base: &Scenario, axes: &[Axis]) -> Result<Grid, GridError> {
        let total = axes
            .iter()
            .try_fold(1usize, |acc, a| acc.checked_mul(a.points));
        match total {
            Some(t) if t <= MAX_CONDITIONS => {}
            t => {
                return Err(GridError::TooMany {
                    conditions: t.unwrap_or(usize::MAX),
                });
            }
        }
        let per_axis: Vec<(Range, usize)> = axes.iter().map(|a| (a.range, a.points)).collect();
        let conditions = Conditions::grid_per_axis(base, &per_axis)?;
        let shown = (0..conditions.axes.len().min(2)).collect();
        Ok(Grid { conditions, shown })
    }

    /// Conditions.
    pub fn len(&self) -> usize {
        self.conditions.list.len()
    }

    /// Whether it has none.
    pub fn is_empty(&self) -> bool {
        self.conditions.list.is_empty()
    }

    /// Condition `k`'s flight condition.
    pub fn flight(&self, k: usize) -> &Flight {
        &self.conditions.list[k].flight
    }

    /// The scenario of condition `k`: `base` flown at it.
    pub fn scenario(&self, base: &Scenario, k: usize) -> Scenario {
        self.conditions.scenario(base, k)
    }

    /// The map's axes: quantity and values of each shown axis.
    pub fn map_axes(&self) -> Vec<(Quantity, &[f64])> {
        self.shown
            .iter()
            .map(|&a| {
                let (q, v) = &self.conditions.axes[a];
                (*q, v.as_slice())
            })
            .collect()
    }

    /// The map cell (ix, iy) of condition `k`.
    pub fn cell(&self, k: usize) -> (usize, usize) {
        let axes = &self.conditions.axes;
        let mut at = vec![0; axes.len()];
        let mut rest = k;
        for (a, (_, values)) in axes.iter().enumerate().rev() {
            at[a] = rest % values.len();
            rest /= values.len();
        }
        (
            self.shown.first().map_or(0, |&a| at[a]),
            self.shown.get(1).map_or(0, |&a| at[a]),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_axis_is_lo_hi_n_and_bad_ones_are_refused_by_name() {
        let a = Axis::parse(Quantity::Mach, "0.6:0.9:4").unwrap();
        assert_eq!(a.points, 4);
        assert_eq!(a.range.lo.to_bits(), 0.6f64.to_bits());
        for bad in [
            "0.6:0.9",
            "0.6:0.9:0",
            "0.9:0.6:3",
            "x:0.9:3",
            "0.6:0.9:2.5",
            "0.6:nan:3",
            "0.6:1.2:1",
            "1.2:0.6:1",
        ] {
            let e = Axis::parse(Quantity::Mach, bad).unwrap_err().to_string();
            assert!(e.starts_with(&format!("--mach {bad}")), "{e}");
        }
        assert!(Axis::parse(Quantity::AltitudeM, "3000:3000:1").is_ok());
        let e = Axis::parse(Quantity::Mach, "0.6:1.2:1")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "--mach 0.6:1.2:1: N = 1 holds the axis at one value, so HI 1.2 would be dropped: give \
             0.6:0.6:1 to hold it at 0.6, or N of 2 or more to sweep from 0.6 to 1.2"
        );
    }

    #[test]
    fn the_grid_is_the_product_and_each_condition_has_its_cell() {
        let s = Scenario::embedded_default();
        let axes = [
            Axis::parse(Quantity::Mach, "0.6:0.9:4").unwrap(),
            Axis::parse(Quantity::AltitudeM, "1000:5000:3").unwrap(),
        ];
        let g = Grid::of(&s, &axes).unwrap();
        assert_eq!(g.len(), 12);
        let cells: Vec<(usize, usize)> = (0..12).map(|k| g.cell(k)).collect();
        assert_eq!(cells[0], (0, 0));
        assert_eq!(cells[1], (0, 1), "altitude varies fastest");
        assert_eq!(cells[11], (3, 2));
        assert_eq!(g.flight(11).mach.to_bits(), 0.9f64.to_bits());
        assert_eq!(g.flight(11).altitude_m.to_bits(), 5000.0f64.to_bits());
        let too_high = [Axis::parse(Quantity::AltitudeM, "1000:12000:3").unwrap()];
        assert!(Grid::of(&s, &too_high).is_err());
    }
}
