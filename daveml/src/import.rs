//! Stage 2, **map**: the parsed file's functions and constants turned into sepval tables of the
//! fields the map names ([`Imported`]), each checked as the standard and sepval's tables require.
//!
//! Source: DAVE-ML 2.0 reference manual / ANSI/AIAA S-119-2011 sections 5.4 (`breakpointDef`:
//! breakpoints monotonically increasing), 5.5 (`griddedTableDef`: one value per grid point, the
//! last breakpoint set changing fastest) and 5.6 (`function`, `independentVarRef`: `min`, `max`,
//! `extrapolate` = `neither` (default), `min`, `max` or `both`; `interpolate` = `linear`
//! (default), `discrete`, `floor`, `ceiling`, `quadraticSpline`, `cubicSpline`). sepval's tables
//! are linear between breakpoints and hold their edge value outside them (docs/model.md section
//! 1), which is `interpolate="linear"` with `extrapolate="neither"`; anything else is refused.

use std::collections::BTreeMap;

use sepval_common::correction::Target;
use sepval_common::table::{Axis, Kind, Table, Variable, unit_suffix};
use sepval_core::number_text::Shown;

use crate::error::{DavemlError, Place};
use crate::map::{Map, Output, Role};
use crate::parse::{
    BreakpointDef, Function, GriddedTable, InputRef, Located, Parsed, Pdf, PdfKind, TableDefn,
    VariableDef,
};
pub use crate::spread::Spread;
use crate::spread::spread_of;
use crate::units;

/// The value a file gives a field.
#[derive(Debug, Clone, PartialEq)]
pub enum FieldValue {
    /// A table (a `function`).
    Table(Table),
    /// A constant (a `variableDef` with an `initialValue` and no `calculation`).
    Constant(f64),
}

/// A field the file gives, and where.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedField {
    /// The field.
    pub target: Target,
    /// Its value, in the scenario's units.
    pub value: FieldValue,
    /// The element it came from.
    pub place: Place,
    /// Its uncertainty, if the file gives one.
    pub spread: Option<Spread>,
}

/// What a DAVE-ML file gives the scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct Imported {
    /// The fields, in the file's order.
    pub fields: Vec<ImportedField>,
    /// What was read and not carried (uncertainties, ignored variables), to say to the user.
    pub notes: Vec<String>,
}

/// The kind of table a field is.
pub fn kind_of(t: Target) -> Kind {
    match t {
        Target::Static(_) => Kind::Static,
        Target::Derivative(_) => Kind::Derivative,
        Target::Interference(_) => Kind::Interference,
        Target::Field(_) | Target::ShapeTable => unreachable!(
            "the flowfield is not the store's data: DAVE-ML carries the store's tables (Target::all)"
        ),
    }
}

/// The parsed file's definitions, looked up by ID.
struct Index<'a> {
    variables: BTreeMap<&'a str, &'a Located<VariableDef>>,
    breakpoints: BTreeMap<&'a str, &'a Located<BreakpointDef>>,
    tables: BTreeMap<&'a str, &'a Located<GriddedTable>>,
}

fn index(p: &Parsed) -> Result<Index<'_>, DavemlError> {
    fn unique<'a, T>(
        items: &'a [Located<T>],
        id: impl Fn(&'a T) -> Option<&'a str>,
        what: &str,
    ) -> Result<BTreeMap<&'a str, &'a Located<T>>, DavemlError> {
        let mut m = BTreeMap::new();
        for l in items {
            if let Some(k) = id(&l.item)
                && m.insert(k, l).is_some()
            {
                return Err(DavemlError::at(
                    &l.place,
                    format!("{what} `{k}` is defined twice"),
                ));
            }
        }
        Ok(m)
    }
    Ok(Index {
        variables: unique(&p.variables, |v| Some(v.var_id.as_str()), "varID")?,
        breakpoints: unique(&p.breakpoints, |b| Some(b.bp_id.as_str()), "bpID")?,
        tables: unique(&p.tables, |t| t.gt_id.as_deref(), "gtID")?,
    })
}

impl<'a> Index<'a> {
    fn variable(&self, id: &str, at: &Place) -> Result<&'a Located<VariableDef>, DavemlError> {
        self.variables.get(id).copied().ok_or_else(|| {
            DavemlError::at(
                at,
                format!("unknown variable `{id}`: no <variableDef> has this varID"),
            )
        })
    }
}

