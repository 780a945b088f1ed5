//! The store's estimated aerodynamics taken into the prior (`sepval campaign init
//! --prior-from-shape SHAPE.toml`, docs/campaign.md "Beginning from pre-flight knowledge"): the
//! shape estimated by `sepval-aero` ([`sepval_aero::start`], docs/aero.md) at the campaign
//! scenario's altitude, its uncertainty taken as the factors' spread through the one mapping of
//! `--prior-daveml` ([`crate::prior_daveml`]: mean = unmoved + sum(e d) / sum(e^2), sd =
//! |s| / |e|, e = 1 for an offset).
//!
//! What differs is where the values are read. The estimate's uncertainty is mostly in its
//! derivatives (CN_alpha, x_cp), which no factor scales; what moves the model as a wrong
//! derivative does is an offset of the static coefficient it feeds, by the derivative's error
//! times the flow angle. So each static coefficient that has a band (CA, CY, CZ, Cm, Cn: the
//! linear term and the crossflow table, [`sepval_aero::start::static_at`]) is read, for the
//! estimate and for the campaign's scenario, at every condition of the campaign's grid and at
//! the store's own flow angles about it, the aircraft's alpha and beta and each
//! [`EXCURSION_DEG`] either side; its band at each point is the derivative's band times the
//! angle and the table's in quadrature ([`sepval_aero::start::static_sigma`]), and the mapping
//! gives its offset (caoff, cyoff, czoff, cmoff, cnoff). Not mapped, said in the docs: the
//! damping derivatives (Cl_p, Cm_q, Cn_r: no factor moves the damping) and Cl (the estimate has
//! no static rolling moment). The other twelve factors keep their belief.
//!
//! Begun from a scenario made by `sepval scenario --from-shape` of the same shape, the
//! campaign flies the estimate's tables: every d is 0 and each offset's mean is 0, its sd the
//! estimate's band over those points. From another scenario the means are the projection of the
//! estimate's difference from it, refused beyond the factor's range as `--prior-daveml`'s.

use std::path::Path;

use sepval_common::correction::Target;
use sepval_common::scenario::Scenario;
use sepval_envelope::Grid;

use crate::CampaignError;
use crate::prior::{Prior, PriorSource};
use crate::prior_daveml::{FieldRefusal, Points, PriorDavemlError, belief, factor_of};
use crate::sources::Mapped;

pub use sepval_aero::start::EXCURSION_DEG;

/// The words the record gives static coefficient `k` of [`sepval_aero::start::OFFSETS`] (the
/// coefficients the estimate gives a band: 0 CA, 1 CY, 2 CZ, 4 Cm, 5 Cn).
fn words(k: usize) -> &'static str {
    match k {
        0 => "CA0(M)",
        1 => "CY_beta(M) beta + CY(beta)",
        2 => "CZ_alpha(M) alpha + CZ(alpha)",
        4 => "Cm_alpha(M) alpha + Cm(alpha)",
        5 => "Cn_beta(M) beta + Cn(beta)",
        _ => "a static coefficient",
    }
}

/// The points the estimate is read at: each condition of `grid` about `scenario`, at its
/// aircraft angles and [`EXCURSION_DEG`] either side ([`sepval_aero::start::points_about`]),
/// as (Mach, alpha \[deg\], beta \[deg\]).
pub fn points(grid: &Grid, scenario: &Scenario) -> Vec<[f64; 3]> {
    (0..grid.len())
        .flat_map(|k| sepval_aero::start::points_about(&grid.scenario(scenario, k).flight))
        .collect()
}

