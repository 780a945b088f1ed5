//! Tabulated aerodynamics and interference: the table form of a scenario's coefficients, its
//! files, and the multilinear interpolation the force evaluation uses.
//!
//! Source: `docs/model.md` section 1 ("Tables") and section 3 ("Tabulated coefficients"). A
//! coefficient is a constant (the contract's form) or a table on a rectilinear grid of one to
//! three variables, interpolated multilinearly:
//!
//! ```text
//! 1 axis:   v(x)       = v_i + t (v_{i+1} - v_i),          t = (x - x_i) / (x_{i+1} - x_i)
//! 2 axes:   v(x, y)    = 1-axis interpolation in y on rows i and i+1, then in x between them
//! 3 axes:   v(x, y, z) = 2-axis interpolation in (y, z) on planes i and i+1, then in x
//! ```
//!
//! (the last axis first; Press et al., *Numerical Recipes*, 3rd ed., section 3.6, "bilinear
//! interpolation", extended one axis at a time). Outside a table the value is held at the edge
//! (t clamped to [0, 1]) and the excursion is recorded, never extrapolated.
//!
//! Choices made here (docs/model.md section 1 records them):
//! - The variables a table may span depend on what it tabulates ([`Kind`]): a static coefficient
//!   (CA, CY, CZ, Cl, Cm, Cn) over Mach, local alpha and local beta; a derivative (CZ_alpha,
//!   CY_beta, Cm_alpha, Cn_beta, Cl_p, Cm_q, Cn_r) over Mach only; an interference increment over
//!   distance from carriage (required), local alpha and lateral offset. The grid's axes nest in
//!   that fixed order (first axis slowest).
//! - Mach is the flight condition's (free-stream) Mach, fixed for the event, so every Mach axis
//!   is interpolated once when the run is set up: a derivative table becomes a constant, and a
//!   static table a table over (alpha, beta). Everything the force evaluation needs is
//!   precomputed per scenario ([`PreparedTables`]); a propagation keeps its interval cursors and
//!   excursion counts in a [`TableState`] of fixed size: no allocation per force evaluation.
//! - Interval search starts from the previous evaluation's interval (a hunt: the store moves
//!   little between two stages), so it costs a comparison or two. Each grid cell holds its
//!   interpolant as a polynomial in the inputs ((c0 + c1 x) + y (c2 + c3 x), ...), evaluated
//!   with fused multiply-adds: the same value as the formula above to rounding, and shorter on
//!   the path from the flow angles to the forces. Tables over the same axes are grouped and
//!   interpolated six lanes at a time.

use std::cell::Cell;
use std::fmt;
use std::marker::PhantomData;
use std::path::{Path, PathBuf};

use serde::de::{self, MapAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::units::{M_PER_FT, M_PER_IN};

/// Most values one table may hold.
pub const MAX_TABLE_VALUES: usize = 1_000_000;

/// A variable a table may be tabulated over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Variable {
    /// The flight condition's Mach number \[-\].
    Mach,
    /// The store's local angle of attack atan2(w, u) \[deg in files\].
    Alpha,
    /// The store's local sideslip asin(v / V) \[deg in files\].
    Beta,
    /// Distance of the CG from its carriage position |r| \[m\].
    Distance,
    /// Lateral offset of the CG from carriage: the launch-frame y (crossrange) \[m\].
    Lateral,
}

impl Variable {
    /// Every variable (each [`Kind`] has its own nesting order, [`Kind::allowed`]).
    pub const ALL: [Variable; 5] = [
        Variable::Mach,
        Variable::Alpha,
        Variable::Beta,
        Variable::Distance,
        Variable::Lateral,
    ];

    /// Its key in an inline TOML table (with the unit of its breakpoints).
    pub fn key(self) -> &'static str {
        match self {
            Variable::Mach => "mach",
            Variable::Alpha => "alpha_deg",
            Variable::Beta => "beta_deg",
            Variable::Distance => "distance_m",
            Variable::Lateral => "lateral_m",
        }
    }

    /// Its name in a CSV header (`name [unit]`).
    pub fn csv_name(self) -> &'static str {
        match self {
            Variable::Mach => "mach",
            Variable::Alpha => "alpha",
            Variable::Beta => "beta",
            Variable::Distance => "distance",
            Variable::Lateral => "lateral",
        }
    }

    /// The unit breakpoints are kept in (scenario files, reports).
    pub fn unit(self) -> &'static str {
        match self {
            Variable::Mach => "-",
            Variable::Alpha | Variable::Beta => "deg",
            Variable::Distance | Variable::Lateral => "m",
        }
    }

    /// Units a CSV header may give, and the conversion to [`Variable::unit`].
    fn csv_units(self) -> &'static [(&'static str, Conversion)] {
        match self {
            Variable::Mach => &[("-", Conversion::Scale(1.0))],
            Variable::Alpha | Variable::Beta => &[
                ("deg", Conversion::Scale(1.0)),
                ("rad", Conversion::RadToDeg),
            ],
            Variable::Distance | Variable::Lateral => &[
                ("m", Conversion::Scale(1.0)),
                ("ft", Conversion::Scale(M_PER_FT)),
                ("in", Conversion::Scale(M_PER_IN)),
            ],
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// How a file's unit converts to the scenario's.
#[derive(Debug, Clone, Copy)]
enum Conversion {
    /// Multiply by this exact factor.
    Scale(f64),
    /// Radians to degrees (`f64::to_degrees`); for a value per degree, per radian.
    RadToDeg,
}

impl Conversion {
    fn apply(self, x: f64) -> f64 {
        match self {
            Conversion::Scale(s) => x * s,
            Conversion::RadToDeg => x.to_degrees(),
        }
    }
}

/// What a table tabulates, which decides the variables it may span and the unit of its values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A static coefficient (CA, CY, CZ, Cl, Cm, Cn): over Mach, alpha and beta.
    Static,
    /// A derivative (per rad of a flow angle or of a non-dimensional rate): over Mach.
    Derivative,
    /// An interference increment: over distance (required), alpha and lateral offset.
    Interference,
}

impl Kind {
    /// The variables it may span, in nesting order.
    pub fn allowed(self) -> &'static [Variable] {
        match self {
            Kind::Static => &[Variable::Mach, Variable::Alpha, Variable::Beta],
            Kind::Derivative => &[Variable::Mach],
            Kind::Interference => &[Variable::Distance, Variable::Alpha, Variable::Lateral],
        }
    }

    /// A variable every table of this kind spans.
    fn required(self) -> Option<Variable> {
        match self {
            Kind::Interference => Some(Variable::Distance),
            _ => None,
        }
    }

    /// Units a CSV value column may give, and the conversion to the scenario's.
    fn value_units(self) -> &'static [(&'static str, Conversion)] {
        match self {
            Kind::Static | Kind::Interference => &[("-", Conversion::Scale(1.0))],
            Kind::Derivative => &[
                ("1/rad", Conversion::Scale(1.0)),
                ("1/deg", Conversion::RadToDeg),
            ],
        }
    }

    fn what(self) -> &'static str {
        match self {
            Kind::Static => "a static coefficient",
            Kind::Derivative => "a derivative",
            Kind::Interference => "an interference increment",
        }
    }

    fn allowed_list(self, sep: &str) -> String {
        self.allowed()
            .iter()
            .map(|v| v.csv_name())
            .collect::<Vec<_>>()
            .join(sep)
    }
}

/// One axis of a table: a variable and its breakpoints (strictly increasing, in the
/// variable's [`Variable::unit`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// The variable.
    pub variable: Variable,
    /// Its breakpoints.
    pub breakpoints: Vec<f64>,
}

/// A table on a rectilinear grid of one to three axes; values row-major (last axis fastest),
/// in the unit of the coefficient (derivatives per rad).
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    axes: Vec<Axis>,
    values: Vec<f64>,
}

