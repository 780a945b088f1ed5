//! The updated store (docs/update.md section 15.7): every kept correction merged into the field
//! it corrects, as a table in the scenario's own form, and the scenario written with its tables
//! as CSV files that every command reads as they are.
//!
//! A correction c over variable x added to a field F (a constant or a table) is the table of
//! F + c on the union of F's grid and c's breakpoints along x (every other axis of F kept): a
//! sum of functions linear between their own breakpoints is linear between those of the union
//! grid, so the merged table is the same function as the field plus the correction, exactly up
//! to rounding. An interference increment given as a constant dC0 with its exponential decay
//! becomes a table over distance sampled from dC0 f(s) on the graded grid of `sepval scenario
//! --interference-tables` (`sepval_common::table_form::interference_distances`: within 3.5e-5 of
//! dC0 between breakpoints), joined with the correction's breakpoints.

use std::path::PathBuf;

use sepval_common::correction::{
    Correction, Derivative, FieldPart, Target, corrected_shape, interpolate,
};
use sepval_common::model::InterferenceDecay;
use sepval_common::scenario::Scenario;
use sepval_common::table::{
    Axis, Coefficient, Kind, Table, TableFile, TableKind, Tabulated, Variable, write_csv,
};
use sepval_common::table_form::interference_distances;

use crate::UpdateError;