/// `prior` with the offsets the estimate of the shape at `path` maps to set (module docs);
/// `scenario` and `grid` the campaign's. A factor an earlier source set (`--prior`,
/// `--prior-daveml`) is refused: two sources would give it.
pub fn read(
    path: &Path,
    scenario: &Scenario,
    grid: &Grid,
    prior: &Prior,
) -> Result<Prior, CampaignError> {
    let name = path.display().to_string();
    let start = sepval_aero::start::read(path, scenario.flight.altitude_m).map_err(|e| {
        CampaignError::Aero {
            path: name.clone(),
            source: Box::new(e),
        }
    })?;
    let refuse = |reason: PriorDavemlError| CampaignError::PriorShape {
        path: name.clone(),
        reason: Box::new(reason),
    };
    let at = points(grid, scenario);
    let set_before = set_by_sources(prior);
    let mut out = prior.clone();
    let mut mapped: Vec<Mapped> = Vec::new();
    for (k, _) in sepval_aero::start::OFFSETS {
        let what = words(k);
        let target = Target::Static(k);
        let field = target.field();
        let element = format!("the estimate's {what}");
        let field_refusal = |reason: FieldRefusal| PriorDavemlError::Field {
            element: element.clone(),
            field: field.clone(),
            reason,
        };
        let (factor, offset) = factor_of(target).expect("a static coefficient has an offset");
        let values: Option<Vec<f64>> = at
            .iter()
            .map(|p| sepval_aero::start::static_at(&start.aero, k, *p))
            .collect();
        let base: Option<Vec<f64>> = at
            .iter()
            .map(|p| sepval_aero::start::static_at(&scenario.aero, k, *p))
            .collect();
        let (Some(values), Some(base)) = (values, base) else {
            return Err(refuse(field_refusal(FieldRefusal::TableNotRead)));
        };
        let sd: Vec<f64> = at
            .iter()
            .map(|p| sepval_aero::start::static_sigma(&start, k, *p))
            .collect();
        let points = Points {
            values: &values,
            base: &base,
            sd: &sd,
        };
        let b = belief(factor, offset, &points, &scenario.factors, &field)
            .map_err(|r| refuse(field_refusal(r)))?;
        if set_before.contains(&factor.name().to_string()) {
            return Err(refuse(PriorDavemlError::SetBefore {
                element,
                factor: factor.name().to_string(),
            }));
        }
        out.factors.insert(factor.name().to_string(), b);
        mapped.push(Mapped {
            element,
            field,
            factor: factor.name().to_string(),
            belief: b,
        });
    }
    let bytes = std::fs::read(path).map_err(|e| crate::record::record_error(path, e))?;
    let absolute = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    out.source = format!("{} and the estimate of {name}", prior.source);
    out.sources.push(PriorSource::Shape {
        path: absolute.display().to_string(),
        sha256: sepval_common::scenario::hex_sha256(&bytes),
        points: at.len(),
        excursion_deg: EXCURSION_DEG,
        mapped,
    });
    Ok(out)
}