impl Table {
    /// A checked table of `kind`: one to three axes, each allowed for the kind and in nesting
    /// order, at least two finite strictly increasing breakpoints each, one finite value per
    /// grid point. The message says what is wrong (the caller says where).
    pub fn new(axes: Vec<Axis>, values: Vec<f64>, kind: Kind) -> Result<Table, String> {
        if axes.is_empty() || axes.len() > 3 {
            return Err(format!(
                "has {} axes: expected one to three of {}",
                axes.len(),
                kind.allowed_list(", ")
            ));
        }
        let mut previous: Option<Variable> = None;
        for a in &axes {
            if !kind.allowed().contains(&a.variable) {
                return Err(format!(
                    "is a table over {}: {} may be tabulated over {} only",
                    a.variable.csv_name(),
                    kind.what(),
                    kind.allowed_list(", ")
                ));
            }
            let rank = |v: Variable| kind.allowed().iter().position(|&w| w == v);
            if previous.is_some_and(|p| rank(p) >= rank(a.variable)) {
                return Err(format!(
                    "axes must nest in the order {}",
                    kind.allowed_list(", ")
                ));
            }
            previous = Some(a.variable);
            check_breakpoints(a.variable, &a.breakpoints)?;
        }
        if let Some(r) = kind.required()
            && !axes.iter().any(|a| a.variable == r)
        {
            return Err(format!(
                "has no {} axis: {} is tabulated over {} at least",
                r.csv_name(),
                kind.what(),
                r.csv_name()
            ));
        }
        let points: usize = axes.iter().map(|a| a.breakpoints.len()).product();
        if points > MAX_TABLE_VALUES {
            return Err(format!(
                "has {points} grid points, more than the limit of {MAX_TABLE_VALUES}"
            ));
        }
        if values.len() != points {
            return Err(format!(
                "has {} values for a grid of {points} points",
                values.len()
            ));
        }
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            return Err(format!(
                "value {k} is {}: expected finite values",
                values[k]
            ));
        }
        Ok(Table { axes, values })
    }

    /// Its axes, in nesting order.
    pub fn axes(&self) -> &[Axis] {
        &self.axes
    }

    /// Its values, row-major (last axis fastest).
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Number of breakpoints of each axis.
    fn shape(&self) -> Vec<usize> {
        self.axes.iter().map(|a| a.breakpoints.len()).collect()
    }
}

fn check_breakpoints(v: Variable, b: &[f64]) -> Result<(), String> {
    if b.len() < 2 {
        return Err(format!(
            "axis {} has {} breakpoint(s): expected at least 2 (give a constant instead of a table)",
            v.csv_name(),
            b.len()
        ));
    }
    for (k, x) in b.iter().enumerate() {
        if !x.is_finite() {
            return Err(format!(
                "axis {} breakpoint {k} is {x}: expected finite values",
                v.csv_name()
            ));
        }
        if k > 0 && *x <= b[k - 1] {
            return Err(format!(
                "axis {} breakpoints are not strictly increasing: {x} after {}",
                v.csv_name(),
                b[k - 1]
            ));
        }
    }
    Ok(())
}

/// A reference to a CSV table file, relative to the scenario file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TableFile {
    /// The file, relative to the scenario file's directory.
    pub csv: PathBuf,
    /// The value column to use (its name without the unit); needed when the file holds several.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub column: Option<String>,
}

/// A coefficient as a scenario gives it.
#[derive(Debug, Clone, PartialEq)]
pub enum Coefficient {
    /// A constant (the contract's form).
    Constant(f64),
    /// A table, inline or read from its file.
    Table(Table),
    /// A table file not read yet (only between parsing and [`Tabulated::resolve`]).
    File(TableFile),
}

/// The marker of what a [`Tabulated`] coefficient is (its [`Kind`]).
pub trait TableKind {
    /// The kind.
    const KIND: Kind;
}

/// Marker: a static coefficient.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StaticKind;
/// Marker: a derivative.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DerivativeKind;
/// Marker: an interference increment.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct InterferenceKind;

impl TableKind for StaticKind {
    const KIND: Kind = Kind::Static;
}
impl TableKind for DerivativeKind {
    const KIND: Kind = Kind::Derivative;
}
impl TableKind for InterferenceKind {
    const KIND: Kind = Kind::Interference;
}

/// A coefficient of a known kind: in TOML a number, an inline table
/// (`{ mach = [..], alpha_deg = [..], values = [[..], ..] }`) or a file
/// (`{ csv = "tables/cz.csv", column = "cz" }`).
#[derive(Debug, Clone, PartialEq)]
pub struct Tabulated<K> {
    /// The coefficient.
    pub value: Coefficient,
    kind: PhantomData<K>,
}

/// A static coefficient (CA, CY, CZ, Cl, Cm, Cn).
pub type StaticCoefficient = Tabulated<StaticKind>;
/// A derivative (CZ_alpha, CY_beta, Cm_alpha, Cn_beta, Cl_p, Cm_q, Cn_r).
pub type DerivativeCoefficient = Tabulated<DerivativeKind>;
/// An interference increment.
pub type InterferenceCoefficient = Tabulated<InterferenceKind>;

impl<K: TableKind> Tabulated<K> {
    /// A constant.
    pub fn constant(v: f64) -> Self {
        Tabulated {
            value: Coefficient::Constant(v),
            kind: PhantomData,
        }
    }

    /// A table, checked for this kind.
    pub fn table(t: Table) -> Result<Self, String> {
        Table::new(t.axes, t.values, K::KIND).map(|t| Tabulated {
            value: Coefficient::Table(t),
            kind: PhantomData,
        })
    }

    /// The constant, if it is one.
    pub fn as_constant(&self) -> Option<f64> {
        match self.value {
            Coefficient::Constant(v) => Some(v),
            _ => None,
        }
    }

    /// The table, if it is one.
    pub fn as_table(&self) -> Option<&Table> {
        match &self.value {
            Coefficient::Table(t) => Some(t),
            _ => None,
        }
    }

    /// Reads a file reference (relative to `dir`) into its table; constants and tables stay.
    pub fn resolve(&mut self, dir: &Path) -> Result<(), TableError> {
        if let Coefficient::File(f) = &self.value {
            let path = dir.join(&f.csv);
            let table = read_csv(&path, f.column.as_deref(), K::KIND)?;
            self.value = Coefficient::Table(table);
        }
        Ok(())
    }
}

impl<K> Serialize for Tabulated<K> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match &self.value {
            Coefficient::Constant(v) => s.serialize_f64(*v),
            Coefficient::File(f) => f.serialize(s),
            Coefficient::Table(t) => {
                let mut m = s.serialize_map(Some(t.axes.len() + 1))?;
                for a in &t.axes {
                    m.serialize_entry(a.variable.key(), &a.breakpoints)?;
                }
                let shape = t.shape();
                match shape.len() {
                    1 => m.serialize_entry("values", &t.values)?,
                    2 => {
                        let rows: Vec<&[f64]> = t.values.chunks(shape[1]).collect();
                        m.serialize_entry("values", &rows)?
                    }
                    _ => {
                        let planes: Vec<Vec<&[f64]>> = t
                            .values
                            .chunks(shape[1] * shape[2])
                            .map(|p| p.chunks(shape[2]).collect())
                            .collect();
                        m.serialize_entry("values", &planes)?
                    }
                }
                m.end()
            }
        }
    }
}

/// The fields an inline table or file reference may have.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTable {
    csv: Option<PathBuf>,
    column: Option<String>,
    mach: Option<Vec<f64>>,
    alpha_deg: Option<Vec<f64>>,
    beta_deg: Option<Vec<f64>>,
    distance_m: Option<Vec<f64>>,
    lateral_m: Option<Vec<f64>>,
    values: Option<Nested>,
}

/// `values` nested one array per axis.
#[derive(Deserialize)]
#[serde(untagged)]
enum Nested {
    D1(Vec<f64>),
    D2(Vec<Vec<f64>>),
    D3(Vec<Vec<Vec<f64>>>),
}

