//! The other direction: a scenario's fields written as a DAVE-ML 2.0 model (and an update's
//! corrected tables with their standard deviations as `uncertainty`), so that another tool reads
//! the store's aerodynamics and verifies its import with the `checkData` cases sepval computes.
//!
//! Source: DAVE-ML 2.0 reference manual / ANSI/AIAA S-119-2011: the document's order is
//! `fileHeader`, `variableDef`s, `breakpointDef`s, `griddedTableDef`s, `function`s, `checkData`
//! (section 5.1); `fileHeader` holds `author`, `creationDate`, `fileVersion`, `description`
//! (5.2); an uncertainty is a `normalPDF` with `numSigmas` and its `bounds` as a `dataTable`
//! of the table's shape, with `correlation`s to other variables (5.7). Choices (docs/daveml.md):
//! one `variableDef` per input sepval's tables use (`mach` nd, `alpha` and `beta` deg,
//! `distance` and `lateral` m) and per field, named as the default map reads them back
//! ([`crate::map`]); a constant field as `initialValue`; breakpoint sets shared between tables
//! when equal; every `independentVarRef` `extrapolate="neither"` and `interpolate="linear"`
//! (sepval's tables hold their edges and are linear).

use crate::error::ExportError;
use std::collections::BTreeSet;

use sepval_common::correction::Target;
use sepval_common::scenario::Scenario;
use sepval_common::table::{Coefficient, Table, Variable};

use crate::assemble::field;
use crate::import::kind_of;
pub use crate::names::{input_id, output_id};
use crate::units::{written_input, written_output};
use crate::xml::{Xml, number};

/// The DAVE-ML 2.0 namespace.
pub const NAMESPACE: &str = "http://daveml.org/2010/DAVEML";

/// Where a model came from, for its `fileHeader`.
#[derive(Debug, Clone, PartialEq)]
pub struct Provenance {
    /// sepval's version.
    pub sepval_version: String,
    /// The date written, `YYYY-MM-DD`.
    pub date: String,
    /// The releases used (an update's `--data` files), if any.
    pub releases: Vec<String>,
    /// What the model is (the scenario, the command).
    pub source: String,
}

impl Provenance {
    /// This sepval's provenance, dated today, of a model made by `source` from `releases`.
    pub fn now(source: String, releases: Vec<String>) -> Provenance {
        Provenance {
            sepval_version: env!("CARGO_PKG_VERSION").to_string(),
            date: crate::today(),
            releases,
            source,
        }
    }
}

/// A field's standard deviation at each value of its table (an update's correction).
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// The field.
    pub target: Target,
    /// One standard deviation per table value (row-major, as the table's values).
    pub sigma: Vec<f64>,
    /// Correlation coefficients with other fields' values, where known.
    pub correlations: Vec<(Target, f64)>,
}

/// A field of the scenario as it is written.
struct Written<'a> {
    target: Target,
    value: &'a Coefficient,
    band: Option<&'a Band>,
}

/// A breakpoint set written once and shared.
struct BreakpointSet {
    id: String,
    variable: Variable,
    values: Vec<f64>,
}

/// The scenario's fields as a DAVE-ML 2.0 document (text).
pub fn to_daveml(s: &Scenario, bands: &[Band], prov: &Provenance) -> Result<String, ExportError> {
    if s.flowfield.is_some() {
        // Its increments would be written as zeros and the field itself not at all: a file
        // that flies another store (docs/daveml.md).
        return Err(ExportError::Flowfield);
    }
    let fields: Vec<Written> = Target::all()
        .into_iter()
        .filter_map(|t| {
            field(s, t).map(|value| Written {
                target: t,
                value,
                band: bands.iter().find(|b| b.target == t),
            })
        })
        .collect();
    for b in bands {
        let Some(w) = fields.iter().find(|w| w.target == b.target) else {
            return Err(ExportError::BandWithoutField {
                field: b.target.field(),
            });
        };
        match w.value {
            Coefficient::Table(t) if t.values().len() == b.sigma.len() => {}
            _ => {
                return Err(ExportError::BandValues {
                    field: b.target.field(),
                    values: b.sigma.len(),
                });
            }
        }
    }
    let sets = breakpoint_sets(&fields);
    let inputs: BTreeSet<Variable> = std::iter::once(Variable::Mach)
        .chain(sets.iter().map(|b| b.variable))
        .collect();
    let mut x = Xml::new();
    x.open("DAVEfunc", &[("xmlns", NAMESPACE)]);
    header(&mut x, s, prov);
    variables(&mut x, &inputs, &fields, s);
    for b in &sets {
        x.open(
            "breakpointDef",
            &[
                ("name", &b.id),
                ("bpID", &b.id),
                ("units", written_input(b.variable)),
            ],
        );
        x.numbers("bpVals", &b.values, 8);
        x.close("breakpointDef");
    }
    for w in &fields {
        if let Coefficient::Table(t) = w.value {
            table(&mut x, w, t, &sets);
        }
    }
    for w in &fields {
        if let Coefficient::Table(t) = w.value {
            function(&mut x, w.target, t);
        }
    }
    crate::shots::check_data(&mut x, &inputs, &fields_of(&fields), s);
    x.close("DAVEfunc");
    Ok(x.finish())
}

