//! Corrections of a store's aerodynamic data whose values a search estimates (docs/update.md
//! section 15): piecewise-linear tables added to a scenario field, over one variable, with their
//! breakpoints in the scenario (`[[correction]]`) and their values in each candidate.
//!
//! `sepval update` fits them by output error together with the factors, then writes the store
//! with each correction merged into the field it corrects; a scenario written by it holds no
//! `[[correction]]`. The value of a correction with breakpoints b_0 < ... < b_{n-1} and values
//! v_0, ..., v_{n-1} at x is the linear interpolation of section 1 ("Tables"),
//!
//! ```text
//! c(x) = v_i + t (v_{i+1} - v_i),   t = (x - b_i) / (b_{i+1} - b_i),   x held in [b_0, b_{n-1}]
//! ```
//!
//! (a single breakpoint: the constant v_0), so that a correction merged into a table of the
//! field on the union of the two grids is the same function (Press et al., *Numerical Recipes*,
//! 3rd ed., section 3.6: a sum of piecewise-linear functions is linear on every cell of the
//! union grid). It adds to the field exactly as a table of that field would (section 3,
//! "Tabulated coefficients"):
//!
//! | field | variables | enters as |
//! |---|---|---|
//! | `aero.ca0` | `mach`, `alpha_deg`, `beta_deg` | CX -= c |
//! | `aero.cy` ... `aero.cn` | `mach`, `alpha_deg`, `beta_deg` | CY += c, ... |
//! | `aero.cz_alpha_per_rad` ... `aero.cn_r_per_rad` | `mach` | the derivative += c |
//! | `interference.dcx0` ... `interference.dcn0` | `distance_m` | the increment += c, times its multiplier |
//! | `flowfield.half_depth_m`, `flowfield.reversal_m` | `mach` | 1 / L_z += c, 1 / z_r += c \[1/m\] |
//! | `flowfield.upwash_per_alpha`, `flowfield.sidewash_per_alpha` | `mach` | a_alpha += c, b_alpha += c \[deg/deg\] |
//! | `flowfield.shape` (a shape given as a table) | `z_m` | g(z) += c(z), from depth 0 where c = 0 |
//!
//! The last two rows change the aircraft's flowfield (docs/model.md section 3b). The last
//! changes how its upwash and sidewash grow with the aircraft's angle of attack, what releases
//! at two or more angles of attack measure and one cannot (the thin-wing scaling of section 3b
//! with its slope unknown: the field of a wing is linear in its angle of attack). The one before
//! changes its shape, the
//! depth below carriage at which it has halved and where it changes sign, through their
//! inverses, so that a correction is a smooth change of g(z) = (1 - z / z_r) / (1 + z / L_z)
//! whatever its size (an inverse of 0: no decay, no reversal); a scenario with such a correction
//! must have a `[flowfield]`.
//!
//! A correction of a shape table is folded into the table when a run is set up: the table on
//! the union of the two grids ([`corrected_shape`]), the function the
//! store written with it has.
//!
//! Mach is the flight condition's, fixed for a run, so a correction over Mach is folded into the
//! run's constants when it is set up ([`CorrectionRun::new`] returns them as [`Folded`]); the
//! others are evaluated at every force evaluation at the stage's local alpha, beta and distance
//! from carriage ([`CorrectionRun::evaluate`]). A run without correction values takes none of
//! these paths.

mod error;
mod run;

use serde::{Deserialize, Serialize};

use crate::table::Variable;

pub use error::{CorrectionError, FieldChangeError};
pub use run::{CorrectionRun, CorrectionValues, Folded, ShapeChange};

/// Most correction values one run carries (over all its corrections): a candidate holds them
/// in a fixed array, so that it travels to the workers without allocation.
pub const MAX_CORRECTION_VALUES: usize = 64;

/// Most corrections one scenario holds.
pub const MAX_CORRECTIONS: usize = 16;

/// Most depths of the flowfield's shape as a table (docs/model.md section 3b), with any
/// correction of it: a run carries the table in a fixed array.
pub const MAX_SHAPE_POINTS: usize = 32;

/// The derivatives a correction may change, in the scenario's order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum Derivative {
    CzAlpha,
    CyBeta,
    CmAlpha,
    CnBeta,
    ClP,
    CmQ,
    CnR,
}

