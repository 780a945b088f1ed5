//! A store's freestream aerodynamics estimated from its shape, as the field does before any
//! wind tunnel: component build-up in the family of Missile DATCOM and Barrowman's equations
//! (docs/aero.md has the equations, their sources and domains, the stated uncertainty of each,
//! and the conformance against published wind-tunnel and range data).
//!
//! The stages: the shape (a store TOML of `sepval-geometry`, [`sepval_geometry::StoreShape`])
//! becomes a [`config::Configuration`] within the methods' domain; the body's slender-body and
//! crossflow terms ([`body`]) and the fins' linear theory with interference ([`fins`]) are
//! summed at each Mach number ([`buildup`]) with the axial force ([`drag`]); the result is an
//! [`Estimate`], written in the scenario's table form with uncertainty bands ([`tables`]) as
//! `aero.toml`, `store.dml` (DAVE-ML through `sepval-daveml`) and `summary.txt` ([`output`]);
//! [`start`] makes it the starting point of a scenario and of a campaign's prior.
//!
//! Conventions are docs/model.md's: reference diameter d = the body's, S = pi d^2 / 4; moments
//! about the CG; CZ_alpha = -CN_alpha; damping per rad of q d / 2V (p d / 2V, r d / 2V).
#![deny(clippy::float_cmp)]

pub mod body;
pub mod buildup;
pub mod config;
pub mod drag;
mod error;
pub mod fins;
pub mod grid;
pub mod output;
pub mod start;
pub mod tables;

use sepval_common::atmosphere::{TROPOPAUSE_M, isa_troposphere};
use sepval_geometry::StoreShape;

pub use buildup::{ACCURACY, Estimated, MachPoint};
pub use config::Configuration;
pub use error::AeroError;

/// The flight condition's altitude when none is given \[m\]: the embedded default scenario's
/// (7924.8 m, 26 000 ft; it sets only the Reynolds number of the skin friction).
pub const DEFAULT_ALTITUDE_M: f64 = 7924.8;

/// What to estimate: a shape over a grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    /// The store's shape.
    pub shape: StoreShape,
    /// Mach numbers, strictly increasing, within [`grid::MACH_DOMAIN`].
    pub mach: Vec<f64>,
    /// Angles of attack (and of sideslip) \[deg\], strictly increasing, within
    /// [`grid::ALPHA_DOMAIN_DEG`].
    pub alpha_deg: Vec<f64>,
    /// Altitude of the condition (ISA) \[m\], for the Reynolds number.
    pub altitude_m: f64,
}

/// An estimate: the configuration, its body terms, each Mach number's build-up and the
/// part not linear in alpha (CN, Cm about the CG) at each alpha of the grid, with its bands.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// The configuration.
    pub config: Configuration,
    /// The body's terms.
    pub body: body::BodyTerms,
    /// The build-up at each Mach number.
    pub points: Vec<MachPoint>,
    /// The alpha grid \[deg\].
    pub alpha_deg: Vec<f64>,
    /// (CN, Cm) not linear in alpha (the body's viscous crossflow and the fins' vortex lift)
    /// at each alpha.
    pub crossflow: Vec<(f64, f64)>,
    /// Their bands (one sigma each) at each alpha.
    pub crossflow_sigma: Vec<(f64, f64)>,
    /// The altitude \[m\].
    pub altitude_m: f64,
}

/// The estimate of `r`, refusing a shape outside the methods' domain or a grid outside its
/// own (typed errors naming the field or the grid).
pub fn estimate(r: &Request) -> Result<Estimate, AeroError> {
    let grid_error = |flag: &str, what: String| AeroError::Grid {
        flag: flag.into(),
        value: String::new(),
        what,
    };
    let check = |flag: &str, v: &[f64], (lo, hi): (f64, f64)| {
        if v.len() < 2
            || v.windows(2)
                .any(|w| w[0].partial_cmp(&w[1]) != Some(std::cmp::Ordering::Less))
        {
            return Err(grid_error(
                flag,
                "expected at least two increasing values".into(),
            ));
        }
        if v.iter().any(|x| !(lo..=hi).contains(x)) {
            return Err(grid_error(flag, format!("outside {lo} to {hi}")));
        }
        Ok(())
    };
    check("--mach", &r.mach, grid::MACH_DOMAIN)?;
    check("--alpha-deg", &r.alpha_deg, grid::ALPHA_DOMAIN_DEG)?;
    if !(0.0..TROPOPAUSE_M).contains(&r.altitude_m) {
        return Err(grid_error(
            "--altitude-m",
            format!(
                "{} m: expected 0 to {TROPOPAUSE_M} m (ISA troposphere)",
                r.altitude_m
            ),
        ));
    }
    let config = Configuration::of(&r.shape)?;
    let body = body::terms(&config);
    let air = isa_troposphere(r.altitude_m);
    let points = r
        .mach
        .iter()
        .map(|&m| buildup::at_mach(&config, &body, m, &air))
        .collect();
    let (crossflow, crossflow_sigma) = r
        .alpha_deg
        .iter()
        .map(|a| buildup::crossflow(&config, &body, a.to_radians()))
        .unzip();
    Ok(Estimate {
        config,
        body,
        points,
        alpha_deg: r.alpha_deg.clone(),
        crossflow,
        crossflow_sigma,
        altitude_m: r.altitude_m,
    })
}
