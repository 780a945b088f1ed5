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
//!
//! The scenario's factor table is the base's, except the five static offsets the estimate's
//! bands feed ([`OFFSETS`]): each offset's range is widened, where the base's is narrower, to
//! [`RANGE_SIGMAS`] times the root-mean-square band of its coefficient at the scenario's flight
//! condition and [`EXCURSION_DEG`] either side of its angles ([`offset_ranges`]), with its step
//! no coarser than the base's. The offsets are what a fit moves to make up an estimate's
//! error; a range narrower than the estimate's own uncertainty would refuse a store the
//! estimate allows (docs/aero.md, "The estimate as a starting point").

use std::path::Path;

use sepval_common::correction::{Derivative, Target};
use sepval_common::scenario::Flight;
use sepval_common::scenario::{Aero, Scenario};
use sepval_common::table::{Coefficient, Kind, Table, Variable};
use sepval_core::factors::{Factor, FactorSpec, FactorTable};
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

/// How far the store's own flow angles are read either side of the aircraft's \[deg\]: the
/// store pitches and yaws away from the aircraft's angles as it separates (docs/campaign.md
/// gives the measurement behind the number). The campaign's prior from a shape reads the
/// estimate at the same points.
pub const EXCURSION_DEG: f64 = 5.0;

/// How many of the estimate's standard deviations an offset's range reaches either side of 0
/// (our choice: 3, the range then holds 99.7 % of a normal belief centred on the estimate).
pub const RANGE_SIGMAS: f64 = 3.0;

/// The static coefficients the estimate gives a band (0 CA, 1 CY, 2 CZ, 4 Cm, 5 Cn) and the
/// offset that adds to each (docs/model.md sections 3 and 4).
pub const OFFSETS: [(usize, Factor); 5] = [
    (0, Factor::Caoff),
    (1, Factor::Cyoff),
    (2, Factor::Czoff),
    (4, Factor::Cmoff),
    (5, Factor::Cnoff),
];

/// The points a flight condition's coefficients are read at, as (Mach, alpha \[deg\], beta
/// \[deg\]): the aircraft's angles and [`EXCURSION_DEG`] either side of both.
pub fn points_about(flight: &Flight) -> [[f64; 3]; 3] {
    [-EXCURSION_DEG, 0.0, EXCURSION_DEG]
        .map(|d| [flight.mach, flight.alpha_deg + d, flight.beta_deg + d])
}

/// The root-mean-square of the estimate's band of static coefficient `k` over `points`.
pub fn rms_sigma(start: &Start, k: usize, points: &[[f64; 3]]) -> f64 {
    let sum: f64 = points
        .iter()
        .map(|p| static_sigma(start, k, *p).powi(2))
        .sum();
    (sum / points.len().max(1) as f64).sqrt()
}

/// `table` with each static offset's range reaching at least [`RANGE_SIGMAS`] times the
/// estimate's band of its coefficient about `flight` ([`points_about`], [`rms_sigma`]) either
/// side of 0, its bits raised so that its step is no coarser than in `table` (at most 52);
/// ranges already wide enough are kept as they are.
pub fn offset_ranges(table: &FactorTable, start: &Start, flight: &Flight) -> FactorTable {
    let points = points_about(flight);
    let mut out = *table;
    for (k, factor) in OFFSETS {
        let spec = table.spec(factor);
        let half = RANGE_SIGMAS * rms_sigma(start, k, &points);
        if !half.is_finite() || (spec.min <= -half && spec.max >= half) {
            continue;
        }
        let (min, max) = (spec.min.min(-half), spec.max.max(half));
        let levels = ((max - min) / spec.step()).ceil();
        let bits = (levels + 1.0)
            .log2()
            .ceil()
            .clamp(f64::from(spec.bits), 52.0) as u32;
        out.0[factor.index()] = FactorSpec { min, max, bits };
    }
    out
}