/// Maps the parsed file's functions and constants to sepval fields with `map`.
pub fn import(p: &Parsed, map: &Map) -> Result<Imported, DavemlError> {
    let idx = index(p)?;
    let mut out = Imported {
        fields: Vec::new(),
        notes: Vec::new(),
    };
    for f in &p.functions {
        let var = idx.variable(&f.item.output.item, &f.item.output.place)?;
        match map.role(&var.item.var_id, &var.item.name) {
            Some(Role::Output(o)) => {
                let (table, spread) = function_table(&idx, map, &f.item, var, o)?;
                push(&mut out, o.target, FieldValue::Table(table), &f.place)?;
                out.fields.last_mut().expect("pushed").spread = spread;
                if let Some(note) = uncertainty_note(&idx, &f.item, var) {
                    out.notes.push(note);
                }
            }
            Some(Role::Ignore) => out.notes.push(format!(
                "function `{}` (line {}) of {} left out: the map ignores it",
                f.item.name, f.place.line, var.item.var_id
            )),
            Some(Role::Input(_)) => {
                return Err(DavemlError::at(
                    &f.item.output.place,
                    format!(
                        "the function's output `{}` is mapped to an input of sepval's tables; sepval's inputs are the flight condition and the store's state, not functions",
                        var.item.var_id
                    ),
                ));
            }
            None => {
                return Err(unmapped(
                    &f.item.output.place,
                    &var.item,
                    "the function's output",
                ));
            }
        }
    }
    constants(p, map, &mut out)?;
    Ok(out)
}

/// The fields given as constants (`initialValue`), and the refusal of those computed.
fn constants(p: &Parsed, map: &Map, out: &mut Imported) -> Result<(), DavemlError> {
    for v in &p.variables {
        let Some(Role::Output(o)) = map.role(&v.item.var_id, &v.item.name) else {
            continue;
        };
        if out.fields.iter().any(|f| f.target == o.target) {
            continue;
        }
        if let Some(calc) = &v.item.calculation {
            return Err(DavemlError::at(
                calc,
                format!(
                    "`{}` (sepval field {}) is a MathML calculation: a scenario's field is a constant or a table, so sepval imports only a gridded function or a constant (initialValue)",
                    v.item.var_id,
                    o.target.field()
                ),
            ));
        }
        let Some(x) = v.item.initial_value else {
            continue;
        };
        let kind = kind_of(o.target);
        let c =
            units::output(kind, &v.item.units).map_err(|e| units_error(&v.place, &v.item, e))?;
        let value = signed(o, c.apply(x));
        push(out, o.target, FieldValue::Constant(value), &v.place)?;
        out.fields.last_mut().expect("pushed").spread =
            v.item.uncertainty.as_ref().map(|p| spread_of(p, 1, c));
    }
    Ok(())
}

fn signed(o: Output, x: f64) -> f64 {
    if o.negate { -x } else { x }
}

fn push(
    out: &mut Imported,
    target: Target,
    value: FieldValue,
    at: &Place,
) -> Result<(), DavemlError> {
    if let Some(prev) = out.fields.iter().find(|f| f.target == target) {
        return Err(DavemlError::at(
            at,
            format!(
                "gives sepval field {} a second time (line {} gave it first)",
                target.field(),
                prev.place.line
            ),
        ));
    }
    out.fields.push(ImportedField {
        target,
        value,
        place: at.clone(),
        spread: None,
    });
    Ok(())
}

fn unmapped(at: &Place, v: &VariableDef, what: &str) -> DavemlError {
    DavemlError::at(
        at,
        format!(
            "{what} `{}`{} is not in the map: name it in a map file (--map MAP.toml, docs/daveml.md) as a sepval input or field, or list it under [ignore]",
            v.var_id,
            if v.name.is_empty() || v.name == v.var_id {
                String::new()
            } else {
                format!(" (name `{}`)", v.name)
            }
        ),
    )
}

fn units_error(at: &Place, v: &VariableDef, expected: &str) -> DavemlError {
    DavemlError::at(
        at,
        format!(
            "`{}` has units `{}`: expected {expected}",
            v.var_id, v.units
        ),
    )
}

