//! The `[flowfield]` table of a scenario: the aircraft's flowfield interference model
//! (docs/model.md section 3b) and the checks of its values. The field itself, its stations and
//! its loads are in [`crate::model::flowfield`].

use serde::{Deserialize, Serialize};

use std::path::Path;

use super::{Aero, Interference};
use crate::table::{Coefficient, FieldAngle, FieldRatio, Table, TableError};
use sepval_core::number_text::Shown;

/// The most stations along the store (docs/model.md section 3b).
pub const MAX_STATIONS: usize = 16;

pub use crate::correction::MAX_SHAPE_POINTS;

/// The shortest and longest store the field's stations are spread along, nose to tail \[m\]
/// (sepval's choice: a millimetre to a kilometre).
pub const MIN_STORE_LENGTH_M: f64 = 1e-3;
/// See [`MIN_STORE_LENGTH_M`].
pub const MAX_STORE_LENGTH_M: f64 = 1e3;
/// The least difference between a field of tables' reference angle of attack and its
/// zero-lift angle \[deg\] (sepval's choice).
pub const MIN_LIFT_ALPHA_DEG: f64 = 0.5;

/// The field's shape g(z) given as a table over the depth below carriage (docs/model.md
/// section 3b, "The shape as a table"), in place of `half_depth_m` and `reversal_m`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeTable {
    /// Depths z below carriage \[m\]: the first 0, then increasing.
    pub depth_m: Vec<f64>,
    /// g at each depth: 1 at carriage; held at the last value below the last depth.
    pub g: Vec<f64>,
}

impl ShapeTable {
    fn check(&self) -> Result<(), Refusal> {
        let n = self.depth_m.len();
        if !(2..=MAX_SHAPE_POINTS).contains(&n) {
            return Err(refuse(
                "shape.depth_m",
                format!("has {n} depths: expected 2 to {MAX_SHAPE_POINTS}"),
            ));
        }
        if self.g.len() != n {
            return Err(refuse(
                "shape.g",
                format!(
                    "has {} values for {n} depths: expected one per depth",
                    self.g.len()
                ),
            ));
        }
        if self.depth_m[0] != 0.0 {
            return Err(refuse(
                "shape.depth_m",
                format!(
                    "starts at {}: expected 0, the carriage position",
                    self.depth_m[0]
                ),
            ));
        }
        for k in 1..n {
            let (a, b) = (self.depth_m[k - 1], self.depth_m[k]);
            if !(b.is_finite() && b > a) {
                return Err(refuse(
                    "shape.depth_m",
                    format!("[{k}] = {b}: expected finite and above the depth before it ({a})"),
                ));
            }
        }
        if let Some(k) = self.g.iter().position(|v| !v.is_finite()) {
            return Err(refuse(
                "shape.g",
                format!("[{k}] = {}: expected a finite value", self.g[k]),
            ));
        }
        // Exactly 1: the field's values are those at carriage, not rescaled by the table.
        #[allow(clippy::float_cmp)]
        let at_carriage_is_one = self.g[0] == 1.0;
        if !at_carriage_is_one {
            return Err(refuse(
                "shape.g",
                format!(
                    "[0] = {}: expected 1 (the field's values are those at carriage)",
                    self.g[0]
                ),
            ));
        }
        Ok(())
    }
}

/// How the field's strength scales with the flight Mach number (docs/model.md section 3b).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum MachScaling {
    /// Pg(M) = 1 / sqrt(max(|1 - M^2|, 0.1)).
    #[default]
    PrandtlGlauert,
    /// Pg(M) = 1: the field does not change with Mach.
    None,
}

fn default_stations() -> usize {
    5
}

fn zero_angle() -> FieldAngle {
    FieldAngle::constant(0.0)
}

fn zero_ratio() -> FieldRatio {
    FieldRatio::constant(0.0)
}

fn one_ratio() -> FieldRatio {
    FieldRatio::constant(1.0)
}

