//! The estimate as a starting point wherever a store's data are asked for (issue 61 item 2;
//! docs/aero.md, "The estimate as a starting point"): a scenario whose `[aero]` is the
//! estimate ([`scenario`], `sepval scenario --from-shape`; `sepval update --scenario` starts
//! from such a scenario as from any other), and the estimate's static coefficients with their
//! bands at flight conditions ([`static_at`], [`static_sigma`]), which `sepval campaign init
//! --prior-from-shape` maps onto the factors' offsets with the mapping of `--prior-daveml`
//! (`sepval_campaign::prior_shape`).
//!
//! The estimate is made on the default grids of `sepval aero` ([`grid::DEFAULT_MACH`],
//! [`grid::DEFAULT_ALPHA_DEG`]) at the altitude of the scenario it goes into (the altitude only
//! sets the Reynolds number of the skin friction), so the same shape and base scenario give the
//! same tables bit for bit: a campaign begun from a scenario made by `--from-shape` maps the
//! estimate onto the very tables it flies.
//!
//! A static coefficient at a point (M, alpha, beta) is what docs/model.md section 3 adds up
//! before the factors, angles in radians in the products:
//!
//!     CA = CA0(M, ...)                 CY = CY_beta(M) beta + CY(...)
//!     CZ = CZ_alpha(M) alpha + CZ(...)  Cl = Cl(...)
//!     Cm = Cm_alpha(M) alpha + Cm(...)  Cn = Cn_beta(M) beta + Cn(...)
//!
//! Its band, from the derivative's band s_D and the static table's s_T, independent, is
//! s = sqrt((s_D angle)^2 + s_T^2): the crossflow's band is the crossflow method's,
//! independent of the linear methods' (docs/aero.md "The stated uncertainty of each").

use std::path::Path;

use sepval_common::correction::{Derivative, Target};
use sepval_common::scenario::{Aero, Scenario};
use sepval_common::table::{Coefficient, Kind, Table, Variable};
use sepval_daveml::Band;
use sepval_geometry::StoreShape;

use crate::{AeroError, Estimate, Request, grid, tables};

/// An estimate with its `[aero]` tables and their bands (one standard deviation per value).
#[derive(Debug, Clone)]
pub struct Start {
    /// The estimate.
    pub estimate: Estimate,
    /// The scenario's `[aero]` of it.
    pub aero: Aero,
    /// The band of each of its tables.
    pub bands: Vec<Band>,
}

/// The estimate of `shape` on `sepval aero`'s default grids at `altitude_m`.
pub fn of_shape(shape: StoreShape, altitude_m: f64) -> Result<Start, AeroError> {
    let request = Request {
        shape,
        mach: grid::parse("--mach", grid::DEFAULT_MACH, grid::MACH_DOMAIN)?,
        alpha_deg: grid::parse(
            "--alpha-deg",
            grid::DEFAULT_ALPHA_DEG,
            grid::ALPHA_DOMAIN_DEG,
        )?,
        altitude_m,
    };
    let estimate = crate::estimate(&request)?;
    let (aero, bands) = tables::aero(&estimate)?;
    Ok(Start {
        estimate,
        aero,
        bands,
    })
}

/// The store TOML at `path` read (`sepval-geometry`'s checks) and estimated at `altitude_m`.
pub fn read(path: &Path, altitude_m: f64) -> Result<Start, AeroError> {
    of_shape(StoreShape::read(path)?, altitude_m)
}

/// `base` with its `[aero]` replaced by the estimate and its reference diameter the shape's
/// (the coefficients are per the body's diameter); everything else, the mass properties and
/// the ejector's feet included, is the base's (docs/aero.md: the shape gives no mass).
pub fn scenario(base: &Scenario, start: &Start) -> Scenario {
    let mut s = base.clone();
    s.store.diameter_m = start.estimate.config.diameter_m;
    s.aero = start.aero.clone();
    s.description = format!(
        "{}; [aero] estimated from the shape {} (sepval scenario --from-shape, docs/aero.md)",
        base.description.trim_end_matches('.'),
        start.estimate.config.source
    );
    s
}

/// The scenario of `sepval scenario --from-shape`: the shape at `path` estimated at `base`'s
/// altitude and put into `base` ([`scenario`]), checked valid and checked to read back from
/// its TOML as made.
pub fn scenario_from_shape(path: &Path, base: &Scenario) -> Result<Scenario, AeroError> {
    let start = read(path, base.flight.altitude_m)?;
    let s = scenario(base, &start);
    let refuse = |what: String| AeroError::Table {
        field: "aero".into(),
        what,
    };
    let back = Scenario::from_toml_str(&s.to_toml_string(), "the scenario from the shape")
        .map_err(|e| refuse(format!("does not read back: {e}")))?;
    if back != s {
        return Err(refuse(
            "the scenario reads back different from what was made".into(),
        ));
    }
    Ok(s)
}