impl Derivative {
    /// Every derivative, in the scenario's order.
    pub const ALL: [Derivative; 7] = [
        Derivative::CzAlpha,
        Derivative::CyBeta,
        Derivative::CmAlpha,
        Derivative::CnBeta,
        Derivative::ClP,
        Derivative::CmQ,
        Derivative::CnR,
    ];

    /// Its scenario field's name within `[aero]`.
    pub fn key(self) -> &'static str {
        match self {
            Derivative::CzAlpha => "cz_alpha_per_rad",
            Derivative::CyBeta => "cy_beta_per_rad",
            Derivative::CmAlpha => "cm_alpha_per_rad",
            Derivative::CnBeta => "cn_beta_per_rad",
            Derivative::ClP => "cl_p_per_rad",
            Derivative::CmQ => "cm_q_per_rad",
            Derivative::CnR => "cn_r_per_rad",
        }
    }
}

/// The scenario field a correction adds to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// A static coefficient: 0 CA, 1 CY, 2 CZ, 3 Cl, 4 Cm, 5 Cn.
    Static(usize),
    /// A derivative.
    Derivative(Derivative),
    /// An interference increment: 0 dCX, ..., 5 dCn.
    Interference(usize),
    /// A part of the aircraft's flowfield (docs/model.md section 3b): its shape or its change
    /// with the aircraft's angle of attack.
    Field(FieldPart),
    /// The flowfield's shape given as a table over depth, g(z): the correction adds to it
    /// over depth (`z_m`).
    ShapeTable,
}

/// A part of the flowfield (docs/model.md section 3b) a correction may change: its shape,
/// through the inverses of its depths, or its change with the aircraft's angle of attack.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FieldPart {
    /// The depth at which the field has halved, L_z: the correction adds to 1 / L_z \[1/m\].
    HalfDepth,
    /// The depth at which it changes sign, z_r: the correction adds to 1 / z_r \[1/m\] (0:
    /// none).
    Reversal,
    /// The upwash's change per degree of aircraft angle of attack, a_alpha: the correction adds
    /// to it \[deg/deg\].
    UpwashPerAlpha,
    /// The sidewash's, b_alpha \[deg/deg\].
    SidewashPerAlpha,
}

impl FieldPart {
    /// Every part, in the scenario's order.
    pub const ALL: [FieldPart; 4] = [
        FieldPart::HalfDepth,
        FieldPart::Reversal,
        FieldPart::UpwashPerAlpha,
        FieldPart::SidewashPerAlpha,
    ];
    /// The parts of the field's shape over depth.
    pub const SHAPE: [FieldPart; 2] = [FieldPart::HalfDepth, FieldPart::Reversal];
    /// The parts of its change with the aircraft's angle of attack.
    pub const PER_ALPHA: [FieldPart; 2] = [FieldPart::UpwashPerAlpha, FieldPart::SidewashPerAlpha];

    /// Its scenario field's name within `[flowfield]`.
    pub fn key(self) -> &'static str {
        match self {
            FieldPart::HalfDepth => "half_depth_m",
            FieldPart::Reversal => "reversal_m",
            FieldPart::UpwashPerAlpha => "upwash_per_alpha",
            FieldPart::SidewashPerAlpha => "sidewash_per_alpha",
        }
    }

    /// Whether it is a part of the shape over depth (the others: the change with alpha).
    pub fn is_shape(self) -> bool {
        matches!(self, FieldPart::HalfDepth | FieldPart::Reversal)
    }
}

/// Names of the static coefficients' fields within `[aero]`, CA first.
const STATIC_KEYS: [&str; 6] = ["ca0", "cy", "cz", "cl", "cm", "cn"];
/// Names of the interference increments' fields within `[interference]`.
const INTERFERENCE_KEYS: [&str; 6] = ["dcx0", "dcy0", "dcz0", "dcl0", "dcm0", "dcn0"];

impl Target {
    /// Every target of the store's aerodynamic data (its tables), in the order of the
    /// scenario's fields.
    pub fn all() -> Vec<Target> {
        (0..6)
            .map(Target::Static)
            .chain(Derivative::ALL.into_iter().map(Target::Derivative))
            .chain((0..6).map(Target::Interference))
            .collect()
    }

    /// Every target, the flowfield's parts after the aerodynamic data.
    pub fn every() -> Vec<Target> {
        let mut out = Target::all();
        out.extend(FieldPart::ALL.map(Target::Field));
        out.push(Target::ShapeTable);
        out
    }