impl RawTable {
    fn into_coefficient(self, kind: Kind) -> Result<Coefficient, String> {
        // In the kind's nesting order (a variable it may not span goes last, to be refused).
        let mut axes: Vec<Axis> = [
            (Variable::Mach, self.mach),
            (Variable::Alpha, self.alpha_deg),
            (Variable::Beta, self.beta_deg),
            (Variable::Distance, self.distance_m),
            (Variable::Lateral, self.lateral_m),
        ]
        .into_iter()
        .filter_map(|(variable, b)| {
            b.map(|breakpoints| Axis {
                variable,
                breakpoints,
            })
        })
        .collect();
        axes.sort_by_key(|a| {
            kind.allowed()
                .iter()
                .position(|&v| v == a.variable)
                .unwrap_or(usize::MAX)
        });
        if let Some(csv) = self.csv {
            if !axes.is_empty() || self.values.is_some() {
                return Err(
                    "a table is either a file (`csv`) or inline (axes and `values`), not both"
                        .into(),
                );
            }
            return Ok(Coefficient::File(TableFile {
                csv,
                column: self.column,
            }));
        }
        if self.column.is_some() {
            return Err("`column` names a column of a `csv` file; there is none".into());
        }
        let Some(values) = self.values else {
            return Err(format!(
                "an inline table needs its breakpoints ({}) and `values`",
                kind.allowed()
                    .iter()
                    .map(|v| format!("`{}`", v.key()))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        };
        // Every axis is checked first, so that a ragged `values` is reported against a good
        // grid.
        let shape: Vec<usize> = axes.iter().map(|a| a.breakpoints.len()).collect();
        let t = Table {
            axes,
            values: Vec::new(),
        };
        Table::new(t.axes.clone(), vec![0.0; shape.iter().product()], kind)?;
        let ragged = |what: &str, k: usize, found: usize, expected: usize| {
            Err(format!(
                "`values`{what} {k} has {found} values, expected {expected} (one per breakpoint of the {} axis)",
                t.axes[shape.len() - 1].variable.csv_name()
            ))
        };
        let flat = match (values, shape.as_slice()) {
            (Nested::D1(v), [n]) => {
                if v.len() != *n {
                    return Err(format!(
                        "`values` has {} values, expected {n} (one per breakpoint)",
                        v.len()
                    ));
                }
                v
            }
            (Nested::D2(rows), [n0, n1]) => {
                if rows.len() != *n0 {
                    return Err(format!("`values` has {} rows, expected {n0}", rows.len()));
                }
                let mut flat = Vec::with_capacity(n0 * n1);
                for (k, r) in rows.into_iter().enumerate() {
                    if r.len() != *n1 {
                        return ragged(" row", k, r.len(), *n1);
                    }
                    flat.extend(r);
                }
                flat
            }
            (Nested::D3(planes), [n0, n1, n2]) => {
                if planes.len() != *n0 {
                    return Err(format!(
                        "`values` has {} planes, expected {n0}",
                        planes.len()
                    ));
                }
                let mut flat = Vec::with_capacity(n0 * n1 * n2);
                for (k, p) in planes.into_iter().enumerate() {
                    if p.len() != *n1 {
                        return Err(format!(
                            "`values` plane {k} has {} rows, expected {n1}",
                            p.len()
                        ));
                    }
                    for r in p {
                        if r.len() != *n2 {
                            return ragged(&format!(" plane {k} row"), 0, r.len(), *n2);
                        }
                        flat.extend(r);
                    }
                }
                flat
            }
            (v, s) => {
                let depth = match v {
                    Nested::D1(_) => 1,
                    Nested::D2(_) => 2,
                    Nested::D3(_) => 3,
                };
                return Err(format!(
                    "`values` is nested {depth} deep for a table of {} axes: nest one array per axis",
                    s.len()
                ));
            }
        };
        Table::new(t.axes, flat, kind).map(Coefficient::Table)
    }
}

impl<'de, K: TableKind> Deserialize<'de> for Tabulated<K> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<K>(PhantomData<K>);
        impl<'de, K: TableKind> Visitor<'de> for V<K> {
            type Value = Tabulated<K>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(
                    f,
                    "a number, an inline table over {} or {{ csv = \"FILE.csv\" }}",
                    K::KIND.allowed_list(", ")
                )
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
                Ok(Tabulated::constant(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
                Ok(Tabulated::constant(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
                Ok(Tabulated::constant(v as f64))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
                let raw = RawTable::deserialize(de::value::MapAccessDeserializer::new(map))?;
                let value = raw.into_coefficient(K::KIND).map_err(de::Error::custom)?;
                Ok(Tabulated {
                    value,
                    kind: PhantomData,
                })
            }
        }
        d.deserialize_any(V(PhantomData))
    }
}

/// Errors reading a table file. Every variant names the file; those about its content name the
/// line and, where there is one, the column (both counted from 1).
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum TableError {
    /// The file could not be read.
    #[error("{file}: cannot read table: {message}")]
    Io {
        /// The file.
        file: String,
        /// The cause.
        message: String,
    },
    /// No header row.
    #[error("{file}: empty table: expected a header row such as `mach [-],alpha [deg],cz [-]`")]
    Empty {
        /// The file.
        file: String,
    },
    /// A header without a unit.
    #[error(
        "{file}: line {line}, column {column}: `{header}` has no unit: write it as `{header} [{example}]`"
    )]
    MissingUnit {
        /// The file.
        file: String,
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The header given.
        header: String,
        /// A unit it could have.
        example: String,
    },
    /// A unit sepval does not know for this column.
    #[error(
        "{file}: line {line}, column {column}: unknown unit in `{header}`: expected {expected}"
    )]
    UnknownUnit {
        /// The file.
        file: String,
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The header given.
        header: String,
        /// The units accepted.
        expected: String,
    },
    /// Something wrong with the header other than units.
    #[error("{file}: line {line}, column {column}: `{header}`: {reason}")]
    Header {
        /// The file.
        file: String,
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The header given.
        header: String,
        /// What is wrong.
        reason: String,
    },
    /// A row with another number of fields than the header.
    #[error("{file}: line {line}: expected {expected} fields as in the header, found {found}")]
    Ragged {
        /// The file.
        file: String,
        /// Line.
        line: usize,
        /// Fields in the header.
        expected: usize,
        /// Fields found.
        found: usize,
    },
    /// A field that is not a finite number.
    #[error(
        "{file}: line {line}, column {column} (`{header}`): expected a finite number, found `{value}`"
    )]
    NotFinite {
        /// The file.
        file: String,
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// Its header.
        header: String,
        /// The field.
        value: String,
    },
    /// Rows that do not form the table's grid.
    #[error("{file}: line {line}, column {column} (`{header}`): {reason}")]
    Grid {
        /// The file.
        file: String,
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// Its header.
        header: String,
        /// What is wrong.
        reason: String,
    },
}

/// Splits a CSV line into trimmed fields (double quotes around a whole field are removed).
fn fields(line: &str) -> Vec<String> {
    line.split(',')
        .map(|f| {
            let f = f.trim();
            f.strip_prefix('"')
                .and_then(|g| g.strip_suffix('"'))
                .unwrap_or(f)
                .trim()
                .to_string()
        })
        .collect()
}

/// One column of a table file.
enum Column {
    Axis(Variable, Conversion),
    Value(String, Conversion),
}