/// The value of coefficient `c` at (M, alpha, beta) (angles in degrees); a table over other
/// variables, or a table file not read, has none.
fn coefficient_at(c: &Coefficient, point: [f64; 3]) -> Option<f64> {
    match c {
        Coefficient::Constant(v) => Some(*v),
        Coefficient::Table(t) => {
            let x: Option<Vec<f64>> = t
                .axes()
                .iter()
                .map(|a| match a.variable {
                    Variable::Mach => Some(point[0]),
                    Variable::Alpha => Some(point[1]),
                    Variable::Beta => Some(point[2]),
                    _ => None,
                })
                .collect();
            Some(t.value_at(&x?))
        }
        Coefficient::File(_) => None,
    }
}

/// The derivative of the linear term of static coefficient `k` (0 CA, 1 CY, 2 CZ, 3 Cl, 4 Cm,
/// 5 Cn) and the index of its angle in a point (1 alpha, 2 beta).
fn linear_term(k: usize) -> Option<(Derivative, usize)> {
    match k {
        1 => Some((Derivative::CyBeta, 2)),
        2 => Some((Derivative::CzAlpha, 1)),
        4 => Some((Derivative::CmAlpha, 1)),
        5 => Some((Derivative::CnBeta, 2)),
        _ => None,
    }
}

/// Static coefficient `k` (0 CA, 1 CY, 2 CZ, 3 Cl, 4 Cm, 5 Cn) of `aero` at `point` = (Mach,
/// alpha \[deg\], beta \[deg\]): the linear term and the static table (module docs). `None`
/// when a table is over another variable or not read.
pub fn static_at(aero: &Aero, k: usize, point: [f64; 3]) -> Option<f64> {
    let field = |t: Target| match t {
        Target::Static(0) => Some(&aero.ca0.value),
        Target::Static(j) => [&aero.cy, &aero.cz, &aero.cl, &aero.cm, &aero.cn]
            .get(j - 1)?
            .as_ref()
            .map(|c| &c.value),
        Target::Derivative(d) => match d {
            Derivative::CzAlpha => aero.cz_alpha_per_rad.as_ref().map(|c| &c.value),
            Derivative::CyBeta => aero.cy_beta_per_rad.as_ref().map(|c| &c.value),
            Derivative::CmAlpha => aero.cm_alpha_per_rad.as_ref().map(|c| &c.value),
            Derivative::CnBeta => aero.cn_beta_per_rad.as_ref().map(|c| &c.value),
            _ => None,
        },
        _ => None,
    };
    let table = match field(Target::Static(k)) {
        Some(c) => coefficient_at(c, point)?,
        None => 0.0,
    };
    let linear = match linear_term(k) {
        Some((d, angle)) => match field(Target::Derivative(d)) {
            Some(c) => coefficient_at(c, point)? * point[angle].to_radians(),
            None => 0.0,
        },
        None => 0.0,
    };
    Some(linear + table)
}

/// The band of `target` in `start` at `point`: its sigmas interpolated as its table's values
/// are (0 when the target has no band).
fn band_at(start: &Start, target: Target, point: [f64; 3]) -> f64 {
    let Some(band) = start.bands.iter().find(|b| b.target == target) else {
        return 0.0;
    };
    let table = match target {
        Target::Static(0) => start.aero.ca0.as_table(),
        Target::Static(j) => [
            &start.aero.cy,
            &start.aero.cz,
            &start.aero.cl,
            &start.aero.cm,
            &start.aero.cn,
        ][j - 1]
            .as_ref()
            .and_then(|c| c.as_table()),
        Target::Derivative(d) => {
            let a = &start.aero;
            match d {
                Derivative::CzAlpha => a.cz_alpha_per_rad.as_ref().and_then(|c| c.as_table()),
                Derivative::CyBeta => a.cy_beta_per_rad.as_ref().and_then(|c| c.as_table()),
                Derivative::CmAlpha => a.cm_alpha_per_rad.as_ref().and_then(|c| c.as_table()),
                Derivative::CnBeta => a.cn_beta_per_rad.as_ref().and_then(|c| c.as_table()),
                _ => None,
            }
        }
        _ => None,
    };
    let Some(table) = table else {
        return band.sigma.first().copied().unwrap_or(0.0);
    };
    Table::new(table.axes().to_vec(), band.sigma.clone(), Kind::Static)
        .ok()
        .and_then(|t| coefficient_at(&Coefficient::Table(t), point))
        .unwrap_or(0.0)
}

/// The estimate's band (one standard deviation) of static coefficient `k` at `point` (module
/// docs: the derivative's band times the angle and the static table's, in quadrature).
pub fn static_sigma(start: &Start, k: usize, point: [f64; 3]) -> f64 {
    let table = band_at(start, Target::Static(k), point);
    let linear = match linear_term(k) {
        Some((d, angle)) => {
            band_at(start, Target::Derivative(d), point) * point[angle].to_radians()
        }
        None => 0.0,
    };
    linear.hypot(table)
}
