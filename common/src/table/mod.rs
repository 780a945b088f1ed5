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

use serde::{Deserialize, Serialize};

use sepval_core::limits::{MAX_MACH, MAX_POSITION_M};
use sepval_core::units::{M_PER_FT, M_PER_IN};

pub use sepval_core::limits::MAX_TABLE_VALUES;

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
    /// A point's launch-frame x from the CG's carriage position (forward) \[m\]: an axis of
    /// the aircraft's flowfield (docs/model.md section 3b).
    X,
    /// A point's launch-frame y from the CG's carriage position (right) \[m\].
    Y,
    /// A point's launch-frame z from the CG's carriage position (down) \[m\].
    Z,
}

impl Variable {
    /// Every variable (each [`Kind`] has its own nesting order, [`Kind::allowed`]).
    pub const ALL: [Variable; 8] = [
        Variable::Mach,
        Variable::Alpha,
        Variable::Beta,
        Variable::Distance,
        Variable::Lateral,
        Variable::X,
        Variable::Y,
        Variable::Z,
    ];

    /// Its key in an inline TOML table (with the unit of its breakpoints).
    pub fn key(self) -> &'static str {
        match self {
            Variable::Mach => "mach",
            Variable::Alpha => "alpha_deg",
            Variable::Beta => "beta_deg",
            Variable::Distance => "distance_m",
            Variable::Lateral => "lateral_m",
            Variable::X => "x_m",
            Variable::Y => "y_m",
            Variable::Z => "z_m",
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
            Variable::X => "x",
            Variable::Y => "y",
            Variable::Z => "z",
        }
    }

    /// The unit breakpoints are kept in (scenario files, reports).
    pub fn unit(self) -> &'static str {
        match self {
            Variable::Mach => "-",
            Variable::Alpha | Variable::Beta => "deg",
            Variable::Distance | Variable::Lateral | Variable::X | Variable::Y | Variable::Z => "m",
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
            Variable::Distance | Variable::Lateral | Variable::X | Variable::Y | Variable::Z => &[
                ("m", Conversion::Scale(1.0)),
                ("ft", Conversion::Scale(M_PER_FT)),
                ("in", Conversion::Scale(M_PER_IN)),
            ],
        }
    }

    /// The values its breakpoints may take, in [`Variable::unit`], and where the range comes
    /// from (docs/model.md section 1, "Tables"): a table's breakpoints outside it are refused,
    /// whichever form (inline TOML, CSV, DAVE-ML) gives them.
    pub fn domain(self) -> (f64, f64, &'static str) {
        let position = "a position within +-MAX_POSITION_M of carriage, core/src/limits.rs";
        let mach = "the model's domain, docs/model.md section 1; 0 is a table's edge";
        match self {
            Variable::Mach => (0.0, MAX_MACH, mach),
            Variable::Alpha => (-180.0, 180.0, "alpha = atan2(w, u)"),
            Variable::Beta => (-90.0, 90.0, "beta = asin(v / V)"),
            Variable::Distance => (0.0, MAX_POSITION_M, "|r| >= 0, within MAX_POSITION_M"),
            Variable::Lateral | Variable::X | Variable::Y | Variable::Z => {
                (-MAX_POSITION_M, MAX_POSITION_M, position)
            }
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
    /// A value column in a unit of another quantity of the same file (a flowfield file holds
    /// angles and ratios): read as is, and refused if it is the column chosen.
    Foreign,
}

impl Conversion {
    fn apply(self, x: f64) -> f64 {
        match self {
            Conversion::Scale(s) => x * s,
            Conversion::RadToDeg => x.to_degrees(),
            Conversion::Foreign => x,
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
    /// An angle of the aircraft's flowfield (upwash, sidewash; in degrees): over the point's
    /// launch-frame x, y and z (docs/model.md section 3b).
    FieldAngle,
    /// A ratio or coefficient of the aircraft's flowfield (dynamic pressure ratio, rolling
    /// moment): over x, y and z.
    FieldRatio,
}

impl Kind {
    /// The variables it may span, in nesting order.
    pub fn allowed(self) -> &'static [Variable] {
        match self {
            Kind::Static => &[Variable::Mach, Variable::Alpha, Variable::Beta],
            Kind::Derivative => &[Variable::Mach],
            Kind::Interference => &[Variable::Distance, Variable::Alpha, Variable::Lateral],
            Kind::FieldAngle | Kind::FieldRatio => &[Variable::X, Variable::Y, Variable::Z],
        }
    }

    /// A variable every table of this kind spans.
    pub(super) fn required(self) -> Option<Variable> {
        match self {
            Kind::Interference => Some(Variable::Distance),
            _ => None,
        }
    }

    /// Units a CSV value column may give, and the conversion to the scenario's.
    fn value_units(self) -> &'static [(&'static str, Conversion)] {
        match self {
            Kind::Static | Kind::Interference | Kind::FieldRatio => {
                &[("-", Conversion::Scale(1.0))]
            }
            Kind::Derivative => &[
                ("1/rad", Conversion::Scale(1.0)),
                ("1/deg", Conversion::RadToDeg),
            ],
            Kind::FieldAngle => &[
                ("deg", Conversion::Scale(1.0)),
                ("rad", Conversion::RadToDeg),
            ],
        }
    }

    /// Units of the other value columns a file of this kind may hold beside its own (a
    /// flowfield's file holds its angles and its ratios): such a column is read, and refused
    /// only if it is the one chosen.
    fn sibling_units(self) -> &'static [&'static str] {
        match self {
            Kind::FieldAngle => &["-"],
            Kind::FieldRatio => &["deg", "rad"],
            _ => &[],
        }
    }

    pub(super) fn what(self) -> &'static str {
        match self {
            Kind::Static => "a static coefficient",
            Kind::Derivative => "a derivative",
            Kind::Interference => "an interference increment",
            Kind::FieldAngle => "a flowfield angle",
            Kind::FieldRatio => "a flowfield ratio",
        }
    }

    pub(super) fn allowed_list(self, sep: &str) -> String {
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
    pub fn new(axes: Vec<Axis>, values: Vec<f64>, kind: Kind) -> Result<Table, TableShapeError> {
        check::check_table(&axes, &values, kind)?;
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

    /// The value at `x` (one number per axis, in the axes' units: angles in degrees),
    /// interpolated multilinearly and held at the edges (docs/model.md section 1): the same
    /// function the force evaluation interpolates, to rounding.
    pub fn value_at(&self, x: &[f64]) -> f64 {
        let sizes = self.shape();
        let mut strides = vec![1usize; sizes.len()];
        for k in (0..sizes.len().saturating_sub(1)).rev() {
            strides[k] = strides[k + 1] * sizes[k + 1];
        }
        // Per axis: the lower corner's index and the weight of the upper one.
        let cells: Vec<(usize, f64)> = self
            .axes
            .iter()
            .zip(x)
            .map(|(a, &v)| {
                let b = &a.breakpoints;
                let i = b.partition_point(|&p| p <= v).clamp(1, b.len() - 1) - 1;
                let t = ((v - b[i]) / (b[i + 1] - b[i])).clamp(0.0, 1.0);
                (i, t)
            })
            .collect();
        let mut sum = 0.0;
        for corner in 0..(1usize << cells.len()) {
            let mut w = 1.0;
            let mut at = 0;
            for (k, &(i, t)) in cells.iter().enumerate() {
                let upper = (corner >> k) & 1 == 1;
                w *= if upper { t } else { 1.0 - t };
                at += (i + usize::from(upper)) * strides[k];
            }
            if w != 0.0 {
                sum += w * self.values[at];
            }
        }
        sum
    }

    /// Number of breakpoints of each axis.
    fn shape(&self) -> Vec<usize> {
        self.axes.iter().map(|a| a.breakpoints.len()).collect()
    }
}

/// ` deg`, ` m`, or nothing for Mach: the unit after a number in a message.
pub fn unit_suffix(v: Variable) -> &'static str {
    match v.unit() {
        "-" => "",
        "deg" => " deg",
        _ => " m",
    }
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
/// Marker: an angle of the aircraft's flowfield.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FieldAngleKind;
/// Marker: a ratio of the aircraft's flowfield.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FieldRatioKind;

impl TableKind for StaticKind {
    const KIND: Kind = Kind::Static;
}
impl TableKind for DerivativeKind {
    const KIND: Kind = Kind::Derivative;
}
impl TableKind for InterferenceKind {
    const KIND: Kind = Kind::Interference;
}
impl TableKind for FieldAngleKind {
    const KIND: Kind = Kind::FieldAngle;
}
impl TableKind for FieldRatioKind {
    const KIND: Kind = Kind::FieldRatio;
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
/// An angle of the aircraft's flowfield \[deg\]: a constant (the analytic field's value at
/// carriage) or a table over position.
pub type FieldAngle = Tabulated<FieldAngleKind>;
/// A ratio of the aircraft's flowfield: a constant or a table over position.
pub type FieldRatio = Tabulated<FieldRatioKind>;

impl<K: TableKind> Tabulated<K> {
    /// A constant.
    pub fn constant(v: f64) -> Self {
        Tabulated {
            value: Coefficient::Constant(v),
            kind: PhantomData,
        }
    }

    /// A table, checked for this kind.
    pub fn table(t: Table) -> Result<Self, TableShapeError> {
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
            if f.csv.as_os_str().is_empty() {
                return Err(TableError::Io {
                    file: "csv = \"\"".to_string(),
                    message: "no file named: expected a CSV file's path, relative to the scenario"
                        .to_string(),
                });
            }
            let path = dir.join(&f.csv);
            let table = read_csv(&path, f.column.as_deref(), K::KIND)?;
            self.value = Coefficient::Table(table);
        }
        Ok(())
    }
}

mod check;
mod csv;
mod error;
mod excursion;
mod prepared;
mod serde_form;
pub use check::TableShapeError;
pub use csv::*;
pub use error::*;
pub use excursion::*;
pub use prepared::*;