/// Reads the table of `kind` in a CSV file: a header row `name [unit]` per column, the axis
/// columns first (in nesting order), then one or more value columns, then one row per grid
/// point in row-major order (first axis slowest). `column` picks the value column (needed when
/// there are several). Lines starting with `#` and blank lines are skipped.
pub fn read_csv(path: &Path, column: Option<&str>, kind: Kind) -> Result<Table, TableError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| TableError::Io {
        file: file.clone(),
        message: e.to_string(),
    })?;
    let mut lines = text
        .trim_start_matches('\u{feff}')
        .lines()
        .enumerate()
        .map(|(k, l)| (k + 1, l))
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((header_line, header)) = lines.next() else {
        return Err(TableError::Empty { file });
    };
    let names = fields(header);
    let mut columns = Vec::with_capacity(names.len());
    for (k, h) in names.iter().enumerate() {
        let at = |reason: String| TableError::Header {
            file: file.clone(),
            line: header_line,
            column: k + 1,
            header: h.clone(),
            reason,
        };
        let (name, unit) = match h.find('[') {
            Some(open) if h.ends_with(']') => (h[..open].trim(), h[open + 1..h.len() - 1].trim()),
            _ => {
                let variable = Variable::ALL.iter().find(|v| v.csv_name() == h);
                return Err(TableError::MissingUnit {
                    file: file.clone(),
                    line: header_line,
                    column: k + 1,
                    header: h.clone(),
                    example: variable
                        .map(|v| v.csv_units()[0].0)
                        .unwrap_or(kind.value_units()[0].0)
                        .to_string(),
                });
            }
        };
        let unknown = |accepted: &[(&str, Conversion)]| TableError::UnknownUnit {
            file: file.clone(),
            line: header_line,
            column: k + 1,
            header: h.clone(),
            expected: accepted
                .iter()
                .map(|(u, _)| format!("`{name} [{u}]`"))
                .collect::<Vec<_>>()
                .join(" or "),
        };
        let c = if let Some(v) = Variable::ALL.iter().find(|v| v.csv_name() == name) {
            if !kind.allowed().contains(v) {
                return Err(at(format!(
                    "{} may be tabulated over {} only, not over {name}",
                    kind.what(),
                    kind.allowed_list(", ")
                )));
            }
            let conv = v
                .csv_units()
                .iter()
                .find(|(u, _)| *u == unit)
                .ok_or_else(|| unknown(v.csv_units()))?
                .1;
            if columns.iter().any(|c| matches!(c, Column::Value(..))) {
                return Err(at("axis columns come before the value columns".into()));
            }
            let rank = |v: &Variable| kind.allowed().iter().position(|w| w == v);
            if let Some(Column::Axis(p, _)) = columns.last()
                && rank(p) >= rank(v)
            {
                return Err(at(format!(
                    "axis columns must come in the order {} (first axis slowest)",
                    kind.allowed_list(", ")
                )));
            }
            Column::Axis(*v, conv)
        } else {
            if name.is_empty() {
                return Err(at("a column needs a name".into()));
            }
            let conv = kind
                .value_units()
                .iter()
                .find(|(u, _)| *u == unit)
                .ok_or_else(|| unknown(kind.value_units()))?
                .1;
            if columns
                .iter()
                .any(|c| matches!(c, Column::Value(n, _) if n == name))
            {
                return Err(at(format!("repeats the column `{name}`")));
            }
            Column::Value(name.to_string(), conv)
        };
        columns.push(c);
    }
    let n_axes = columns
        .iter()
        .filter(|c| matches!(c, Column::Axis(..)))
        .count();
    let value_names: Vec<&str> = columns
        .iter()
        .filter_map(|c| match c {
            Column::Value(n, _) => Some(n.as_str()),
            _ => None,
        })
        .collect();
    let header_error = |column: usize, reason: String| TableError::Header {
        file: file.clone(),
        line: header_line,
        column,
        header: names
            .get(column.saturating_sub(1))
            .cloned()
            .unwrap_or_default(),
        reason,
    };
    if n_axes == 0 {
        return Err(header_error(
            1,
            format!(
                "no axis column: {} is tabulated over {}",
                kind.what(),
                kind.allowed_list(", ")
            ),
        ));
    }
    if let Some(r) = kind.required()
        && !columns
            .iter()
            .any(|c| matches!(c, Column::Axis(v, _) if *v == r))
    {
        return Err(header_error(
            1,
            format!("no {} column: {} needs one", r.csv_name(), kind.what()),
        ));
    }
    let chosen = match column {
        Some(want) => columns
            .iter()
            .position(|c| matches!(c, Column::Value(n, _) if n == want))
            .ok_or_else(|| {
                header_error(
                    n_axes + 1,
                    format!(
                        "no value column `{want}` (the file has: {})",
                        value_names.join(", ")
                    ),
                )
            })?,
        None if value_names.len() == 1 => n_axes,
        None => {
            return Err(header_error(
                n_axes + 1,
                format!(
                    "{} value columns ({}): name one with `column = \"...\"` in the scenario",
                    value_names.len(),
                    value_names.join(", ")
                ),
            ));
        }
    };

    // Rows: every field a finite number, converted to the scenario's units.
    let mut rows: Vec<(usize, Vec<f64>)> = Vec::new();
    for (line, text) in lines {
        let f = fields(text);
        if f.len() != columns.len() {
            return Err(TableError::Ragged {
                file,
                line,
                expected: columns.len(),
                found: f.len(),
            });
        }
        let mut row = Vec::with_capacity(f.len());
        for (k, (s, c)) in f.iter().zip(&columns).enumerate() {
            let v: f64 = match s.parse::<f64>() {
                Ok(v) if v.is_finite() => v,
                _ => {
                    return Err(TableError::NotFinite {
                        file,
                        line,
                        column: k + 1,
                        header: names[k].clone(),
                        value: s.clone(),
                    });
                }
            };
            let conv = match c {
                Column::Axis(_, conv) | Column::Value(_, conv) => *conv,
            };
            row.push(conv.apply(v));
        }
        if rows.len() >= MAX_TABLE_VALUES {
            return Err(TableError::Grid {
                file,
                line,
                column: 1,
                header: names[0].clone(),
                reason: format!("more rows than the limit of {MAX_TABLE_VALUES} grid points"),
            });
        }
        rows.push((line, row));
    }
    if rows.is_empty() {
        return Err(header_error(1, "no rows after the header".into()));
    }

    // The grid: the breakpoints of axis j are its values at rows 0, stride_j, 2 stride_j, ...
    // while the slower axes keep row 0's values (stride_j: the product of the faster axes'
    // sizes, found from the last axis backwards).
    let grid_error = |r: usize, j: usize, reason: String| TableError::Grid {
        file: file.clone(),
        line: rows[r].0,
        column: j + 1,
        header: names[j].clone(),
        reason,
    };
    let mut sizes = vec![0usize; n_axes];
    let mut breakpoints: Vec<Vec<f64>> = vec![Vec::new(); n_axes];
    let mut stride = 1usize;
    for j in (0..n_axes).rev() {
        let mut r = 0;
        while r < rows.len() && (0..j).all(|i| rows[r].1[i].to_bits() == rows[0].1[i].to_bits()) {
            let x = rows[r].1[j];
            if let Some(&prev) = breakpoints[j].last()
                && x <= prev
            {
                return Err(grid_error(
                    r,
                    j,
                    format!(
                        "breakpoints are not strictly increasing: {x} after {prev} (rows are in row-major order, the first axis slowest)"
                    ),
                ));
            }
            breakpoints[j].push(x);
            r += stride;
        }
        sizes[j] = breakpoints[j].len();
        if sizes[j] < 2 {
            return Err(grid_error(
                0,
                j,
                format!(
                    "axis {} has 1 breakpoint: expected at least 2 (give a constant instead of a table)",
                    names[j]
                ),
            ));
        }
        stride *= sizes[j];
    }
    if rows.len() != stride {
        let last = rows.len().min(stride) - 1;
        return Err(grid_error(
            last,
            0,
            format!(
                "the rows do not form a complete grid: {} rows for {} breakpoints ({stride} rows expected)",
                rows.len(),
                sizes
                    .iter()
                    .map(|s| s.to_string())
                    .collect::<Vec<_>>()
                    .join(" x ")
            ),
        ));
    }
    let mut values = Vec::with_capacity(rows.len());
    for (r, (_, row)) in rows.iter().enumerate() {
        let mut rem = r;
        for j in (0..n_axes).rev() {
            let expected = breakpoints[j][rem % sizes[j]];
            rem /= sizes[j];
            if row[j].to_bits() != expected.to_bits() {
                return Err(grid_error(
                    r,
                    j,
                    format!(
                        "expected {expected} here: rows list every grid point in row-major order (the first axis slowest)"
                    ),
                ));
            }
        }
        values.push(row[chosen]);
    }
    let axes = columns
        .iter()
        .zip(breakpoints)
        .filter_map(|(c, breakpoints)| match c {
            Column::Axis(variable, _) => Some(Axis {
                variable: *variable,
                breakpoints,
            }),
            Column::Value(..) => None,
        })
        .collect();
    Table::new(axes, values, kind).map_err(|reason| header_error(1, reason))
}