/// The static offsets whose ranges differ between `base` and `now` (those [`offset_ranges`]
/// widened), in table order.
pub fn widened(base: &FactorTable, now: &FactorTable) -> Vec<Factor> {
    OFFSETS
        .iter()
        .map(|&(_, f)| f)
        .filter(|&f| base.spec(f) != now.spec(f))
        .collect()
}

/// `base` with its `[aero]` replaced by the estimate, its reference diameter the shape's (the
/// coefficients are per the body's diameter) and its static offsets' ranges reaching the
/// estimate's band ([`offset_ranges`]); everything else, the mass properties and the
/// ejector's feet included, is the base's (docs/aero.md: the shape gives no mass).
pub fn scenario(base: &Scenario, start: &Start) -> Scenario {
    let mut s = base.clone();
    s.store.diameter_m = start.estimate.config.diameter_m;
    s.aero = start.aero.clone();
    s.factors = offset_ranges(&base.factors, start, &base.flight);
    let widened: Vec<String> = widened(&base.factors, &s.factors)
        .iter()
        .map(|f| {
            let spec = s.factors.spec(*f);
            format!("{} {:.3} to {:.3}", f.name(), spec.min, spec.max)
        })
        .collect();
    let ranges = if widened.is_empty() {
        String::new()
    } else {
        format!(
            "; offsets widened to {RANGE_SIGMAS} sigma of the estimate: {}",
            widened.join(", ")
        )
    };
    s.description = format!(
        "{}; [aero] estimated from the shape {} (sepval scenario --from-shape, docs/aero.md){ranges}",
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

#[cfg(test)]
mod tests {
    use super::*;

    fn eglin() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/eglin-store/shape.toml")
    }

    /// The offsets' ranges recomputed from the bands as written: CA0's band is over Mach alone,
    /// so at the default's Mach 0.95 it is the mean of the band at the grid's Mach 0.9 and
    /// 1.0, and caoff reaches three of it either side, on a step no coarser than Anderson's;
    /// the offsets whose ranges already hold three sigmas, and every other factor, are kept.
    #[test]
    fn the_offsets_reach_three_of_the_estimates_sigmas() {
        let base = Scenario::embedded_default();
        let start = read(&eglin(), base.flight.altitude_m).expect("the Eglin store");
        let s = scenario(&base, &start);
        let band = start
            .bands
            .iter()
            .find(|b| b.target == Target::Static(0))
            .expect("CA0 has a band");
        let mach = start.aero.ca0.as_table().expect("a table").axes()[0]
            .breakpoints
            .clone();
        let at = |m: f64| mach.iter().position(|x| (x - m).abs() < 1e-9).unwrap();
        let sigma = 0.5 * (band.sigma[at(0.9)] + band.sigma[at(1.0)]);
        let caoff = s.factors.spec(Factor::Caoff);
        let anderson = base.factors.spec(Factor::Caoff);
        assert!((caoff.max - 3.0 * sigma).abs() < 1e-12, "{caoff:?} {sigma}");
        assert!((caoff.min + 3.0 * sigma).abs() < 1e-12, "{caoff:?} {sigma}");
        assert!(caoff.max > anderson.max, "{caoff:?}");
        assert!(caoff.step() <= anderson.step(), "{caoff:?}");
        assert!(
            caoff.step() > 0.5 * anderson.step(),
            "{caoff:?}: one bit more than needed"
        );
        for f in Factor::ALL {
            let (got, was) = (s.factors.spec(f), base.factors.spec(f));
            if OFFSETS.iter().all(|(_, o)| *o != f) {
                assert_eq!(got, was, "{f:?}");
            } else if got != was {
                assert!(got.min < was.min && got.max > was.max, "{f:?} {got:?}");
            }
        }
        let cm = rms_sigma(&start, 4, &points_about(&base.flight));
        assert!(3.0 * cm < 0.5, "cmoff's band {cm} within Anderson's range");
        assert_eq!(
            s.factors.spec(Factor::Cmoff),
            base.factors.spec(Factor::Cmoff)
        );
    }
}