    /// The field's TOML path, e.g. `aero.cm` or `interference.dcz0`.
    pub fn field(self) -> String {
        match self {
            Target::Static(k) => format!("aero.{}", STATIC_KEYS[k]),
            Target::Derivative(d) => format!("aero.{}", d.key()),
            Target::Interference(k) => format!("interference.{}", INTERFERENCE_KEYS[k]),
            Target::Field(f) => format!("flowfield.{}", f.key()),
            Target::ShapeTable => "flowfield.shape".to_string(),
        }
    }

    /// The target of a field of the store's tables (not the flowfield's shape), by its TOML
    /// path.
    pub fn table_of_field(field: &str) -> Option<Target> {
        Target::all().into_iter().find(|t| t.field() == field)
    }

    /// The target of a field's TOML path.
    pub fn of_field(field: &str) -> Option<Target> {
        Target::every().into_iter().find(|t| t.field() == field)
    }

    /// The variables a correction of this field may span.
    pub fn variables(self) -> &'static [Variable] {
        match self {
            Target::Static(_) => &[Variable::Mach, Variable::Alpha, Variable::Beta],
            Target::Derivative(_) => &[Variable::Mach],
            Target::Interference(_) => &[Variable::Distance],
            Target::Field(_) => &[Variable::Mach],
            Target::ShapeTable => &[Variable::Z],
        }
    }

    /// The coefficient axis it acts on: 0 CA (or dCX), ..., 5 Cn; for a derivative, the axis of
    /// its coefficient (CZ for CZ_alpha, ...); for the flowfield's shape, which acts on every
    /// axis, CZ's (that of its upwash, the field's largest part); for the upwash's and the
    /// sidewash's change with alpha, CZ's and CY's.
    pub fn axis(self) -> usize {
        match self {
            Target::Static(k) | Target::Interference(k) => k,
            Target::Field(FieldPart::SidewashPerAlpha) => 1,
            Target::Field(_) | Target::ShapeTable => 2,
            Target::Derivative(d) => match d {
                Derivative::CzAlpha => 2,
                Derivative::CyBeta => 1,
                Derivative::CmAlpha | Derivative::CmQ => 4,
                Derivative::CnBeta | Derivative::CnR => 5,
                Derivative::ClP => 3,
            },
        }
    }
}

/// A correction as a scenario file writes it: `[[correction]]` with `field`, `variable` and
/// `breakpoints` (in the variable's unit: `mach` -, `alpha_deg` and `beta_deg` deg,
/// `distance_m` m).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CorrectionRecord {
    /// The field corrected, as a TOML path (`aero.cm`, `aero.cm_alpha_per_rad`,
    /// `interference.dcz0`, ...).
    pub field: String,
    /// The variable: `mach`, `alpha_deg`, `beta_deg` or `distance_m`.
    pub variable: String,
    /// Its breakpoints, strictly increasing (one: a constant correction).
    pub breakpoints: Vec<f64>,
}

/// A checked correction.
#[derive(Debug, Clone, PartialEq)]
pub struct Correction {
    /// The field it adds to.
    pub target: Target,
    /// Its variable.
    pub variable: Variable,
    /// Its breakpoints, strictly increasing, in the variable's unit.
    pub breakpoints: Vec<f64>,
}

impl CorrectionRecord {
    /// The record of `c`.
    pub fn of(c: &Correction) -> CorrectionRecord {
        CorrectionRecord {
            field: c.target.field(),
            variable: c.variable.key().to_string(),
            breakpoints: c.breakpoints.clone(),
        }
    }

    /// The correction it describes, checked.
    pub fn correction(&self) -> Result<Correction, CorrectionError> {
        let target = Target::of_field(&self.field).ok_or_else(|| CorrectionError::Field {
            field: self.field.clone(),
        })?;
        let allowed = target.variables();
        let variable = allowed
            .iter()
            .copied()
            .find(|v| v.key() == self.variable)
            .ok_or_else(|| CorrectionError::Variable {
                field: self.field.clone(),
                variable: self.variable.clone(),
                allowed: allowed
                    .iter()
                    .map(|v| v.key())
                    .collect::<Vec<_>>()
                    .join(", "),
            })?;
        let b = &self.breakpoints;
        if b.is_empty() {
            return Err(CorrectionError::NoBreakpoints);
        }
        if let Some(x) = b.iter().find(|x| !x.is_finite()) {
            return Err(CorrectionError::BreakpointNotFinite { value: *x });
        }
        if let Some(k) = (1..b.len()).find(|&k| b[k] <= b[k - 1]) {
            return Err(CorrectionError::BreakpointsNotIncreasing {
                before: b[k - 1],
                after: b[k],
            });
        }
        if b.len() > MAX_CORRECTION_VALUES {
            return Err(CorrectionError::TooManyBreakpoints { count: b.len() });
        }
        Ok(Correction {
            target,
            variable,
            breakpoints: b.clone(),
        })
    }
}