/// Writes a table as CSV (header `name [unit]`, one row per grid point, numbers in the shortest
/// form that reads back as the same double): one or more value columns on one grid.
pub fn write_csv(axes: &[Axis], columns: &[(&str, &str, &[f64])]) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let head: Vec<String> = axes
        .iter()
        .map(|a| format!("{} [{}]", a.variable.csv_name(), a.variable.unit()))
        .chain(columns.iter().map(|(n, u, _)| format!("{n} [{u}]")))
        .collect();
    s.push_str(&head.join(","));
    s.push('\n');
    let sizes: Vec<usize> = axes.iter().map(|a| a.breakpoints.len()).collect();
    let n: usize = sizes.iter().product();
    for r in 0..n {
        let mut rem = r;
        let mut idx = vec![0; axes.len()];
        for j in (0..axes.len()).rev() {
            idx[j] = rem % sizes[j];
            rem /= sizes[j];
        }
        let fields: Vec<String> = axes
            .iter()
            .zip(&idx)
            .map(|(a, &i)| format!("{:?}", a.breakpoints[i]))
            .chain(columns.iter().map(|(_, _, v)| format!("{:?}", v[r])))
            .collect();
        let _ = writeln!(s, "{}", fields.join(","));
    }
    s
}

// ---------------------------------------------------------------------------------------------
// Interpolation at run time.

/// Most tables one scenario can hold (13 aerodynamic fields and 6 interference increments).
pub const MAX_TABLES: usize = 19;
/// Most run-time groups (tables sharing their axes): one per static coefficient and per
/// interference increment at most.
const MAX_GROUPS: usize = 12;

/// Where a run-time table's value goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// A static coefficient: 0 CA, 1 CY, 2 CZ, 3 Cl, 4 Cm, 5 Cn.
    Static(usize),
    /// An interference increment: 0 dCX, ..., 5 dCn (times its multiplier).
    Interference(usize),
}

impl Target {
    /// Its place in the output of [`PreparedTables::evaluate`].
    fn slot(self) -> usize {
        match self {
            Target::Static(k) => k,
            Target::Interference(k) => 6 + k,
        }
    }
}

/// What a scenario's table spans, for reports.
#[derive(Debug, Clone, PartialEq)]
pub struct TableInfo {
    /// The scenario field, e.g. `aero.cz`.
    pub name: String,
    /// Each axis and its breakpoint range (first, last), in the variable's unit.
    pub axes: Vec<(Variable, f64, f64)>,
}

/// One axis of a run-time group: breakpoints in the force evaluation's units (angles in rad).
#[derive(Debug, Clone)]
struct RuntimeAxis {
    variable: Variable,
    /// Index of its input in [`PreparedTables::evaluate`]'s `inputs`.
    input: usize,
    breakpoints: Vec<f64>,
    /// Excursions are reported in the variable's unit: degrees per radian for angles.
    report_scale: f64,
}

/// Run-time tables of one block (static coefficients or interference increments) sharing their
/// axes: each grid point holds the block's six lanes (CA, CY, CZ, Cl, Cm, Cn or dCX, ..., dCn;
/// 0 in a lane no table of the group fills), so that one interval search and one set of
/// weights serve them all and the six lanes are interpolated together.
#[derive(Debug, Clone)]
struct Group {
    axes: Vec<RuntimeAxis>,
    /// Values of one grid point (6) times the sizes of the faster axes.
    strides: [usize; 3],
    /// 0 for the static coefficients, 6 for the interference increments.
    block: usize,
    /// The tables (indices into `info`) of the group.
    ids: Vec<usize>,
    values: Vec<f64>,
    /// Per grid cell, the multilinear interpolant as a polynomial in the inputs, 2^k
    /// coefficient lanes (bit j of a coefficient's index: times x_j) of six values each.
    cells: Vec<f64>,
    /// Doubles of one cell times the cell counts of the faster axes.
    cell_strides: [usize; 3],
}

impl Group {
    /// The group's six lanes at `inputs` (held at the edges; `outside` set when held).
    #[inline(always)]
    fn interpolate(
        &self,
        cursors: &[Cell<u32>; 3],
        inputs: &Inputs,
        outside: &mut bool,
    ) -> [f64; 6] {
        let c = &self.cells;
        // The cell's polynomial, nested: (c0 + c1 x) + y (c2 + c3 x), and so on, one arm per
        // axis count (unrolled). Helper functions, not closures, do the arithmetic: a closure
        // is not always inlined into the FMA-compiled propagator.
        match self.axes.len() {
            0 => *lanes(c, 0),
            1 => {
                let (at, x) = self.axis(0, cursors, inputs, outside);
                lin(x, lanes(c, at), lanes(c, at + 6))
            }
            2 => {
                let (a0, x) = self.axis(0, cursors, inputs, outside);
                let (a1, y) = self.axis(1, cursors, inputs, outside);
                bilinear(c, a0 + a1, x, y)
            }
            _ => {
                let (a0, x) = self.axis(0, cursors, inputs, outside);
                let (a1, y) = self.axis(1, cursors, inputs, outside);
                let (a2, z) = self.axis(2, cursors, inputs, outside);
                let at = a0 + a1 + a2;
                lin(z, &bilinear(c, at, x, y), &bilinear(c, at + 24, x, y))
            }
        }
    }

    /// Axis `k` at `inputs`: the offset of its interval's cells and its input held at the
    /// edges (`outside` set when held).
    #[inline(always)]
    fn axis(
        &self,
        k: usize,
        cursors: &[Cell<u32>; 3],
        inputs: &Inputs,
        outside: &mut bool,
    ) -> (usize, f64) {
        let a = &self.axes[k];
        let (i, x, out) = locate(a, pick(a.input, inputs), &cursors[k]);
        *outside |= out;
        (i * self.cell_strides[k], x)
    }

    /// Expands the grid values into each cell's polynomial (docs/model.md section 3): on
    /// [x0, x1] the linear interpolant is v0 (x1 - x)/dx + v1 (x - x0)/dx, and the
    /// multilinear one the product of such factors summed over the cell's 2^k corners; its
    /// monomial coefficients make an evaluation two fused multiply-adds deep per axis less than
    /// weights and differences would (the value is the same to rounding).
    fn build_cells(&mut self) {
        let k = self.axes.len();
        let intervals: Vec<usize> = self.axes.iter().map(|a| a.breakpoints.len() - 1).collect();
        let per_cell = 6 << k;
        let mut stride = per_cell;
        for j in (0..k).rev() {
            self.cell_strides[j] = stride;
            stride *= intervals[j];
        }
        let cells: usize = intervals.iter().product();
        self.cells = vec![0.0; cells * per_cell];
        for cell in 0..cells {
            let mut idx = [0usize; 3];
            let mut rem = cell;
            for j in (0..k).rev() {
                idx[j] = rem % intervals[j];
                rem /= intervals[j];
            }
            for corner in 0..(1usize << k) {
                let point: usize = (0..k)
                    .map(|j| (idx[j] + ((corner >> j) & 1)) * self.strides[j])
                    .sum();
                for mask in 0..(1usize << k) {
                    let mut factor = 1.0;
                    for (j, a) in self.axes.iter().enumerate() {
                        let (x0, x1) = (a.breakpoints[idx[j]], a.breakpoints[idx[j] + 1]);
                        let dx = x1 - x0;
                        let upper = (corner >> j) & 1 == 1;
                        factor *= match ((mask >> j) & 1 == 1, upper) {
                            (true, false) => -1.0 / dx,
                            (true, true) => 1.0 / dx,
                            (false, false) => x1 / dx,
                            (false, true) => -x0 / dx,
                        };
                    }
                    let at = cell * per_cell + mask * 6;
                    for c in 0..6 {
                        self.cells[at + c] += factor * self.values[point + c];
                    }
                }
            }
        }
    }
}

