//! `sepval campaign init` and `rehearse` as asked: the flags' values checked and read into the
//! campaign's settings record and what `init` starts from ([`Init`]), before anything is
//! written or allocated for the work.
//!
//! The work's limits, each refused with exit status 2 before anything is made (before
//! 2026-12-01 `--samples 10000000` on a 2 x 2 grid grew to 4.5 GB and aborted, leaving the
//! directory locked):
//! - `--samples` from [`MIN_SAMPLES`] to [`sepval_predict::condition::MAX_SAMPLES`] per
//!   condition (a prediction's most), and their trajectories at the band's points within
//!   [`sepval_predict::condition::MAX_VALUE_BYTES`] (one condition is held at a time);
//! - samples x conditions at most [`MAX_ROUND_SIMULATIONS`] (a round's envelope);
//! - `--generations` within the genetic search's limits ([`sepval_solve::ga`]:
//!   `MAX_GENERATIONS`, and `MAX_EVALUATIONS` at the study's population of 100).

use std::path::{Path, PathBuf};

use sepval_predict::ClearanceSettings;
use sepval_run::inputs;

use sepval_common::simulation::sample_times;
use sepval_predict::condition::{MAX_SAMPLES, MAX_VALUE_BYTES};

use crate::preflight::{Allowance, Preflight};
use crate::prior::Prior;
use crate::program::{Init, grid_of, input_record};
use crate::record::SettingsRecord;
use crate::release::{Against, NewRelease};
use crate::{CampaignError, Refusal};

/// The fewest samples per condition: a probability of failing estimated from fewer is one
/// sample's (1 / 20 = 0.05, the default allowed probability).
pub const MIN_SAMPLES: usize = 20;
/// The most simulations of one round's envelope (samples x conditions): 1e7, about an hour on
/// the 2-core development machine through the SIMD lanes.
pub const MAX_ROUND_SIMULATIONS: u64 = 10_000_000;

/// The flags of `init` (and of `rehearse`, which begins as `init` does), as given.
#[derive(Debug, Clone)]
pub struct InitRequest<'a> {
    /// `--scenario` (none: the embedded default).
    pub scenario: Option<&'a Path>,
    /// `--aircraft` (required).
    pub aircraft: Option<&'a Path>,
    /// `--store-shape`.
    pub store_shape: Option<&'a Path>,
    /// The axes given, (flag, `LO:HI:N`), in the order of `[flight]`.
    pub axes: Vec<(String, String)>,
    /// `--clearance-mm`.
    pub clearance_mm: f64,
    /// `--allowed`.
    pub allowed: f64,
    /// `--fly-risk`.
    pub fly_risk: f64,
    /// `--samples`.
    pub samples: usize,
    /// `--seed`.
    pub seed: u64,
    /// `--generations`.
    pub generations: usize,
    /// `--prior` (none: the factors' default prior).
    pub prior: Option<&'a Path>,
    /// `--prior-daveml`: the store's data with uncertainty.
    pub prior_daveml: Option<&'a Path>,
    /// `--prior-from-shape`: the store's shape, its estimate's uncertainty taken as the
    /// offsets' spread.
    pub prior_from_shape: Option<&'a Path>,
    /// `--preflight`: pre-flight trajectories.
    pub preflight: &'a [PathBuf],
    /// `--preflight-allowance-m` and `--preflight-allowance-deg`.
    pub preflight_allowance: (f64, f64),
    /// Threads of this process.
    pub threads: usize,
}

/// A probability flag in (0, 0.5).
fn probability(flag: &'static str, p: f64) -> Result<f64, CampaignError> {
    if !(p > 0.0 && p < 0.5) {
        return Err(CampaignError::Setting {
            flag,
            value: p.to_string(),
            expected: "expected a probability above 0 and below 0.5".into(),
        });
    }
    Ok(p)
}