/// The note for an uncertainty sepval reads and does not carry.
fn uncertainty_note(idx: &Index, f: &Function, var: &Located<VariableDef>) -> Option<String> {
    let pdf = pdf_of(idx, f, var)?;
    let what = match pdf.kind {
        PdfKind::Normal => "normalPDF",
        PdfKind::Uniform => "uniformPDF",
    };
    Some(format!(
        "the uncertainty of `{}` ({what}) is read and not carried: a sepval scenario holds the nominal tables (the update's bands come from releases, docs/update.md)",
        var.item.var_id
    ))
}

/// The PDF of a function's table, else of its output variable.
fn pdf_of<'a>(idx: &'a Index, f: &'a Function, var: &'a Located<VariableDef>) -> Option<&'a Pdf> {
    match &f.table.item {
        TableDefn::Inline(t) => t.uncertainty.as_ref(),
        TableDefn::Ref { gt_id: id } => idx
            .tables
            .get(id.as_str())
            .and_then(|t| t.item.uncertainty.as_ref()),
        TableDefn::Simple | TableDefn::Unsupported { .. } => None,
    }
    .or(var.item.uncertainty.as_ref())
}

/// One input of a function: its sepval variable, conversion and breakpoints (converted).
#[derive(Clone)]
struct AxisIn {
    variable: Variable,
    breakpoints: Vec<f64>,
}

/// The gridded table of a function, and where it is defined.
fn table_of<'a>(idx: &'a Index, f: &'a Function) -> Result<(&'a GriddedTable, Place), DavemlError> {
    match &f.table.item {
        TableDefn::Inline(t) => Ok((t, f.table.place.clone())),
        TableDefn::Ref { gt_id: id } => idx
            .tables
            .get(id.as_str())
            .map(|t| (&t.item, t.place.clone()))
            .ok_or_else(|| {
                DavemlError::at(
                    &f.table.place,
                    format!("unknown table `{id}`: no <griddedTableDef> has this gtID"),
                )
            }),
        TableDefn::Simple => Err(not_gridded(
            f,
            "a simple function (independentVarPts/dependentVarPts)",
        )),
        TableDefn::Unsupported { tag } => Err(not_gridded(f, &format!("a <{tag}>"))),
    }
}

/// The refusal of function `f`, whose table is `what` and not gridded.
fn not_gridded(f: &Function, what: &str) -> DavemlError {
    DavemlError::at(
        &f.table.place,
        format!(
            "function `{}` is {what}: sepval imports gridded tables (griddedTableDef) only",
            f.name
        ),
    )
}

/// Refuses an output whose `minValue`/`maxValue` would saturate its table's `data`.
fn unsaturated(var: &Located<VariableDef>, data: &[f64]) -> Result<(), DavemlError> {
    let (min, max) = var.item.limits;
    if let Some(x) = data
        .iter()
        .find(|&&x| min.is_some_and(|m| x < m) || max.is_some_and(|m| x > m))
    {
        return Err(DavemlError::at(
            &var.place,
            format!(
                "minValue/maxValue of `{}` limit its table (a value {x:?} lies beyond them): sepval's tables are not saturated",
                var.item.var_id
            ),
        ));
    }
    Ok(())
}

