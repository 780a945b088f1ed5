//! Stage 4, **check**: the file's `checkData` cases (DAVE-ML 2.0 / S-119 section 5.8,
//! `staticShot`: `checkInputs` and `checkOutputs` signals with an optional `tol`) evaluated
//! through the imported scenario's tables; every output the map gives a field must match to its
//! tolerance, or nothing is written.
//!
//! Choices the standard leaves open (docs/daveml.md): a signal names a variable by `varID` or
//! `name`; its `signalUnits`, when given, are its unit (else its variable's); an output without
//! `tol` must match to [`DEFAULT_TOL`] of max(1, |value|); inputs the map does not know
//! (altitude, ...) are ignored, and so are outputs it ignores.

use sepval_common::scenario::Scenario;
use sepval_common::table::{Coefficient, Variable};

use crate::assemble::field;
use crate::error::{DavemlError, Mismatch};
use crate::import::kind_of;
use crate::map::{Map, Role};
use crate::parse::{Located, Parsed, Signal, VariableDef};
use crate::units;

/// The relative tolerance of an output given without `tol`.
pub const DEFAULT_TOL: f64 = 1e-6;

/// The variable a signal names.
fn variable_of<'a>(
    p: &'a Parsed,
    s: &Located<Signal>,
) -> Result<&'a Located<VariableDef>, DavemlError> {
    let n = s.item.name.as_str();
    p.variables
        .iter()
        .find(|v| v.item.var_id == n)
        .or_else(|| p.variables.iter().find(|v| v.item.name == n))
        .ok_or_else(|| {
            DavemlError::at(
                &s.place,
                format!("unknown variable `{n}`: no <variableDef> has this varID or name"),
            )
        })
}

/// Checks every case; returns how many outputs were compared.
pub fn check(p: &Parsed, map: &Map, scenario: &Scenario) -> Result<usize, DavemlError> {
    let mut compared = 0;
    for case in &p.checks {
        let mut x: Vec<(Variable, f64)> = Vec::new();
        for s in &case.item.inputs {
            let v = variable_of(p, s)?;
            if let Some(Role::Input(var)) = map.role(&v.item.var_id, &v.item.name) {
                let u = s.item.units.as_deref().unwrap_or(&v.item.units);
                let c = units::input(var, u).map_err(|e| {
                    DavemlError::at(&s.place, format!("signalUnits `{u}`: expected {e}"))
                })?;
                x.push((var, c.apply(s.item.value)));
            }
        }
        for s in &case.item.outputs {
            let v = variable_of(p, s)?;
            let Some(Role::Output(o)) = map.role(&v.item.var_id, &v.item.name) else {
                continue;
            };
            let raw = match field(scenario, o.target) {
                Some(Coefficient::Table(t)) => {
                    let mut at = Vec::new();
                    for a in t.axes() {
                        let value = x.iter().find(|(w, _)| *w == a.variable).ok_or_else(|| {
                            DavemlError::at(
                                &case.place,
                                format!(
                                    "case `{}` gives no {} for {}",
                                    case.item.name,
                                    a.variable.csv_name(),
                                    v.item.var_id
                                ),
                            )
                        })?;
                        at.push(value.1);
                    }
                    t.value_at(&at)
                }
                Some(Coefficient::Constant(c)) => *c,
                _ => continue,
            };
            let u = s.item.units.as_deref().unwrap_or(&v.item.units);
            let c = units::output(kind_of(o.target), u).map_err(|e| {
                DavemlError::at(&s.place, format!("signalUnits `{u}`: expected {e}"))
            })?;
            let got = c.invert(if o.negate { -raw } else { raw });
            let expected = s.item.value;
            let tol = s.item.tol.unwrap_or(DEFAULT_TOL * expected.abs().max(1.0));
            if (got - expected).abs() > tol || !got.is_finite() {
                return Err(DavemlError::Check(Box::new(Mismatch {
                    place: s.place.clone(),
                    case: case.item.name.clone(),
                    output: v.item.var_id.clone(),
                    got,
                    expected,
                    tol,
                })));
            }
            compared += 1;
        }
    }
    Ok(compared)
}