/// Checks the work the flags ask for (module docs) against the grid of `conditions` and the
/// `points` of a condition's band.
fn check_work(
    samples: usize,
    generations: usize,
    conditions: usize,
    points: usize,
) -> Result<(), CampaignError> {
    let refuse = |flag, value: usize, expected: String| {
        Err(CampaignError::Setting {
            flag,
            value: value.to_string(),
            expected,
        })
    };
    if !(MIN_SAMPLES..=MAX_SAMPLES).contains(&samples) {
        let expected = format!("expected {MIN_SAMPLES} to {MAX_SAMPLES} samples per condition");
        return refuse("--samples", samples, expected);
    }
    let bytes = samples.saturating_mul(points).saturating_mul(6 * 8);
    if bytes > MAX_VALUE_BYTES {
        let expected = format!(
            "{samples} samples of {points} band points take {bytes} bytes, above the {MAX_VALUE_BYTES} a condition may hold: give fewer samples"
        );
        return refuse("--samples", samples, expected);
    }
    let simulations = samples as u64 * conditions as u64;
    if simulations > MAX_ROUND_SIMULATIONS {
        let expected = format!(
            "{samples} samples at each of {conditions} conditions are {simulations} simulations a round, above the limit of {MAX_ROUND_SIMULATIONS}: give fewer samples or a coarser grid"
        );
        return refuse("--samples", samples, expected);
    }
    let ga = sepval_solve::ga::GaSettings {
        generations,
        ..Default::default()
    };
    match ga.validate() {
        Err(sepval_solve::ga::GaError::Setting { expected, .. }) => {
            refuse("--generations", generations, expected.to_string())
        }
        Err(e) => refuse("--generations", generations, e.to_string()),
        Ok(()) => Ok(()),
    }
}

impl InitRequest<'_> {
    /// The flags checked (the probabilities, the samples, an aircraft and at least one axis
    /// given) and the scenario, the prior and the geometry read: what `init` begins from.
    pub fn read(&self) -> Result<Init, CampaignError> {
        let allowed = probability("--allowed", self.allowed)?;
        let fly_risk = probability("--fly-risk", self.fly_risk)?;
        let Some(aircraft) = self.aircraft else {
            return Err(Refusal::NoAircraft.into());
        };
        let scenario = inputs::scenario(self.scenario, None)
            .map_err(|e| CampaignError::Inputs(Box::new(e)))?;
        if self.axes.is_empty() {
            return Err(Refusal::NoAxis.into());
        }
        let mut prior = match self.prior {
            Some(p) => Prior::read(p, &scenario.factors)?,
            None => Prior::default_of(&scenario.factors),
        };
        if let Some(p) = self.prior_daveml {
            prior = crate::prior_daveml::read(p, &scenario, &prior)?;
        }
        let clearance =
            ClearanceSettings::read(aircraft, self.store_shape, self.clearance_mm, &scenario)
                .map_err(|e| CampaignError::Clearance(Box::new(e)))?;
        let settings = SettingsRecord {
            scenario: self.scenario.map(input_record).transpose()?,
            aircraft: input_record(aircraft)?,
            store_shape: self.store_shape.map(input_record).transpose()?,
            axes: self.axes.clone(),
            clearance_mm: self.clearance_mm,
            allowed,
            fly_risk,
            samples: self.samples,
            seed: self.seed,
            generations: self.generations,
            prior,
        };
        let mut settings = settings;
        let grid = grid_of(&settings, &scenario)?;
        if let Some(p) = self.prior_from_shape {
            settings.prior = crate::prior_shape::read(p, &scenario, &grid, &settings.prior)?;
        }
        let times = sample_times(scenario.integrator.t_end_s, scenario.integrator.rate_hz);
        let points = sepval_predict::simulate::Grid::of(&times).len();
        check_work(self.samples, self.generations, grid.len(), points)?;
        let preflight = self.preflight(&scenario, &settings, &grid)?;
        Ok(Init {
            settings,
            scenario,
            grid,
            clearance,
            threads: self.threads,
            preflight,
        })
    }

    /// The pre-flight trajectories read and screened as releases (each stating its
    /// condition), each given once, and their allowance checked (none given: none).
    fn preflight(
        &self,
        scenario: &sepval_common::scenario::Scenario,
        settings: &SettingsRecord,
        grid: &sepval_envelope::Grid,
    ) -> Result<Option<Preflight>, CampaignError> {
        let (m, deg) = self.preflight_allowance;
        let allowance = Allowance::checked(m, deg)?;
        if self.preflight.is_empty() {
            return Ok(None);
        }
        let against = Against {
            scenario,
            axes: &settings.axes,
            grid,
        };
        let mut trajectories: Vec<NewRelease> = Vec::new();
        for p in self.preflight {
            let in_file = |e: CampaignError| Refusal::Preflight {
                path: p.clone(),
                reason: Box::new(e),
            };
            let policy = sepval_common::telemetry::outliers::Policy::Refuse;
            let t = NewRelease::read(p, against, policy, true, &mut |_| {}).map_err(in_file)?;
            if let Some(o) = trajectories.iter().find(|o| o.sha256 == t.sha256) {
                return Err(Refusal::PreflightTwice {
                    path: p.to_path_buf(),
                    other: o.given.clone(),
                }
                .into());
            }
            trajectories.push(t);
        }
        Ok(Some(Preflight {
            trajectories,
            allowance,
        }))
    }
}