/// The flowfield of docs/model.md section 3b, as the scenario file gives it (angles in
/// degrees): analytic (its values at carriage, a shape over depth) or tables over position.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlowfieldSpec {
    /// Number N of stations along the store (2 to [`MAX_STATIONS`]).
    #[serde(default = "default_stations")]
    pub stations: usize,
    /// Body x of the store's nose from the CG (the moment reference point) \[m\].
    pub nose_x_m: f64,
    /// Body x of the store's tail from the CG \[m\].
    pub tail_x_m: f64,
    /// a0: induced angle of attack at carriage at the reference condition \[deg\]; or the
    /// upwash as a table over position (x, y, z of L from the CG's carriage position).
    pub upwash_deg: FieldAngle,
    /// a_alpha: its change per degree of aircraft angle of attack \[deg/deg\].
    #[serde(default)]
    pub upwash_per_alpha: f64,
    /// a_x: its change per metre along L's x \[deg/m\].
    #[serde(default)]
    pub upwash_gradient_deg_per_m: f64,
    /// b0: induced sideslip at carriage \[deg\]; or a table over position.
    #[serde(default = "zero_angle")]
    pub sidewash_deg: FieldAngle,
    /// b_alpha: its change per degree of aircraft angle of attack \[deg/deg\].
    #[serde(default)]
    pub sidewash_per_alpha: f64,
    /// b_x: its change per metre along L's x \[deg/m\].
    #[serde(default)]
    pub sidewash_gradient_deg_per_m: f64,
    /// eta0: local over free-stream dynamic pressure at carriage; or a table over position.
    #[serde(default = "one_ratio")]
    pub dynamic_pressure_ratio: FieldRatio,
    /// l0: rolling-moment coefficient the field induces at carriage; or a table over the CG's
    /// position.
    #[serde(default = "zero_ratio")]
    pub roll_cl: FieldRatio,
    /// L_z: the depth below carriage at which the field has halved \[m\] (none: the shape
    /// is a table, [`FlowfieldSpec::shape`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_depth_m: Option<f64>,
    /// z_r: depth below carriage where the field changes sign \[m\] (none: it never does).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reversal_m: Option<f64>,
    /// M_ref: the Mach number at which a0, b0, eta0 and l0 hold.
    pub reference_mach: f64,
    /// alpha_ref: the aircraft angle of attack at which they hold \[deg\].
    #[serde(default)]
    pub reference_alpha_deg: f64,
    /// How the field scales with Mach.
    #[serde(default)]
    pub mach_scaling: MachScaling,
    /// The shape g(z) as a table over depth, in place of `half_depth_m` and `reversal_m`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<ShapeTable>,
    /// alpha_0: the aircraft's zero-lift angle of attack \[deg\], by which a field given as
    /// tables scales with the aircraft's angle of attack (none: it does not).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zero_lift_alpha_deg: Option<f64>,
}

/// The fields of `[flowfield]` that may be tables over position, in the order of
/// [`FlowfieldSpec::position_tables`].
pub const POSITION_FIELDS: [&str; 4] = [
    "upwash_deg",
    "sidewash_deg",
    "dynamic_pressure_ratio",
    "roll_cl",
];

mod grid;

/// A field of `[flowfield]` (its TOML path) and why its value is refused.
pub(super) type Refusal = (String, String);

fn refuse(field: &str, reason: String) -> Refusal {
    (format!("flowfield.{field}"), reason)
}

/// `v` of `field`, which must be finite.
fn finite(field: &str, v: f64) -> Result<(), Refusal> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(refuse(
            field,
            format!("= {}: expected a finite value", Shown(v)),
        ))
    }
}

/// `v` of `field`, which must be finite and above 0.
fn positive(field: &str, v: f64) -> Result<(), Refusal> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(refuse(
            field,
            format!("= {}: expected a finite value > 0", Shown(v)),
        ))
    }
}

impl FlowfieldSpec {
    /// Checks the values for their range, and the rest of the scenario for what the field
    /// needs (docs/model.md section 3b): the six decay increments 0, the store's slopes
    /// CZ_alpha and CY_beta given and non-zero.
    pub(super) fn check(&self, aero: &Aero, interference: &Interference) -> Result<(), Refusal> {
        if !(2..=MAX_STATIONS).contains(&self.stations) {
            return Err(refuse(
                "stations",
                format!("= {}: expected 2 to {MAX_STATIONS}", self.stations),
            ));
        }
        self.check_values()?;
        for (field, c) in interference.increments() {
            if !matches!(c.value, Coefficient::Constant(v) if v == 0.0) {
                return Err((
                    field.to_string(),
                    "must be the constant 0 in a scenario with a [flowfield]: the field replaces \
                     the distance-decay increments (leave out [flowfield] to use them)"
                        .to_string(),
                ));
            }
        }
        for (field, slope) in [
            ("aero.cz_alpha_per_rad", aero.cz_alpha_per_rad.as_ref()),
            ("aero.cy_beta_per_rad", aero.cy_beta_per_rad.as_ref()),
        ] {
            let nonzero = match slope.map(|s| &s.value) {
                Some(Coefficient::Constant(v)) => *v != 0.0,
                // A Mach table whose values share a sign is non-zero wherever it is read.
                Some(Coefficient::Table(t)) => {
                    t.values().iter().all(|v| *v > 0.0) || t.values().iter().all(|v| *v < 0.0)
                }
                _ => false,
            };
            if !nonzero {
                return Err((
                    field.to_string(),
                    "must be given and non-zero (a Mach table of one sign) in a scenario with a \
                     [flowfield]: the field acts on the store through its slopes"
                        .to_string(),
                ));
            }
        }
        Ok(())
    }