/// Checks a scenario's corrections together: each on its own, at most [`MAX_CORRECTIONS`] of
/// them and [`MAX_CORRECTION_VALUES`] values in all; returns them with the index of the first
/// that is wrong on error.
pub fn check_all(
    records: &[CorrectionRecord],
) -> Result<Vec<Correction>, (usize, CorrectionError)> {
    if records.len() > MAX_CORRECTIONS {
        return Err((
            MAX_CORRECTIONS,
            CorrectionError::TooManyCorrections {
                count: records.len(),
            },
        ));
    }
    let mut out = Vec::with_capacity(records.len());
    let mut values = 0;
    for (k, r) in records.iter().enumerate() {
        let c = r.correction().map_err(|e| (k, e))?;
        values += c.breakpoints.len();
        if values > MAX_CORRECTION_VALUES {
            return Err((k, CorrectionError::TooManyValuesUpTo { count: values }));
        }
        out.push(c);
    }
    Ok(out)
}

/// The shape table (`depth_m`, `g`) with the correction c(z) (`knots_m`, `change`: section 1's
/// interpolation, held at the ends) added: the table on the union of the two grids, where the
/// sum of the two piecewise-linear functions is linear on every cell, so that it is the same
/// function (W. H. Press et al., *Numerical Recipes*, 3rd ed., 2007, section 3.6). The
/// correction must keep g(0) = 1 and the union at most [`MAX_SHAPE_POINTS`] depths; `sepval
/// update`'s correction `flowfield.shape` over `z_m` (docs/update.md section 15.3a), folded
/// into a run's shape and merged into the store written by this one function.
pub fn corrected_shape(
    depth_m: &[f64],
    g: &[f64],
    knots_m: &[f64],
    change: &[f64],
) -> Result<(Vec<f64>, Vec<f64>), FieldChangeError> {
    let mut union: Vec<f64> = depth_m.iter().chain(knots_m).copied().collect();
    union.sort_by(f64::total_cmp);
    union.dedup();
    if union.len() > MAX_SHAPE_POINTS {
        return Err(FieldChangeError::ShapeDepths {
            depths: union.len(),
        });
    }
    let sum: Vec<f64> = union
        .iter()
        .map(|&z| interpolate(depth_m, g, z) + interpolate(knots_m, change, z))
        .collect();
    // Exactly 1, as the scenario's check of a table (its g at carriage).
    #[allow(clippy::float_cmp)]
    let at_carriage_is_one = sum[0] == 1.0;
    if union.first() != Some(&0.0) || !at_carriage_is_one {
        return Err(FieldChangeError::ShapeAtCarriage { value: sum[0] });
    }
    Ok((union, sum))
}

/// The value at `x` of the piecewise-linear function through (`b_i`, `v_i`), held at the ends
/// (the interpolation of section 1, "Tables"; one breakpoint: `v_0`).
#[inline(always)]
pub fn interpolate(b: &[f64], v: &[f64], x: f64) -> f64 {
    let n = b.len();
    if n == 1 || x <= b[0] {
        return v[0];
    }
    if x >= b[n - 1] {
        return v[n - 1];
    }
    // Few breakpoints (a correction has a handful): a linear scan.
    let mut i = 0;
    while x > b[i + 1] {
        i += 1;
    }
    let t = (x - b[i]) / (b[i + 1] - b[i]);
    t.mul_add(v[i + 1] - v[i], v[i])
}

/// The weights of each breakpoint's value at `x`: `interpolate(b, v, x)` is their dot product
/// with `v` (to rounding); for reports and the linear algebra of an update.
pub fn weights(b: &[f64], x: f64) -> Vec<f64> {
    let n = b.len();
    let mut w = vec![0.0; n];
    if n == 1 || x <= b[0] {
        w[0] = 1.0;
        return w;
    }
    if x >= b[n - 1] {
        w[n - 1] = 1.0;
        return w;
    }
    let mut i = 0;
    while x > b[i + 1] {
        i += 1;
    }
    let t = (x - b[i]) / (b[i + 1] - b[i]);
    w[i] = 1.0 - t;
    w[i + 1] = t;
    w
}