/// The tables of one scenario at its flight Mach, ready for the force evaluation.
#[derive(Debug, Clone, Default)]
pub struct PreparedTables {
    /// Every table of the scenario, in report order.
    pub info: Vec<TableInfo>,
    /// Each table's excursion beyond its Mach axis (0 inside, or without one).
    mach_excursion: Vec<f64>,
    /// The static coefficients' groups first, then the interference increments'.
    groups: Vec<Group>,
    /// How many groups are of static coefficients.
    static_groups: usize,
    /// Constant static coefficients (CY, CZ, Cl, Cm, Cn given as numbers; CA is never here).
    constants: [f64; 6],
    /// Whether the force evaluation has anything to add (groups, or a constant not 0).
    runtime: bool,
}

impl PreparedTables {
    /// No tables.
    pub const NONE: PreparedTables = PreparedTables {
        info: Vec::new(),
        mach_excursion: Vec::new(),
        groups: Vec::new(),
        static_groups: 0,
        constants: [0.0; 6],
        runtime: false,
    };

    /// Whether the scenario has any table.
    #[inline(always)]
    pub fn any(&self) -> bool {
        !self.info.is_empty()
    }

    /// Whether force evaluations must see the tables: to interpolate them, or to count the
    /// evaluations of a run whose Mach lies outside a Mach axis. A scenario whose only tables
    /// are Mach tables containing its Mach (folded into constants) runs the contract's path.
    #[inline(always)]
    pub fn in_evaluation(&self) -> bool {
        self.runtime || self.mach_excursion.iter().any(|&e| e > 0.0)
    }

    /// Whether the force evaluation has tables to interpolate.
    #[inline(always)]
    pub fn runtime(&self) -> bool {
        self.runtime
    }

    /// Registers a table (name for reports) and interpolates its Mach axis at `mach`: the
    /// table over its other axes (or a 0-axis table: one value).
    pub fn slice_mach(
        &mut self,
        name: &str,
        table: &Table,
        mach: f64,
    ) -> (usize, Vec<Axis>, Vec<f64>) {
        let id = self.info.len();
        self.info.push(TableInfo {
            name: name.to_string(),
            axes: table
                .axes
                .iter()
                .map(|a| {
                    (
                        a.variable,
                        a.breakpoints[0],
                        a.breakpoints[a.breakpoints.len() - 1],
                    )
                })
                .collect(),
        });
        let first = &table.axes[0];
        if first.variable != Variable::Mach {
            self.mach_excursion.push(0.0);
            return (id, table.axes.clone(), table.values.clone());
        }
        let b = &first.breakpoints;
        let (i, t, excursion) = locate_cold(b, mach);
        self.mach_excursion.push(excursion.abs());
        let inner: usize = table.values.len() / b.len();
        let lo = &table.values[i * inner..(i + 1) * inner];
        let hi = &table.values[(i + 1) * inner..(i + 2) * inner];
        let values = lo
            .iter()
            .zip(hi)
            .map(|(&v0, &v1)| t.mul_add(v1 - v0, v0))
            .collect();
        (id, table.axes[1..].to_vec(), values)
    }

    /// Adds a table (already sliced at the Mach, registered as `id`) for the force evaluation:
    /// a channel of the group with the same axes, or a new group.
    pub fn add_runtime(&mut self, id: usize, target: Target, axes: Vec<Axis>, values: Vec<f64>) {
        let runtime: Vec<RuntimeAxis> = axes
            .iter()
            .map(|a| {
                let (breakpoints, report_scale): (Vec<f64>, f64) = match a.variable {
                    Variable::Alpha | Variable::Beta => (
                        a.breakpoints.iter().map(|d| d.to_radians()).collect(),
                        1.0f64.to_degrees(),
                    ),
                    _ => (a.breakpoints.clone(), 1.0),
                };
                RuntimeAxis {
                    variable: a.variable,
                    input: match a.variable {
                        Variable::Alpha => 0,
                        Variable::Beta => 1,
                        Variable::Distance => 2,
                        // Mach never reaches the run time (sliced above).
                        Variable::Lateral | Variable::Mach => 3,
                    },
                    breakpoints,
                    report_scale,
                }
            })
            .collect();
        let sizes: Vec<usize> = axes.iter().map(|a| a.breakpoints.len()).collect();
        let slot = target.slot();
        let (block, lane) = (slot / 6 * 6, slot % 6);
        let same = |g: &Group| {
            g.block == block
                && g.axes.len() == runtime.len()
                && g.axes
                    .iter()
                    .zip(&runtime)
                    .all(|(a, b)| a.variable == b.variable && a.breakpoints == b.breakpoints)
        };
        let g = match self.groups.iter().position(same) {
            Some(k) => &mut self.groups[k],
            None => {
                assert!(
                    self.groups.len() < MAX_GROUPS,
                    "at most {MAX_GROUPS} run-time groups"
                );
                // Static groups before interference groups.
                let at = if block == 0 {
                    self.static_groups += 1;
                    self.static_groups - 1
                } else {
                    self.groups.len()
                };
                self.groups.insert(
                    at,
                    Group {
                        axes: runtime,
                        strides: strides(&sizes, 6),
                        block,
                        ids: Vec::new(),
                        values: vec![0.0; 6 * values.len()],
                        cells: Vec::new(),
                        cell_strides: [0; 3],
                    },
                );
                &mut self.groups[at]
            }
        };
        self.runtime = true;
        g.ids.push(id);
        for (p, v) in values.iter().enumerate() {
            // Two tables of one coefficient in one group add (a static table and a constant
            // never meet here; the scenario has one field per coefficient).
            g.values[6 * p + lane] += v;
        }
        g.build_cells();
    }

    /// The tables' contributions at the inputs of one force evaluation: static coefficients
    /// (CA, CY, CZ, Cl, Cm, Cn) and interference increments (before their multipliers), without
    /// the constant static coefficients ([`PreparedTables::constants`]).
    #[inline(always)]
    pub fn evaluate(&self, state: &TableState, inputs: &Inputs) -> ([f64; 6], [f64; 6]) {
        let mut statics = [0.0; 6];
        let mut increments = [0.0; 6];
        let mut outside = false;
        for (g, cursors) in self.groups.iter().zip(&state.cursor) {
            let r = g.interpolate(cursors, inputs, &mut outside);
            let sum = if g.block == 0 {
                &mut statics
            } else {
                &mut increments
            };
            for c in 0..6 {
                sum[c] += r[c];
            }
        }
        if outside {
            self.record_outside(state, inputs);
        }
        (statics, increments)
    }

    /// The constant static coefficients (CY, CZ, Cl, Cm, Cn given as numbers next to tables).
    #[inline(always)]
    pub fn constants(&self) -> &[f64; 6] {
        &self.constants
    }

    /// Counts, per table, an evaluation outside it and its worst excursion per variable.
    #[cold]
    #[inline(never)]
    fn record_outside(&self, state: &TableState, inputs: &Inputs) {
        for g in &self.groups {
            let mut out = false;
            for a in &g.axes {
                let x = pick(a.input, inputs);
                let b = &a.breakpoints;
                let e = (b[0] - x).max(x - b[b.len() - 1]);
                if e > 0.0 {
                    out = true;
                    let e = e * a.report_scale;
                    for &id in &g.ids {
                        let w = &state.worst[id][a.variable.index()];
                        w.set(w.get().max(e));
                    }
                }
            }
            if out {
                for &id in &g.ids {
                    state.count[id].set(state.count[id].get() + 1);
                }
            }
        }
    }