    fn check_values(&self) -> Result<(), Refusal> {
        finite("nose_x_m", self.nose_x_m)?;
        finite("tail_x_m", self.tail_x_m)?;
        if self.nose_x_m <= self.tail_x_m {
            return Err(refuse(
                "nose_x_m",
                format!(
                    "= {}: expected the nose ahead of the tail (tail_x_m = {})",
                    self.nose_x_m, self.tail_x_m
                ),
            ));
        }
        // The stations' spread sum (x_k - x_bar)^2 divides their weights (docs/model.md
        // section 3b): a store 1e-300 m long made it 0 and the weights NaN, one 1e155 m long
        // infinite.
        let length_m = self.nose_x_m - self.tail_x_m;
        if !(MIN_STORE_LENGTH_M..=MAX_STORE_LENGTH_M).contains(&length_m) {
            return Err(refuse(
                "nose_x_m",
                format!(
                    "- tail_x_m = {} m: expected a store from {MIN_STORE_LENGTH_M} to \
                     {MAX_STORE_LENGTH_M} m long",
                    Shown(length_m)
                ),
            ));
        }
        finite("upwash_per_alpha", self.upwash_per_alpha)?;
        finite("upwash_gradient_deg_per_m", self.upwash_gradient_deg_per_m)?;
        finite("sidewash_per_alpha", self.sidewash_per_alpha)?;
        finite(
            "sidewash_gradient_deg_per_m",
            self.sidewash_gradient_deg_per_m,
        )?;
        finite("reference_alpha_deg", self.reference_alpha_deg)?;
        positive("reference_mach", self.reference_mach)?;
        if self.is_grid() {
            return self.check_grid();
        }
        let [a0, b0, eta0, l0] = self.carriage_values();
        for (field, v) in [("upwash_deg", a0), ("sidewash_deg", b0)] {
            if !(v.is_finite() && v.abs() < 45.0) {
                return Err(refuse(
                    field,
                    format!("= {}: expected a finite angle within +-45 deg", Shown(v)),
                ));
            }
        }
        finite("roll_cl", l0)?;
        positive("dynamic_pressure_ratio", eta0)?;
        if let Some(a) = self.zero_lift_alpha_deg {
            return Err(refuse(
                "zero_lift_alpha_deg",
                format!(
                    "= {a} is given for an analytic field: it scales a field given as tables over \
                     position (the analytic field's change with alpha is upwash_per_alpha)"
                ),
            ));
        }
        self.check_shape()
    }

    /// Whether the field is given as tables over position (any of [`POSITION_FIELDS`] a
    /// table).
    pub fn is_grid(&self) -> bool {
        self.position_tables().iter().any(Option::is_some)
    }

    /// Whether the field's shape is tabulated (a table over depth, or the field as tables over
    /// position): it has no half depth or reversal depth for `update` to correct.
    pub fn shape_is_tabulated(&self) -> bool {
        self.shape.is_some() || self.is_grid()
    }

    /// The tables over position of [`POSITION_FIELDS`], where given.
    pub fn position_tables(&self) -> [Option<&Table>; 4] {
        [
            self.upwash_deg.as_table(),
            self.sidewash_deg.as_table(),
            self.dynamic_pressure_ratio.as_table(),
            self.roll_cl.as_table(),
        ]
    }

    /// The analytic field's values at carriage (a0 \[deg\], b0 \[deg\], eta0, l0); for a field
    /// of tables, their neutral values (0, 0, 1, 0) where a field is not a constant.
    pub fn carriage_values(&self) -> [f64; 4] {
        [
            self.upwash_deg.as_constant().unwrap_or(0.0),
            self.sidewash_deg.as_constant().unwrap_or(0.0),
            self.dynamic_pressure_ratio.as_constant().unwrap_or(1.0),
            self.roll_cl.as_constant().unwrap_or(0.0),
        ]
    }

    /// Reads the tables over position given as files (relative to `dir`) into inline tables,
    /// naming the field of an error (its TOML path).
    pub(super) fn resolve_tables(&mut self, dir: &Path) -> Result<(), (String, TableError)> {
        let at = |field: &'static str| move |e| (format!("flowfield.{field}"), e);
        self.upwash_deg
            .resolve(dir)
            .map_err(at(POSITION_FIELDS[0]))?;
        self.sidewash_deg
            .resolve(dir)
            .map_err(at(POSITION_FIELDS[1]))?;
        self.dynamic_pressure_ratio
            .resolve(dir)
            .map_err(at(POSITION_FIELDS[2]))?;
        self.roll_cl.resolve(dir).map_err(at(POSITION_FIELDS[3]))
    }

    /// The shape: analytic (`half_depth_m`, and `reversal_m` if any) or a table, not both.
    fn check_shape(&self) -> Result<(), Refusal> {
        match (&self.shape, self.half_depth_m) {
            (None, Some(l_z)) => {
                positive("half_depth_m", l_z)?;
                self.reversal_m
                    .map_or(Ok(()), |z_r| positive("reversal_m", z_r))
            }
            (None, None) => Err(refuse(
                "half_depth_m",
                "is missing: give the depth at which the field halves, or its shape as a table \
                 (shape = { depth_m = [...], g = [...] })"
                    .to_string(),
            )),
            (Some(_), Some(_)) => Err(refuse(
                "shape",
                "and half_depth_m are both given: the shape is a table or the analytic \
                 (1 - z / z_r) / (1 + z / L_z), not both"
                    .to_string(),
            )),
            (Some(t), None) => {
                if self.reversal_m.is_some() {
                    return Err(refuse(
                        "reversal_m",
                        "is given with a shape table: where the field changes sign is the \
                         table's (a value below 0)"
                            .to_string(),
                    ));
                }
                t.check()
            }
        }
    }
}
