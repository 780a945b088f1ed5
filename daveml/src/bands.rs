//! An update's corrections as the bands of the tables they were merged into: each correction's
//! standard deviation (given at its own breakpoints over one variable, docs/update.md) at every
//! value of its field's table, for the `normalPDF` the DAVE-ML file carries.
//!
//! Choices (docs/daveml.md): between a correction's breakpoints its standard deviation is
//! interpolated linearly like the correction itself, which bounds the standard deviation of the
//! interpolated value from above (sd(a X + b Y) <= a sd(X) + b sd(Y) for a, b >= 0, whatever the
//! correlation); outside them it is held, as the correction is. Two corrections of one field add
//! in quadrature (they are fitted as separate terms; their correlation is not recorded). The
//! update records no correlation between corrections, so none is written.

use sepval_common::correction::{Target, interpolate};
use sepval_common::scenario::Scenario;
use sepval_common::table::{Coefficient, Variable};

use crate::assemble::field;
use crate::error::DavemlError;
use crate::export::Band;

/// A correction's standard deviation as an update records it (`update.json`).
#[derive(Debug, Clone, PartialEq)]
pub struct CorrectionSpread {
    /// The field corrected, e.g. `aero.cm`.
    pub field: String,
    /// Its variable's key: `mach`, `alpha_deg`, `beta_deg` or `distance_m`.
    pub variable: String,
    /// Its breakpoints.
    pub breakpoints: Vec<f64>,
    /// Its standard deviation at each.
    pub std: Vec<f64>,
}

/// The bands of the fields of `s` the `corrections` changed.
pub fn bands(s: &Scenario, corrections: &[CorrectionSpread]) -> Result<Vec<Band>, DavemlError> {
    let mut out: Vec<Band> = Vec::new();
    for c in corrections {
        let refuse = |message: String| DavemlError::Band {
            field: c.field.clone(),
            message,
        };
        let target = Target::table_of_field(&c.field)
            .ok_or_else(|| refuse("not a field of the store's tables".into()))?;
        let variable = Variable::ALL
            .into_iter()
            .find(|v| v.key() == c.variable)
            .ok_or_else(|| refuse(format!("variable `{}` is not one of sepval's", c.variable)))?;
        if c.breakpoints.is_empty() || c.breakpoints.len() != c.std.len() {
            return Err(refuse(format!(
                "{} breakpoints and {} standard deviations",
                c.breakpoints.len(),
                c.std.len()
            )));
        }
        let Some(Coefficient::Table(t)) = field(s, target) else {
            return Err(refuse("not a table in the updated store".into()));
        };
        let k = t
            .axes()
            .iter()
            .position(|a| a.variable == variable)
            .ok_or_else(|| refuse(format!("its table has no {} axis", variable.csv_name())))?;
        let sizes: Vec<usize> = t.axes().iter().map(|a| a.breakpoints.len()).collect();
        let stride: usize = sizes[k + 1..].iter().product();
        let sigma: Vec<f64> = (0..t.values().len())
            .map(|i| {
                let x = t.axes()[k].breakpoints[(i / stride) % sizes[k]];
                interpolate(&c.breakpoints, &c.std, x)
            })
            .collect();
        match out.iter_mut().find(|b| b.target == target) {
            Some(b) => {
                for (a, s) in b.sigma.iter_mut().zip(&sigma) {
                    *a = a.hypot(*s);
                }
            }
            None => out.push(Band {
                target,
                sigma,
                correlations: Vec::new(),
            }),
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use sepval_common::table::{Axis, Kind, Table, Tabulated};

    #[test]
    fn a_correction_over_alpha_spreads_over_its_tables_alpha_axis() {
        let mut s = Scenario::embedded_default();
        let axes = vec![
            Axis {
                variable: Variable::Mach,
                breakpoints: vec![0.5, 1.0],
            },
            Axis {
                variable: Variable::Alpha,
                breakpoints: vec![-10.0, 0.0, 5.0, 10.0],
            },
        ];
        let t = Table::new(axes, vec![0.0; 8], Kind::Static).unwrap();
        s.aero.cm = Some(Tabulated::table(t).unwrap());
        let c = CorrectionSpread {
            field: "aero.cm".into(),
            variable: "alpha_deg".into(),
            breakpoints: vec![-10.0, 10.0],
            std: vec![0.02, 0.04],
        };
        let b = bands(&s, &[c.clone(), c]).unwrap();
        assert_eq!(b.len(), 1);
        let one: [f64; 4] = [0.02, 0.03, 0.035, 0.04];
        for (i, got) in b[0].sigma.iter().enumerate() {
            let want = one[i % 4].hypot(one[i % 4]);
            assert!((got - want).abs() <= 1e-15, "{i}: {got} {want}");
        }
        let bad = CorrectionSpread {
            field: "aero.cl".into(),
            variable: "alpha_deg".into(),
            breakpoints: vec![0.0],
            std: vec![0.1],
        };
        assert!(bands(&s, &[bad]).is_err());
    }
}