    /// The excursions of a run, per table (tables never left are omitted).
    pub fn report(&self, ex: &TableExcursions) -> Vec<TableExcursion> {
        let mut out = Vec::new();
        for (id, info) in self.info.iter().enumerate() {
            let mach = self.mach_excursion[id];
            let count = if mach > 0.0 {
                ex.evaluations
            } else {
                ex.count[id]
            };
            if count == 0 {
                continue;
            }
            let axes = info
                .axes
                .iter()
                .filter_map(|&(v, lo, hi)| {
                    let worst = if v == Variable::Mach {
                        mach
                    } else {
                        ex.worst[id][v.index()]
                    };
                    (worst > 0.0).then_some(AxisExcursion {
                        variable: v.key().to_string(),
                        range: [lo, hi],
                        worst_excursion: worst,
                    })
                })
                .collect();
            out.push(TableExcursion {
                table: info.name.clone(),
                evaluations_outside: count,
                evaluations: ex.evaluations,
                axes,
            });
        }
        out
    }
}

/// The freestream database's constants at the flight Mach: the scenario's constants, and its
/// derivative tables (and a CA table over Mach only) interpolated at the Mach. A derivative
/// left out (a static table replaces it) is 0; a CA tabulated over alpha or beta is 0 here and
/// interpolated at each force evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs)]
pub struct AeroAtMach {
    pub ca0: f64,
    pub cz_alpha_per_rad: f64,
    pub cy_beta_per_rad: f64,
    pub cm_alpha_per_rad: f64,
    pub cn_beta_per_rad: f64,
    pub cl_p_per_rad: f64,
    pub cm_q_per_rad: f64,
    pub cn_r_per_rad: f64,
}

/// A scenario's tables set up at its flight Mach (docs/model.md section 3): the constants of
/// the freestream database, the constant interference increments at carriage (0 for a
/// tabulated one) and the tables the force evaluation interpolates.
pub fn prepare(scenario: &crate::scenario::Scenario) -> (AeroAtMach, [f64; 6], PreparedTables) {
    let mach = scenario.flight.mach;
    let mut p = PreparedTables::default();
    let a = &scenario.aero;
    let unread = "a validated scenario holds no unread table files";
    let derivative = |p: &mut PreparedTables, name: &str, c: Option<&Coefficient>| match c {
        None => 0.0,
        Some(Coefficient::Constant(v)) => *v,
        Some(Coefficient::Table(t)) => p.slice_mach(name, t, mach).2[0],
        Some(Coefficient::File(_)) => unreachable!("{unread}"),
    };
    let mut consts = AeroAtMach {
        ca0: 0.0,
        cz_alpha_per_rad: derivative(
            &mut p,
            "aero.cz_alpha_per_rad",
            a.cz_alpha_per_rad.as_ref().map(|c| &c.value),
        ),
        cy_beta_per_rad: derivative(
            &mut p,
            "aero.cy_beta_per_rad",
            a.cy_beta_per_rad.as_ref().map(|c| &c.value),
        ),
        cm_alpha_per_rad: derivative(
            &mut p,
            "aero.cm_alpha_per_rad",
            a.cm_alpha_per_rad.as_ref().map(|c| &c.value),
        ),
        cn_beta_per_rad: derivative(
            &mut p,
            "aero.cn_beta_per_rad",
            a.cn_beta_per_rad.as_ref().map(|c| &c.value),
        ),
        cl_p_per_rad: derivative(&mut p, "aero.cl_p_per_rad", Some(&a.cl_p_per_rad.value)),
        cm_q_per_rad: derivative(&mut p, "aero.cm_q_per_rad", Some(&a.cm_q_per_rad.value)),
        cn_r_per_rad: derivative(&mut p, "aero.cn_r_per_rad", Some(&a.cn_r_per_rad.value)),
    };
    let statics = [
        ("aero.ca0", Some(&a.ca0)),
        ("aero.cy", a.cy.as_ref()),
        ("aero.cz", a.cz.as_ref()),
        ("aero.cl", a.cl.as_ref()),
        ("aero.cm", a.cm.as_ref()),
        ("aero.cn", a.cn.as_ref()),
    ];
    for (k, (name, c)) in statics.into_iter().enumerate() {
        match c.map(|c| &c.value) {
            None => {}
            Some(Coefficient::Constant(v)) if k == 0 => consts.ca0 = *v,
            Some(Coefficient::Constant(v)) => {
                p.constants[k] = *v;
                p.runtime |= *v != 0.0;
            }
            Some(Coefficient::Table(t)) => {
                let (id, axes, values) = p.slice_mach(name, t, mach);
                if k == 0 && axes.is_empty() {
                    // CA over Mach only: a constant of the run, as the contract's CA0.
                    consts.ca0 = values[0];
                } else {
                    p.add_runtime(id, Target::Static(k), axes, values);
                }
            }
            Some(Coefficient::File(_)) => unreachable!("{unread}"),
        }
    }
    let mut increments = [0.0; 6];
    for (k, (name, c)) in scenario.interference.increments().into_iter().enumerate() {
        match &c.value {
            Coefficient::Constant(v) => increments[k] = *v,
            Coefficient::Table(t) => {
                let (id, axes, values) = p.slice_mach(name, t, mach);
                p.add_runtime(id, Target::Interference(k), axes, values);
            }
            Coefficient::File(_) => unreachable!("{unread}"),
        }
    }
    (consts, increments, p)
}

fn strides(sizes: &[usize], channels: usize) -> [usize; 3] {
    let mut s = [0usize; 3];
    let mut acc = channels;
    for k in (0..sizes.len()).rev() {
        s[k] = acc;
        acc *= sizes[k];
    }
    s
}

/// The interval of `x` among breakpoints `b` (index i of [b_i, b_{i+1}]), the weight t in [0, 1]
/// and the signed excursion beyond the table (0 inside), for a one-off lookup.
fn locate_cold(b: &[f64], x: f64) -> (usize, f64, f64) {
    let n = b.len();
    if x <= b[0] {
        return (0, 0.0, x - b[0]);
    }
    if x >= b[n - 1] {
        return (n - 2, 1.0, x - b[n - 1]);
    }
    let i = b.partition_point(|&bp| bp <= x) - 1;
    (i, (x - b[i]) / (b[i + 1] - b[i]), 0.0)
}

/// [`locate_cold`] hunting from the previous interval (`cursor`): the interval, `x` held at
/// the table's edges, and whether it was outside. A NaN input stays NaN (the run then
/// diverges).
#[inline(always)]
fn locate(a: &RuntimeAxis, x: f64, cursor: &Cell<u32>) -> (usize, f64, bool) {
    let b = &a.breakpoints;
    let n = b.len();
    if x < b[0] {
        return (0, b[0], true);
    }
    if x > b[n - 1] {
        return (n - 2, b[n - 1], true);
    }
    let mut i = cursor.get() as usize;
    while i > 0 && x < b[i] {
        i -= 1;
    }
    while i + 2 < n && x > b[i + 1] {
        i += 1;
    }
    cursor.set(i as u32);
    (i, x, false)
}

/// Six lanes of `c` from `at`.
#[inline(always)]
fn lanes(c: &[f64], at: usize) -> &[f64; 6] {
    c[at..at + 6].try_into().expect("six lanes")
}

/// a + x b, lane by lane.
#[inline(always)]
fn lin(x: f64, a: &[f64; 6], b: &[f64; 6]) -> [f64; 6] {
    [
        x.mul_add(b[0], a[0]),
        x.mul_add(b[1], a[1]),
        x.mul_add(b[2], a[2]),
        x.mul_add(b[3], a[3]),
        x.mul_add(b[4], a[4]),
        x.mul_add(b[5], a[5]),
    ]
}