fn fields_of<'a>(fields: &'a [Written<'a>]) -> Vec<(Target, &'a Coefficient)> {
    fields.iter().map(|w| (w.target, w.value)).collect()
}

fn header(x: &mut Xml, s: &Scenario, prov: &Provenance) {
    x.open("fileHeader", &[("name", &s.name)]);
    x.empty(
        "author",
        &[
            ("name", &format!("sepval {}", prov.sepval_version)),
            ("org", "sepval"),
        ],
    );
    x.empty("creationDate", &[("date", &prov.date)]);
    x.leaf(
        "fileVersion",
        &[],
        &format!("sepval {}", prov.sepval_version),
    );
    let releases = if prov.releases.is_empty() {
        "no releases (the scenario's own data)".to_string()
    } else {
        format!("the releases {}", prov.releases.join(", "))
    };
    let beyond = if s.extension.is_empty() && s.correction.is_empty() {
        String::new()
    } else {
        format!(
            " Not in this file: the scenario's {} model-extension term(s) and {} correction(s) (docs/model.md), which sepval adds to these tables.",
            s.extension.len(),
            s.correction.len()
        )
    };
    x.leaf(
        "description",
        &[],
        &format!(
            "{} written by sepval {} on {} from {}, using {}. Axes: body axes of docs/model.md section 2 (CA axial, positive aft; CZ positive down); moments about the CG, reference diameter {} m. Tables hold their edge values outside their breakpoints.{beyond}",
            s.name,
            prov.sepval_version,
            prov.date,
            prov.source,
            releases,
            number(s.store.diameter_m)
        ),
    );
    x.close("fileHeader");
}

fn variables(x: &mut Xml, inputs: &BTreeSet<Variable>, fields: &[Written], s: &Scenario) {
    for &v in inputs {
        let id = input_id(v);
        x.open(
            "variableDef",
            &[("name", id), ("varID", id), ("units", written_input(v))],
        );
        x.leaf("description", &[], &input_description(v));
        x.close("variableDef");
    }
    for w in fields {
        let id = output_id(w.target);
        let units = written_output(kind_of(w.target));
        let mut attrs = vec![("name", id), ("varID", id), ("units", units)];
        let initial;
        if let Coefficient::Constant(c) = w.value {
            initial = number(*c);
            attrs.push(("initialValue", &initial));
        }
        x.open("variableDef", &attrs);
        x.leaf(
            "description",
            &[],
            &output_description(w.target, w.value, s),
        );
        if matches!(w.value, Coefficient::Table(_)) {
            x.empty("isOutput", &[]);
        }
        x.close("variableDef");
    }
}

fn input_description(v: Variable) -> String {
    match v {
        Variable::Mach => "free-stream Mach number of the flight condition".into(),
        Variable::Alpha => "the store's local angle of attack atan2(w, u)".into(),
        Variable::Beta => "the store's local sideslip asin(v / V)".into(),
        Variable::Distance => "distance of the store's CG from its carriage position".into(),
        Variable::Lateral => "lateral (launch-frame y) offset of the CG from carriage".into(),
        Variable::X | Variable::Y | Variable::Z => format!(
            "launch-frame {} of a point from the CG's carriage position",
            v.csv_name()
        ),
    }
}

