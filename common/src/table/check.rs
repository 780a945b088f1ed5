//! The checks of a table's grid and values (the caller says which table).

use sepval_core::number_text::Shown;

use super::{Axis, Kind, MAX_TABLE_VALUES, Variable, unit_suffix};

/// What makes a table's axes or values unusable; the message continues a sentence that names
/// the table ("the table ...", "`aero.cm` ...").
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TableShapeError {
    /// No axis, or more than three.
    #[error("has {axes} axes: expected one to three of {}", kind.allowed_list(", "))]
    AxisCount {
        /// The axes given.
        axes: usize,
        /// What the table tabulates.
        kind: Kind,
    },
    /// An axis over a variable the kind may not span.
    #[error(
        "is a table over {}: {} may be tabulated over {} only",
        variable.csv_name(),
        kind.what(),
        kind.allowed_list(", ")
    )]
    Variable {
        /// The axis's variable.
        variable: Variable,
        /// What the table tabulates.
        kind: Kind,
    },
    /// Axes out of nesting order.
    #[error("axes must nest in the order {}", kind.allowed_list(", "))]
    Order {
        /// What the table tabulates.
        kind: Kind,
    },
    /// No axis over the variable every table of the kind spans.
    #[error(
        "has no {} axis: {} is tabulated over {} at least",
        required.csv_name(),
        kind.what(),
        required.csv_name()
    )]
    Required {
        /// The variable required.
        required: Variable,
        /// What the table tabulates.
        kind: Kind,
    },
    /// A grid over the limit.
    #[error("has {points} grid points, more than the limit of {MAX_TABLE_VALUES}")]
    TooManyPoints {
        /// The grid's points.
        points: usize,
    },
    /// Not one value per grid point.
    #[error("has {values} values for a grid of {points} points")]
    ValueCount {
        /// The values given.
        values: usize,
        /// The grid's points.
        points: usize,
    },
    /// A value that is not a finite number.
    #[error("value {index} is {value}: expected finite values")]
    ValueNotFinite {
        /// Its index, row-major.
        index: usize,
        /// The value.
        value: f64,
    },
    /// An axis with fewer than two breakpoints.
    #[error(
        "axis {} has {count} breakpoint(s): expected at least 2 (give a constant instead of a table)",
        variable.csv_name()
    )]
    TooFewBreakpoints {
        /// The axis's variable.
        variable: Variable,
        /// Its breakpoints.
        count: usize,
    },
    /// A breakpoint that is not a finite number.
    #[error("axis {} breakpoint {index} is {value}: expected finite values", variable.csv_name())]
    BreakpointNotFinite {
        /// The axis's variable.
        variable: Variable,
        /// The breakpoint's index.
        index: usize,
        /// The breakpoint.
        value: f64,
    },
    /// A breakpoint outside its variable's domain.
    #[error(
        "axis {name} breakpoint {shown} is outside {name}'s domain, {lo} to {hi}{unit} ({why})",
        name = variable.csv_name(),
        shown = Shown(*value),
        lo = Shown(variable.domain().0),
        hi = Shown(variable.domain().1),
        unit = unit_suffix(*variable),
        why = variable.domain().2
    )]
    OutsideDomain {
        /// The axis's variable.
        variable: Variable,
        /// The breakpoint.
        value: f64,
    },
    /// Breakpoints that do not increase strictly.
    #[error(
        "axis {} breakpoints are not strictly increasing: {value} after {before}",
        variable.csv_name()
    )]
    NotIncreasing {
        /// The axis's variable.
        variable: Variable,
        /// The breakpoint before.
        before: f64,
        /// The one after it, not above it.
        value: f64,
    },
    /// Breakpoints whose spacing has no finite, non-zero inverse.
    #[error(
        "axis {} breakpoints {before} and {value} are too close together or too far apart to \
         interpolate between (their spacing's inverse is {inverse})",
        variable.csv_name()
    )]
    Spacing {
        /// The axis's variable.
        variable: Variable,
        /// The breakpoint before.
        before: f64,
        /// The breakpoint.
        value: f64,
        /// 1 / (value - before).
        inverse: f64,
    },
}

/// One to three axes, each allowed for `kind` and in nesting order, at least two finite
/// strictly increasing breakpoints each, one finite value per grid point.
pub(super) fn check_table(
    axes: &[Axis],
    values: &[f64],
    kind: Kind,
) -> Result<(), TableShapeError> {
    if axes.is_empty() || axes.len() > 3 {
        return Err(TableShapeError::AxisCount {
            axes: axes.len(),
            kind,
        });
    }
    let mut previous: Option<Variable> = None;
    for a in axes {
        if !kind.allowed().contains(&a.variable) {
            return Err(TableShapeError::Variable {
                variable: a.variable,
                kind,
            });
        }
        let rank = |v: Variable| kind.allowed().iter().position(|&w| w == v);
        if previous.is_some_and(|p| rank(p) >= rank(a.variable)) {
            return Err(TableShapeError::Order { kind });
        }
        previous = Some(a.variable);
        check_breakpoints(a.variable, &a.breakpoints)?;
    }
    if let Some(required) = kind.required()
        && !axes.iter().any(|a| a.variable == required)
    {
        return Err(TableShapeError::Required { required, kind });
    }
    let points: usize = axes.iter().map(|a| a.breakpoints.len()).product();
    if points > MAX_TABLE_VALUES {
        return Err(TableShapeError::TooManyPoints { points });
    }
    if values.len() != points {
        return Err(TableShapeError::ValueCount {
            values: values.len(),
            points,
        });
    }
    if let Some(index) = values.iter().position(|v| !v.is_finite()) {
        return Err(TableShapeError::ValueNotFinite {
            index,
            value: values[index],
        });
    }
    Ok(())
}

fn check_breakpoints(variable: Variable, b: &[f64]) -> Result<(), TableShapeError> {
    if b.len() < 2 {
        return Err(TableShapeError::TooFewBreakpoints {
            variable,
            count: b.len(),
        });
    }
    for (index, &value) in b.iter().enumerate() {
        if !value.is_finite() {
            return Err(TableShapeError::BreakpointNotFinite {
                variable,
                index,
                value,
            });
        }
        let (lo, hi, _) = variable.domain();
        if !(lo..=hi).contains(&value) {
            return Err(TableShapeError::OutsideDomain { variable, value });
        }
        if index > 0 && value <= b[index - 1] {
            return Err(TableShapeError::NotIncreasing {
                variable,
                before: b[index - 1],
                value,
            });
        }
        // An interval is interpolated across by its width's inverse: a width below 1e-308 (or
        // above 1e308) has none that is finite and non-zero, and the value there would be NaN.
        if index > 0 {
            let inverse = 1.0 / (value - b[index - 1]);
            if !(inverse.is_finite() && inverse > 0.0) {
                return Err(TableShapeError::Spacing {
                    variable,
                    before: b[index - 1],
                    value,
                    inverse,
                });
            }
        }
    }
    Ok(())
}