/// A correction that does not merge into the store's field (the caller names the field).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MergeError {
    /// A correction of the flowfield, for a scenario without one.
    #[error("the scenario has no [flowfield]")]
    NoFlowfield,
    /// A correction of the half depth of a field whose shape is a table.
    #[error("the flowfield's shape is a table: no half depth to correct")]
    NoHalfDepth,
    /// A corrected 1 / L_z not above 0.
    #[error("1 / half_depth_m would be {inverse} per m")]
    HalfDepth {
        /// 1 / L_z corrected \[1/m\].
        inverse: f64,
    },
    /// A correction of the reversal depth of a field whose shape is a table.
    #[error("the flowfield's shape is a table: no reversal depth to correct")]
    NoReversal,
    /// A corrected 1 / z_r below 0.
    #[error("1 / reversal_m would be {inverse} per m")]
    Reversal {
        /// 1 / z_r corrected \[1/m\].
        inverse: f64,
    },
    /// A correction of the shape table, for a scenario without one.
    #[error("the scenario has no [flowfield] shape table")]
    NoShapeTable,
    /// The shape table and its correction do not make a shape.
    #[error(transparent)]
    Shape(#[from] sepval_common::correction::FieldChangeError),
    /// The merged table is not a table of its field.
    #[error(transparent)]
    Table(#[from] sepval_common::table::TableShapeError),
}

/// The updated store: its scenario (tables as file references) and its table files.
#[derive(Debug, Clone)]
pub struct Store {
    /// The scenario as a user adopts it: tables merged, inline (for simulating now).
    pub scenario: Scenario,
    /// The same scenario referring to its table files.
    pub file_form: Scenario,
    /// (path relative to the scenario, CSV text) of each table.
    pub files: Vec<(PathBuf, String)>,
}

/// A field's kind.
fn kind(target: Target) -> Kind {
    match target {
        Target::Static(_) => Kind::Static,
        Target::Derivative(_) => Kind::Derivative,
        Target::Interference(_) => Kind::Interference,
        Target::Field(_) | Target::ShapeTable => {
            unreachable!("the flowfield's parts are not tables (Target::all lists the tables)")
        }
    }
}

/// The field's coefficient, or 0 where the scenario leaves it out.
fn current(s: &Scenario, target: Target) -> Coefficient {
    let a = &s.aero;
    let value = |c: Option<&Coefficient>| c.cloned().unwrap_or(Coefficient::Constant(0.0));
    match target {
        Target::Static(0) => a.ca0.value.clone(),
        Target::Static(k) => value(
            [&a.cy, &a.cz, &a.cl, &a.cm, &a.cn][k - 1]
                .as_ref()
                .map(|c| &c.value),
        ),
        Target::Derivative(d) => value(derivative(a, d).map(|c| &c.value)),
        Target::Interference(k) => s.interference.increments()[k].1.value.clone(),
        Target::Field(_) | Target::ShapeTable => {
            unreachable!("the flowfield's parts are not tables (Target::all lists the tables)")
        }
    }
}

fn derivative(
    a: &sepval_common::scenario::Aero,
    d: Derivative,
) -> Option<&sepval_common::table::DerivativeCoefficient> {
    match d {
        Derivative::CzAlpha => a.cz_alpha_per_rad.as_ref(),
        Derivative::CyBeta => a.cy_beta_per_rad.as_ref(),
        Derivative::CmAlpha => a.cm_alpha_per_rad.as_ref(),
        Derivative::CnBeta => a.cn_beta_per_rad.as_ref(),
        Derivative::ClP => Some(&a.cl_p_per_rad),
        Derivative::CmQ => Some(&a.cm_q_per_rad),
        Derivative::CnR => Some(&a.cn_r_per_rad),
    }
}

fn tabulated<K: TableKind>(c: Coefficient) -> Tabulated<K> {
    let mut t = Tabulated::<K>::constant(0.0);
    t.value = c;
    t
}

/// Sets the field to `c`.
fn set(s: &mut Scenario, target: Target, c: Coefficient) {
    let a = &mut s.aero;
    match target {
        Target::Static(0) => a.ca0 = tabulated(c),
        Target::Static(k) => {
            *[&mut a.cy, &mut a.cz, &mut a.cl, &mut a.cm, &mut a.cn][k - 1] = Some(tabulated(c))
        }
        Target::Derivative(d) => {
            let t = tabulated(c);
            match d {
                Derivative::CzAlpha => a.cz_alpha_per_rad = Some(t),
                Derivative::CyBeta => a.cy_beta_per_rad = Some(t),
                Derivative::CmAlpha => a.cm_alpha_per_rad = Some(t),
                Derivative::CnBeta => a.cn_beta_per_rad = Some(t),
                Derivative::ClP => a.cl_p_per_rad = t,
                Derivative::CmQ => a.cm_q_per_rad = t,
                Derivative::CnR => a.cn_r_per_rad = t,
            }
        }
        Target::Interference(k) => *s.interference.increments_mut()[k].1 = tabulated(c),
        Target::Field(_) | Target::ShapeTable => {
            unreachable!("the flowfield's parts are not tables (Target::all lists the tables)")
        }
    }
}

/// The flowfield's `part` of `s` corrected by `change` (a constant: the one breakpoint's
/// value): the half depth 1 / (1 / L_z + change) and the reversal depth 1 / (1 / z_r +
/// change), or none when that is 0 (`change` in 1/m, added to the inverse); the upwash's and
/// sidewash's change with alpha plus `change` \[deg/deg\].
fn set_field_part(s: &mut Scenario, part: FieldPart, change: f64) -> Result<(), MergeError> {
    let Some(field) = s.flowfield.as_mut() else {
        return Err(MergeError::NoFlowfield);
    };
    match part {
        FieldPart::HalfDepth => {
            let Some(l_z) = field.half_depth_m else {
                return Err(MergeError::NoHalfDepth);
            };
            let inverse = 1.0 / l_z + change;
            if inverse.is_nan() || inverse <= 0.0 {
                return Err(MergeError::HalfDepth { inverse });
            }
            field.half_depth_m = Some(1.0 / inverse);
        }
        FieldPart::Reversal => {
            if field.shape_is_tabulated() {
                return Err(MergeError::NoReversal);
            }
            let inverse = field.reversal_m.map_or(0.0, |z_r| 1.0 / z_r) + change;
            if inverse < 0.0 {
                return Err(MergeError::Reversal { inverse });
            }
            field.reversal_m = (inverse > 0.0).then(|| 1.0 / inverse);
        }
        FieldPart::UpwashPerAlpha => field.upwash_per_alpha += change,
        FieldPart::SidewashPerAlpha => field.sidewash_per_alpha += change,
    }
    Ok(())
}

/// The flowfield's shape table of `s` with the correction (`depth_m`, `change`) added: the
/// table the runs fitted it with (`corrected_shape`, the same function to the bit).
fn set_shape_table(s: &mut Scenario, depth_m: &[f64], change: &[f64]) -> Result<(), MergeError> {
    let Some(shape) = s.flowfield.as_mut().and_then(|f| f.shape.as_mut()) else {
        return Err(MergeError::NoShapeTable);
    };
    let (depth, g) = corrected_shape(&shape.depth_m, &shape.g, depth_m, change)?;
    shape.depth_m = depth;
    shape.g = g;
    Ok(())
}

/// Sorted union of breakpoint lists.
fn union(lists: &[&[f64]]) -> Vec<f64> {
    let mut v: Vec<f64> = lists.iter().flat_map(|l| l.iter().copied()).collect();
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| a.to_bits() == b.to_bits());
    v
}