fn output_description(t: Target, c: &Coefficient, s: &Scenario) -> String {
    let base = format!("sepval field {}", t.field());
    match (t, c) {
        (Target::Interference(_), Coefficient::Constant(_)) => format!(
            "{base}: the increment at carriage, times f(s) = (exp(-s/lambda) - exp(-s_end/lambda)) / (1 - exp(-s_end/lambda)) below s_end and 0 from s_end (docs/model.md section 3), lambda = {} m, s_end = {} m",
            number(s.interference.lambda_m),
            number(s.interference.s_end_m)
        ),
        (Target::Derivative(_), _) => format!("{base}, per radian"),
        _ => base,
    }
}

/// Every distinct (variable, breakpoints) of the tables, named `<variable>_<n>`.
fn breakpoint_sets(fields: &[Written]) -> Vec<BreakpointSet> {
    let mut sets: Vec<BreakpointSet> = Vec::new();
    for w in fields {
        let Coefficient::Table(t) = w.value else {
            continue;
        };
        for a in t.axes() {
            let same = |b: &BreakpointSet| {
                b.variable == a.variable
                    && b.values.len() == a.breakpoints.len()
                    && b.values
                        .iter()
                        .zip(&a.breakpoints)
                        .all(|(p, q)| p.to_bits() == q.to_bits())
            };
            if !sets.iter().any(same) {
                let n = sets.iter().filter(|b| b.variable == a.variable).count() + 1;
                sets.push(BreakpointSet {
                    id: format!("{}_{n}", input_id(a.variable)),
                    variable: a.variable,
                    values: a.breakpoints.clone(),
                });
            }
        }
    }
    sets
}

fn table(x: &mut Xml, w: &Written, t: &Table, sets: &[BreakpointSet]) {
    let id = format!("{}_table", output_id(w.target));
    let units = written_output(kind_of(w.target));
    x.open(
        "griddedTableDef",
        &[("name", &id), ("gtID", &id), ("units", units)],
    );
    x.open("breakpointRefs", &[]);
    for a in t.axes() {
        let set = sets
            .iter()
            .find(|b| {
                b.variable == a.variable
                    && b.values
                        .iter()
                        .map(|v| v.to_bits())
                        .eq(a.breakpoints.iter().map(|v| v.to_bits()))
            })
            .expect("every axis has its set");
        x.empty("bpRef", &[("bpID", &set.id)]);
    }
    x.close("breakpointRefs");
    if let Some(b) = w.band {
        x.open("uncertainty", &[("effect", "additive")]);
        x.open("normalPDF", &[("numSigmas", "1")]);
        x.open("bounds", &[]);
        x.numbers("dataTable", &b.sigma, row_length(t));
        x.close("bounds");
        for (other, _) in &b.correlations {
            x.empty("correlatesWith", &[("varID", output_id(*other))]);
        }
        for (other, rho) in &b.correlations {
            x.empty(
                "correlation",
                &[("varID", output_id(*other)), ("corrCoef", &number(*rho))],
            );
        }
        x.close("normalPDF");
        x.close("uncertainty");
    }
    x.numbers("dataTable", t.values(), row_length(t));
    x.close("griddedTableDef");
}

/// The number of values of a table's last axis (one row of its dataTable per line).
fn row_length(t: &Table) -> usize {
    t.axes().last().map_or(1, |a| a.breakpoints.len())
}

fn function(x: &mut Xml, target: Target, t: &Table) {
    let id = output_id(target);
    x.open("function", &[("name", id)]);
    x.leaf(
        "description",
        &[],
        &format!(
            "{id} ({}) by linear interpolation, held at the edges",
            target.field()
        ),
    );
    for a in t.axes() {
        x.empty(
            "independentVarRef",
            &[
                ("varID", input_id(a.variable)),
                ("min", &number(a.breakpoints[0])),
                ("max", &number(a.breakpoints[a.breakpoints.len() - 1])),
                ("extrapolate", "neither"),
                ("interpolate", "linear"),
            ],
        );
    }
    x.empty("dependentVarRef", &[("varID", id)]);
    x.open("functionDefn", &[("name", &format!("{id}_fn"))]);
    x.empty("griddedTableRef", &[("gtID", &format!("{id}_table"))]);
    x.close("functionDefn");
    x.close("function");
}