/// The input of an axis (`input` as [`RuntimeAxis::input`]), chosen among scalars: an array
/// indexed at run time would go through memory, and its assembly from four scalar stores into
/// one vector load stalls store forwarding at every force evaluation.
#[inline(always)]
fn pick(input: usize, inputs: &Inputs) -> f64 {
    match input {
        0 => inputs.alpha_rad,
        1 => inputs.beta_rad,
        2 => inputs.distance_m,
        _ => inputs.lateral_m,
    }
}

/// What the run-time tables are looked up at.
#[derive(Debug, Clone, Copy)]
pub struct Inputs {
    /// Local angle of attack \[rad\].
    pub alpha_rad: f64,
    /// Local sideslip \[rad\].
    pub beta_rad: f64,
    /// Distance of the CG from carriage \[m\].
    pub distance_m: f64,
    /// Lateral offset of the CG from carriage (launch-frame y) \[m\].
    pub lateral_m: f64,
}

/// (c0 + c1 x) + y (c2 + c3 x) with the four coefficient lanes from `at`.
#[inline(always)]
fn bilinear(c: &[f64], at: usize, x: f64, y: f64) -> [f64; 6] {
    let p = lin(x, lanes(c, at), lanes(c, at + 6));
    let q = lin(x, lanes(c, at + 12), lanes(c, at + 18));
    lin(y, &p, &q)
}

/// One propagation's table scratch: interval cursors and excursion counts (fixed size).
#[derive(Debug, Default)]
pub struct TableState {
    cursor: [[Cell<u32>; 3]; MAX_GROUPS],
    evaluations: Cell<u64>,
    count: [Cell<u64>; MAX_TABLES],
    worst: [[Cell<f64>; 5]; MAX_TABLES],
}

impl TableState {
    /// Counts one force evaluation (of a scenario with tables).
    #[inline(always)]
    pub fn count_evaluation(&self) {
        self.evaluations.set(self.evaluations.get() + 1);
    }

    /// The counts so far.
    pub fn excursions(&self) -> TableExcursions {
        TableExcursions {
            evaluations: self.evaluations.get(),
            count: std::array::from_fn(|k| self.count[k].get()),
            worst: std::array::from_fn(|k| std::array::from_fn(|v| self.worst[k][v].get())),
        }
    }
}

/// How often a run's force evaluations left each table, and how far (fixed size, in
/// [`crate::propagator::RunLog`]); [`PreparedTables::report`] names them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableExcursions {
    /// Force evaluations that looked tables up.
    pub evaluations: u64,
    /// Per table: evaluations outside it (beyond an axis other than Mach).
    pub count: [u64; MAX_TABLES],
    /// Per table and variable ([`Variable::ALL`] order): the largest excursion, in the
    /// variable's unit.
    pub worst: [[f64; 5]; MAX_TABLES],
}

impl Default for TableExcursions {
    fn default() -> Self {
        TableExcursions {
            evaluations: 0,
            count: [0; MAX_TABLES],
            worst: [[0.0; 5]; MAX_TABLES],
        }
    }
}

/// A table a run left: how often and how far beyond each axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TableExcursion {
    /// The scenario field, e.g. `aero.cz`.
    pub table: String,
    /// Force evaluations (RK4 stages) outside the table, its value held at the edge.
    pub evaluations_outside: u64,
    /// Force evaluations of the run.
    pub evaluations: u64,
    /// Each axis left: its range and the largest excursion beyond it.
    pub axes: Vec<AxisExcursion>,
}

/// The excursion beyond one axis of a table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AxisExcursion {
    /// The variable, with its unit (`alpha_deg`, `distance_m`, `mach`).
    pub variable: String,
    /// The table's first and last breakpoint.
    pub range: [f64; 2],
    /// The largest distance beyond the range, in the variable's unit.
    pub worst_excursion: f64,
}

impl fmt::Display for TableExcursion {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(
            f,
            "left table `{}` in {} of {} force evaluations (value held at the edge)",
            self.table, self.evaluations_outside, self.evaluations
        )?;
        for a in &self.axes {
            write!(
                f,
                "; {} up to {} beyond [{}, {}]",
                a.variable, a.worst_excursion, a.range[0], a.range[1]
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact values on purpose: interpolation of representable data
mod tests {
    use super::*;

    fn at(alpha_rad: f64, beta_rad: f64) -> Inputs {
        Inputs {
            alpha_rad,
            beta_rad,
            distance_m: 0.0,
            lateral_m: 0.0,
        }
    }

    fn axis(variable: Variable, b: &[f64]) -> Axis {
        Axis {
            variable,
            breakpoints: b.to_vec(),
        }
    }

    #[test]
    fn bilinear_interpolation_and_edge_hold() {
        let mut p = PreparedTables::default();
        let t = Table::new(
            vec![
                axis(Variable::Mach, &[0.5, 1.0]),
                axis(Variable::Alpha, &[0.0, 10.0]),
                axis(Variable::Beta, &[-5.0, 5.0]),
            ],
            vec![0.0, 1.0, 2.0, 3.0, 10.0, 11.0, 12.0, 13.0],
            Kind::Static,
        )
        .unwrap();
        let (id, axes, values) = p.slice_mach("aero.cz", &t, 0.75);
        assert_eq!(values, vec![5.0, 6.0, 7.0, 8.0]);
        p.add_runtime(id, Target::Static(2), axes, values);
        let state = TableState::default();
        state.count_evaluation();
        let (s, _) = p.evaluate(&state, &at(5f64.to_radians(), 0.0));
        assert!((s[2] - 6.5).abs() < 1e-12, "{}", s[2]);
        // Beyond alpha: held at the alpha = 10 deg edge and recorded.
        state.count_evaluation();
        let (s, _) = p.evaluate(&state, &at(12f64.to_radians(), 5.0f64.to_radians()));
        assert!((s[2] - 8.0).abs() < 1e-12, "{}", s[2]);
        let r = p.report(&state.excursions());
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].evaluations_outside, 1);
        assert_eq!(r[0].evaluations, 2);
        assert!((r[0].axes[0].worst_excursion - 2.0).abs() < 1e-9, "{r:?}");
    }

    #[test]
    fn mach_beyond_the_table_is_held_and_counts_every_evaluation() {
        let mut p = PreparedTables::default();
        let t = Table::new(
            vec![axis(Variable::Mach, &[0.5, 0.9])],
            vec![1.0, 2.0],
            Kind::Derivative,
        )
        .unwrap();
        let (_, axes, values) = p.slice_mach("aero.cm_q_per_rad", &t, 0.95);
        assert!(axes.is_empty());
        assert_eq!(values, vec![2.0]);
        let ex = TableExcursions {
            evaluations: 40,
            ..TableExcursions::default()
        };
        let r = p.report(&ex);
        assert_eq!(r[0].evaluations_outside, 40);
        assert!((r[0].axes[0].worst_excursion - 0.05).abs() < 1e-12);
    }

    #[test]
    fn tables_are_checked() {
        let e = Table::new(
            vec![axis(Variable::Alpha, &[0.0, 1.0])],
            vec![0.0, 1.0],
            Kind::Derivative,
        )
        .unwrap_err();
        assert_eq!(
            e,
            "is a table over alpha: a derivative may be tabulated over mach only"
        );
        let e = Table::new(
            vec![axis(Variable::Mach, &[0.9, 0.6])],
            vec![0.0, 1.0],
            Kind::Static,
        )
        .unwrap_err();
        assert_eq!(
            e,
            "axis mach breakpoints are not strictly increasing: 0.6 after 0.9"
        );
        let e = Table::new(
            vec![axis(Variable::Alpha, &[0.0, 1.0])],
            vec![0.0, 1.0],
            Kind::Interference,
        )
        .unwrap_err();
        assert_eq!(
            e,
            "has no distance axis: an interference increment is tabulated over distance at least"
        );
    }
}