/// The field `target` of `s` with `corrections` (each with its values) added, as a constant or
/// a table.
fn merged(
    s: &Scenario,
    target: Target,
    corrections: &[(&Correction, &[f64])],
) -> Result<Coefficient, MergeError> {
    let base = current(s, target);
    let k = kind(target);
    let decay = InterferenceDecay::new(s.interference.lambda_m, s.interference.s_end_m);
    let exponential = matches!(
        (&base, target),
        (Coefficient::Constant(_), Target::Interference(_))
    );
    let mut axes: Vec<Axis> = Vec::new();
    for &v in k.allowed() {
        let mut lists: Vec<&[f64]> = Vec::new();
        if let Coefficient::Table(t) = &base
            && let Some(a) = t.axes().iter().find(|a| a.variable == v)
        {
            lists.push(&a.breakpoints);
        }
        for (c, _) in corrections.iter().filter(|(c, _)| c.variable == v) {
            lists.push(&c.breakpoints);
        }
        let graded;
        if exponential && v == Variable::Distance {
            graded = interference_distances(s.interference.s_end_m);
            lists.push(&graded);
        }
        let b = union(&lists);
        if b.len() >= 2 {
            axes.push(Axis {
                variable: v,
                breakpoints: b,
            });
        }
    }
    let value_at = |point: &[(Variable, f64)]| -> f64 {
        let of = |v: Variable| point.iter().find(|p| p.0 == v).map_or(0.0, |p| p.1);
        let mut y = match &base {
            Coefficient::Constant(c) if exponential => c * decay.factor(of(Variable::Distance)),
            Coefficient::Constant(c) => *c,
            Coefficient::Table(t) => {
                let x: Vec<f64> = t.axes().iter().map(|a| of(a.variable)).collect();
                t.value_at(&x)
            }
            Coefficient::File(_) => f64::NAN,
        };
        for (c, values) in corrections {
            y += interpolate(&c.breakpoints, values, of(c.variable));
        }
        y
    };
    if axes.is_empty() {
        return Ok(Coefficient::Constant(value_at(&[])));
    }
    let sizes: Vec<usize> = axes.iter().map(|a| a.breakpoints.len()).collect();
    let n: usize = sizes.iter().product();
    let mut values = Vec::with_capacity(n);
    for r in 0..n {
        let mut rem = r;
        let mut point = vec![(Variable::Mach, 0.0); axes.len()];
        for j in (0..axes.len()).rev() {
            point[j] = (axes[j].variable, axes[j].breakpoints[rem % sizes[j]]);
            rem /= sizes[j];
        }
        values.push(value_at(&point));
    }
    Ok(Coefficient::Table(Table::new(axes, values, k)?))
}

/// The store of `base` (its `[[correction]]` list ignored) with `corrections` merged, each with
/// its values (every breakpoint's), its description saying so.
pub fn updated_store(
    base: &Scenario,
    corrections: &[(Correction, Vec<f64>)],
    description: &str,
) -> Result<Store, UpdateError> {
    let mut s = base.clone();
    s.correction.clear();
    s.description = description.to_string();
    for target in Target::all() {
        let on: Vec<(&Correction, &[f64])> = corrections
            .iter()
            .filter(|(c, _)| c.target == target)
            .map(|(c, v)| (c, v.as_slice()))
            .collect();
        if on.is_empty() {
            continue;
        }
        let c = merged(base, target, &on).map_err(|reason| UpdateError::Merge {
            field: target.field(),
            reason,
        })?;
        set(&mut s, target, c);
    }
    for (c, v) in corrections {
        let merged = match c.target {
            Target::Field(part) => set_field_part(&mut s, part, v[0]),
            Target::ShapeTable => set_shape_table(&mut s, &c.breakpoints, v),
            _ => Ok(()),
        };
        merged.map_err(|reason| UpdateError::Merge {
            field: c.target.field(),
            reason,
        })?;
    }
    s.validate("the updated store")
        .map_err(UpdateError::Store)?;
    let (file_form, files) = file_form(&s);
    Ok(Store {
        scenario: s,
        file_form,
        files,
    })
}

/// `s` with each of its tables moved to a CSV file `tables/<field>.csv`.
fn file_form(s: &Scenario) -> (Scenario, Vec<(PathBuf, String)>) {
    let mut out = s.clone();
    let mut files = Vec::new();
    for target in Target::all() {
        let Coefficient::Table(t) = current(s, target) else {
            continue;
        };
        let field = target.field();
        let name = field.replace('.', "_");
        let path = PathBuf::from(format!("tables/{name}.csv"));
        let column = field.rsplit('.').next().unwrap_or("value").to_string();
        let unit = if kind(target) == Kind::Derivative {
            "1/rad"
        } else {
            "-"
        };
        files.push((
            path.clone(),
            write_csv(t.axes(), &[(&column, unit, t.values())]),
        ));
        set(
            &mut out,
            target,
            Coefficient::File(TableFile {
                csv: path,
                column: Some(column),
            }),
        );
    }
    (out, files)
}