/// The factors an earlier source of `prior` set (a `--prior` file, a `--prior-daveml` file).
fn set_by_sources(prior: &Prior) -> Vec<String> {
    prior
        .sources
        .iter()
        .flat_map(|s| match s {
            PriorSource::File { factors, .. } => factors.clone(),
            PriorSource::Daveml { mapped, .. } | PriorSource::Shape { mapped, .. } => {
                mapped.iter().map(|m| m.factor.clone()).collect()
            }
            _ => Vec::new(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use sepval_envelope::grid::Axis;
    use sepval_run::conditions::Quantity;

    fn shape() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/geometry/store.toml")
    }

    /// Mach 0.6, 0.8, 1.0 and alpha 0, 5, 10 deg: with the excursions every point on the
    /// estimate's grids (Mach every 0.1, alpha every 5 deg), so the expectation below reads
    /// the estimate's own numbers, no interpolation.
    fn grid(base: &Scenario, alpha_deg: &str) -> Grid {
        let axes = [
            Axis::parse(Quantity::Mach, "0.6:1.0:3").unwrap(),
            Axis::parse(Quantity::AlphaDeg, alpha_deg).unwrap(),
        ];
        Grid::of(base, &axes).unwrap()
    }

    /// The offsets' beliefs recomputed from the estimate's printed quantities (CN_alpha,
    /// Cm_alpha, CA0 and the crossflow with their sigmas), independently of `static_at` and
    /// `static_sigma`: at the scenario made from the shape every mean is 0 and each sd is the
    /// root-mean-square over the 27 points of the band (derivative band times angle, crossflow
    /// band in quadrature).
    #[test]
    fn the_estimates_bands_become_the_offsets_spreads() {
        let base = Scenario::embedded_default();
        let from_shape =
            sepval_aero::start::scenario_from_shape(&shape(), &base).expect("the example store");
        let grid = grid(&from_shape, "0:10:3");
        let prior = Prior::default_of(&from_shape.factors);
        let got = read(&shape(), &from_shape, &grid, &prior).unwrap();
        let est = sepval_aero::start::read(&shape(), from_shape.flight.altitude_m)
            .unwrap()
            .estimate;
        let at_mach = |m: f64| {
            est.points
                .iter()
                .find(|p| (p.mach - m).abs() < 1e-9)
                .expect("on the grid")
        };
        let crossflow = |a: f64| {
            let i = est.alpha_deg.iter().position(|x| (x - a).abs() < 1e-9);
            est.crossflow_sigma[i.expect("on the grid")]
        };
        let (mut ca, mut cz, mut cm, mut n) = (0.0, 0.0, 0.0, 0.0);
        for m in [0.6, 0.8, 1.0] {
            let p = at_mach(m);
            for a_aircraft in [0.0, 5.0, 10.0] {
                for a in [a_aircraft - 5.0, a_aircraft, a_aircraft + 5.0] {
                    let (cn_band, cm_band) = crossflow(a);
                    let r = f64::to_radians(a);
                    ca += p.ca0.sigma.powi(2);
                    cz += (p.cn_alpha_per_rad.sigma * r).powi(2) + cn_band.powi(2);
                    cm += (p.cm_alpha_per_rad.sigma * r).powi(2) + cm_band.powi(2);
                    n += 1.0;
                }
            }
        }
        let expect = [
            ("caoff", (ca / n).sqrt()),
            ("czoff", (cz / n).sqrt()),
            ("cmoff", (cm / n).sqrt()),
        ];
        for (name, sd) in expect {
            let b = got.factors[name];
            assert!(b.mean.abs() < 1e-12, "{name} mean {}", b.mean);
            assert!(
                (b.sd - sd).abs() < 1e-9 * sd,
                "{name} sd {} expected {sd}",
                b.sd
            );
        }
        // The lateral offsets: beta is 0 at every condition, read at 0 and +-5 deg.
        assert!(got.factors["cyoff"].sd > 0.0 && got.factors["cnoff"].sd > 0.0);
        // The factors the estimate does not give keep the default's beliefs.
        for name in ["fwdfac", "cloff", "czintfac", "yinerfac"] {
            assert_eq!(got.factors[name], prior.factors[name], "{name}");
        }
        let lines = got.lines().join("\n");
        assert!(
            lines.contains("czoff") && lines.contains("store.toml"),
            "{lines}"
        );
    }

    /// From a scenario other than the estimate's the means are the projection of the
    /// difference: the estimate's scenario with CA0 raised by 0.02 everywhere gives caoff mean
    /// -0.02 (the estimate is 0.02 below it) and the same sd; the embedded default (CA0 1.10,
    /// the estimate's a half of it) puts caoff past its range, refused naming it.
    #[test]
    fn another_scenario_moves_the_means_or_is_refused() {
        let base = Scenario::embedded_default();
        let from_shape =
            sepval_aero::start::scenario_from_shape(&shape(), &base).expect("the example store");
        let on_estimate = grid(&from_shape, "0:10:3");
        let prior = Prior::default_of(&from_shape.factors);
        let at = read(&shape(), &from_shape, &on_estimate, &prior).unwrap();
        let mut raised = from_shape.clone();
        let sepval_common::table::Coefficient::Table(t) = &raised.aero.ca0.value else {
            panic!("the estimate's CA0 is a table")
        };
        let values: Vec<f64> = t.values().iter().map(|v| v + 0.02).collect();
        let t = sepval_common::table::Table::new(
            t.axes().to_vec(),
            values,
            sepval_common::table::Kind::Static,
        )
        .unwrap();
        raised.aero.ca0.value = sepval_common::table::Coefficient::Table(t);
        let moved = read(&shape(), &raised, &on_estimate, &prior).unwrap();
        let (a, m) = (at.factors["caoff"], moved.factors["caoff"]);
        assert!((m.mean + 0.02).abs() < 1e-12, "{m:?}");
        assert!((m.sd - a.sd).abs() <= 1e-15 * a.sd, "{m:?} {a:?}");
        assert_eq!(moved.factors["czoff"], at.factors["czoff"]);
        let on_default = grid(&base, "0:10:3");
        let e = read(&shape(), &base, &on_default, &prior)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("--prior-from-shape ") && e.contains("caoff") && e.contains("outside"),
            "{e}"
        );
    }
}