/// The table of a function whose output is the field `o`, and its spread if the file gives
/// one (in the table's order).
fn function_table(
    idx: &Index,
    map: &Map,
    f: &Function,
    var: &Located<VariableDef>,
    o: Output,
) -> Result<(Table, Option<Spread>), DavemlError> {
    let (table, table_place) = table_of(idx, f)?;
    if f.inputs.len() != table.breakpoints.len() {
        return Err(DavemlError::at(
            &table_place,
            format!(
                "function `{}` has {} independentVarRef(s) and its table {} breakpoint set(s)",
                f.name,
                f.inputs.len(),
                table.breakpoints.len()
            ),
        ));
    }
    let kind = kind_of(o.target);
    if f.inputs.len() > kind.allowed().len() {
        return Err(DavemlError::at(
            &f.inputs[0].place,
            format!(
                "function `{}` has {} inputs: sepval field {} is a table of at most {} ({})",
                f.name,
                f.inputs.len(),
                o.target.field(),
                kind.allowed().len(),
                kind.allowed()
                    .iter()
                    .map(|v| v.csv_name())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    let mut axes = Vec::new();
    for (input, bp) in f.inputs.iter().zip(&table.breakpoints) {
        axes.push(axis(idx, map, input, bp, &table_place)?);
    }
    let points: usize = axes.iter().map(|a| a.breakpoints.len()).product();
    if table.data.len() != points {
        return Err(DavemlError::at(
            &table_place,
            format!(
                "the dataTable has {} values for a grid of {points} points ({})",
                table.data.len(),
                axes.iter()
                    .map(|a| a.breakpoints.len().to_string())
                    .collect::<Vec<_>>()
                    .join(" x ")
            ),
        ));
    }
    let c =
        units::output(kind, &var.item.units).map_err(|e| units_error(&var.place, &var.item, e))?;
    unsaturated(var, &table.data)?;
    let values: Vec<f64> = table.data.iter().map(|&x| signed(o, c.apply(x))).collect();
    let mut spread = pdf_of(idx, f, var).map(|p| spread_of(p, points, c));
    if let Some(s) = spread
        .as_mut()
        .filter(|s| s.sd.len() == points && points > 1)
    {
        // The standard deviations in the table's nesting order, as its values.
        let (_, sd) = nest(axes.clone(), std::mem::take(&mut s.sd), kind)
            .map_err(|m| DavemlError::at(&f.inputs[0].place, m))?;
        s.sd = sd;
    }
    let (axes, values) =
        nest(axes, values, kind).map_err(|m| DavemlError::at(&f.inputs[0].place, m))?;
    let table = Table::new(axes, values, kind).map_err(|m| {
        DavemlError::at(
            &table_place,
            format!("as sepval field {}, the table {m}", o.target.field()),
        )
    })?;
    Ok((table, spread))
}

/// One input of a function, checked: mapped, linear, held outside, its breakpoints increasing.
fn axis(
    idx: &Index,
    map: &Map,
    input: &Located<InputRef>,
    bp_id: &str,
    table_place: &Place,
) -> Result<AxisIn, DavemlError> {
    let i = &input.item;
    let var = idx.variable(&i.var_id, &input.place)?;
    let variable = match map.role(&var.item.var_id, &var.item.name) {
        Some(Role::Input(v)) => v,
        _ => return Err(unmapped(&input.place, &var.item, "the function's input")),
    };
    if i.interpolate != "linear" {
        return Err(DavemlError::at(
            &input.place,
            format!(
                "interpolate=\"{}\" on `{}`: sepval's tables are linear between breakpoints (interpolate=\"linear\")",
                i.interpolate, i.var_id
            ),
        ));
    }
    if i.extrapolate != "neither" {
        return Err(DavemlError::at(
            &input.place,
            format!(
                "extrapolate=\"{}\" on `{}`: sepval's tables hold their edge value outside the breakpoints (extrapolate=\"neither\") and never extrapolate",
                i.extrapolate, i.var_id
            ),
        ));
    }
    let bp = idx.breakpoints.get(bp_id).ok_or_else(|| {
        DavemlError::at(
            table_place,
            format!("unknown breakpoint set `{bp_id}`: no <breakpointDef> has this bpID"),
        )
    })?;
    if let Some(u) = &bp.item.units
        && u.trim() != var.item.units.trim()
    {
        return Err(DavemlError::at(
            &bp.place,
            format!(
                "breakpoint set `{bp_id}` has units `{u}` and its variable `{}` units `{}`",
                var.item.var_id, var.item.units
            ),
        ));
    }
    let c = units::input(variable, &var.item.units)
        .map_err(|e| units_error(&var.place, &var.item, e))?;
    let b = &bp.item.values;
    if let Some(k) = (1..b.len()).find(|&k| b[k] <= b[k - 1]) {
        return Err(DavemlError::at(
            &bp.place,
            format!(
                "breakpoint set `{bp_id}` is not strictly increasing: {:?} after {:?}",
                b[k],
                b[k - 1]
            ),
        ));
    }
    let breakpoints: Vec<f64> = b.iter().map(|&x| c.apply(x)).collect();
    in_domain(&bp.place, bp_id, &i.var_id, variable, b, &breakpoints)?;
    let (lo, hi) = (b.first().copied(), b.last().copied());
    let inside = |(min, max): (Option<f64>, Option<f64>)| {
        min.zip(lo).is_some_and(|(x, e)| x > e) || max.zip(hi).is_some_and(|(x, e)| x < e)
    };
    if inside((i.min, i.max)) {
        return Err(DavemlError::at(
            &input.place,
            format!(
                "min/max of `{}` lie inside its breakpoints {bp_id}: sepval holds a table at its breakpoints' edges only",
                i.var_id
            ),
        ));
    }
    if inside(var.item.limits) {
        return Err(DavemlError::at(
            &var.place,
            format!(
                "minValue/maxValue of `{}` lie inside the breakpoints {bp_id}: sepval limits a table's input at its breakpoints' edges only",
                i.var_id
            ),
        ));
    }
    Ok(AxisIn {
        variable,
        breakpoints,
    })
}

/// Refuses a breakpoint set (`file` as the file gives it, `converted` to sepval's unit) with a
/// breakpoint outside its variable's domain: the same range as the TOML and CSV forms'
/// ([`Variable::domain`]).
fn in_domain(
    at: &Place,
    bp_id: &str,
    var_id: &str,
    v: Variable,
    file: &[f64],
    converted: &[f64],
) -> Result<(), DavemlError> {
    let (lo, hi, why) = v.domain();
    let Some((x, y)) = file
        .iter()
        .zip(converted)
        .find(|&(_, y)| !(lo..=hi).contains(y))
    else {
        return Ok(());
    };
    let unit = unit_suffix(v);
    let shown = if x.to_bits() == y.to_bits() {
        format!("{x:?}")
    } else {
        format!("{x:?} ({y:?}{unit})")
    };
    Err(DavemlError::at(
        at,
        format!(
            "breakpoint set `{bp_id}` of `{var_id}` (sepval's {0}): breakpoint {shown} is outside {0}'s domain, {1} to {2}{unit} ({why})",
            v.csv_name(),
            Shown(lo),
            Shown(hi),
        ),
    ))
}

/// The axes put in sepval's nesting order for `kind`, the values permuted with them.
fn nest(axes: Vec<AxisIn>, values: Vec<f64>, kind: Kind) -> Result<(Vec<Axis>, Vec<f64>), String> {
    let rank = |v: Variable| kind.allowed().iter().position(|&w| w == v);
    for a in &axes {
        if rank(a.variable).is_none() {
            return Err(format!(
                "an input is {}: this field may be tabulated over {} only",
                a.variable.csv_name(),
                kind.allowed()
                    .iter()
                    .map(|v| v.csv_name())
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
    }
    let mut order: Vec<usize> = (0..axes.len()).collect();
    order.sort_by_key(|&k| rank(axes[k].variable));
    if let Some(w) = order
        .windows(2)
        .find(|w| axes[w[0]].variable == axes[w[1]].variable)
    {
        return Err(format!("two inputs are {}", axes[w[0]].variable.csv_name()));
    }
    let sizes: Vec<usize> = axes.iter().map(|a| a.breakpoints.len()).collect();
    let mut strides = vec![1usize; sizes.len()];
    for k in (0..sizes.len().saturating_sub(1)).rev() {
        strides[k] = strides[k + 1] * sizes[k + 1];
    }
    let new_sizes: Vec<usize> = order.iter().map(|&k| sizes[k]).collect();
    let mut permuted = Vec::with_capacity(values.len());
    let mut idx = vec![0usize; order.len()];
    for _ in 0..values.len() {
        let at: usize = order.iter().zip(&idx).map(|(&k, &i)| i * strides[k]).sum();
        permuted.push(values[at]);
        for j in (0..idx.len()).rev() {
            idx[j] += 1;
            if idx[j] < new_sizes[j] {
                break;
            }
            idx[j] = 0;
        }
    }
    let mut axes: Vec<Option<AxisIn>> = axes.into_iter().map(Some).collect();
    let nested = order
        .iter()
        .map(|&k| {
            let a = axes[k].take().expect("each axis once");
            Axis {
                variable: a.variable,
                breakpoints: a.breakpoints,
            }
        })
        .collect();
    Ok((nested, permuted))
}
