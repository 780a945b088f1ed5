//! The `checkData` sepval writes (DAVE-ML 2.0 / S-119 section 5.8): static shots at a few
//! points of the tables' ranges, each giving every input and every field's value there as
//! sepval's tables compute it, with a tolerance, so the receiving tool can verify its import.
//!
//! Choices (docs/daveml.md): three shots (one when no table spans an input), at 0.25, 0.5 and
//! 0.8 of each input's range over all tables (between breakpoints, so interpolation is exercised, and inside every table's edges
//! where the ranges agree); Mach alone, when no table spans it, at the flight's Mach. Each
//! output's tolerance is 1e-9 of max(1, the largest magnitude of its table): other tools'
//! interpolation differs from sepval's by rounding only.

use std::collections::BTreeSet;

use sepval_common::correction::Target;
use sepval_common::scenario::Scenario;
use sepval_common::table::{Coefficient, Variable};

use crate::import::kind_of;
use crate::names::{input_id, output_id};
use crate::units::{written_input, written_output};
use crate::xml::{Xml, number};

/// Where in each input's range the shots are.
const FRACTIONS: [f64; 3] = [0.25, 0.5, 0.8];
/// The relative tolerance of a shot's output.
pub const SHOT_TOL: f64 = 1e-9;

/// The range of `v` over every table, or `None` when no table spans it.
fn range(fields: &[(Target, &Coefficient)], v: Variable) -> Option<(f64, f64)> {
    let mut r: Option<(f64, f64)> = None;
    for (_, c) in fields {
        if let Coefficient::Table(t) = c {
            for a in t.axes().iter().filter(|a| a.variable == v) {
                let (lo, hi) = (a.breakpoints[0], a.breakpoints[a.breakpoints.len() - 1]);
                r = Some(r.map_or((lo, hi), |(l, h)| (l.min(lo), h.max(hi))));
            }
        }
    }
    r
}

/// The value of a field at the inputs `x`.
fn value(c: &Coefficient, x: &[(Variable, f64)]) -> Option<f64> {
    match c {
        Coefficient::Constant(v) => Some(*v),
        Coefficient::Table(t) => {
            let at: Vec<f64> = t
                .axes()
                .iter()
                .map(|a| {
                    x.iter()
                        .find(|(w, _)| *w == a.variable)
                        .map_or(0.0, |p| p.1)
                })
                .collect();
            Some(t.value_at(&at))
        }
        Coefficient::File(_) => None,
    }
}

fn tol(c: &Coefficient) -> f64 {
    let scale = match c {
        Coefficient::Constant(v) => v.abs(),
        Coefficient::Table(t) => t.values().iter().fold(0.0f64, |m, v| m.max(v.abs())),
        Coefficient::File(_) => 0.0,
    };
    SHOT_TOL * scale.max(1.0)
}

fn signal(x: &mut Xml, name: &str, units: &str, v: f64, tol: Option<f64>) {
    x.open("signal", &[]);
    x.leaf("signalName", &[], name);
    x.leaf("signalUnits", &[], units);
    x.leaf("signalValue", &[], &number(v));
    if let Some(t) = tol {
        x.leaf("tol", &[], &number(t));
    }
    x.close("signal");
}

/// Writes `checkData` for `fields` over `inputs`.
pub fn check_data(
    x: &mut Xml,
    inputs: &BTreeSet<Variable>,
    fields: &[(Target, &Coefficient)],
    s: &Scenario,
) {
    x.open("checkData", &[]);
    let mut shots: Vec<Vec<(Variable, f64)>> = Vec::new();
    for f in FRACTIONS {
        let at: Vec<(Variable, f64)> = inputs
            .iter()
            .map(|&v| {
                let p = range(fields, v).map_or(s.flight.mach, |(lo, hi)| lo + f * (hi - lo));
                (v, p)
            })
            .collect();
        // No table spans an input: every shot would be the same one.
        if !shots.contains(&at) {
            shots.push(at);
        }
    }
    for (k, at) in shots.iter().enumerate() {
        let at = at.as_slice();
        x.open("staticShot", &[("name", &format!("sepval case {}", k + 1))]);
        x.open("checkInputs", &[]);
        for (v, p) in at {
            signal(x, input_id(*v), written_input(*v), *p, None);
        }
        x.close("checkInputs");
        x.open("checkOutputs", &[]);
        for (t, c) in fields {
            if let Some(y) = value(c, at) {
                let units = written_output(kind_of(*t));
                signal(x, output_id(*t), units, y, Some(tol(c)));
            }
        }
        x.close("checkOutputs");
        x.close("staticShot");
    }
    x.close("checkData");
}
