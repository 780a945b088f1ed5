//! `sepval campaign init` and `rehearse` as asked: the flags' values checked and read into the
//! campaign's settings record and what `init` starts from ([`Init`]), before anything is
//! written.

use std::path::Path;

use sepval_fit::inputs;
use sepval_predict::ClearanceSettings;

use crate::CampaignError;
use crate::prior::Prior;
use crate::program::{Init, input_record};
use crate::record::SettingsRecord;

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
    /// Threads of this process.
    pub threads: usize,
}

/// A probability flag in (0, 0.5).
fn probability(flag: &str, p: f64) -> Result<f64, CampaignError> {
    if !(p > 0.0 && p < 0.5) {
        return Err(CampaignError::Refused(format!(
            "{flag} {p}: expected a probability above 0 and below 0.5"
        )));
    }
    Ok(p)
}

impl InitRequest<'_> {
    /// The flags checked (the probabilities, the samples, an aircraft and at least one axis
    /// given) and the scenario, the prior and the geometry read: what `init` begins from.
    pub fn read(&self) -> Result<Init, CampaignError> {
        let allowed = probability("--allowed", self.allowed)?;
        let fly_risk = probability("--fly-risk", self.fly_risk)?;
        if self.samples < 20 {
            return Err(CampaignError::Refused(format!(
                "--samples {}: at least 20 samples per condition",
                self.samples
            )));
        }
        let Some(aircraft) = self.aircraft else {
            return Err(CampaignError::Refused(
                "--aircraft FILE is required: the aircraft's geometry (e.g. examples/geometry/aircraft.toml)".into(),
            ));
        };
        let scenario = inputs::scenario(self.scenario, None)
            .map_err(|e| CampaignError::Inputs(Box::new(e)))?;
        if self.axes.is_empty() {
            return Err(CampaignError::Refused(
                "give at least one axis: --mach, --altitude-m, --alpha-deg, --beta-deg or --gamma-deg, each LO:HI:N".into(),
            ));
        }
        let prior = match self.prior {
            Some(p) => Prior::read(p, &scenario.factors)?,
            None => Prior::default_of(&scenario.factors),
        };
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
        Ok(Init {
            settings,
            scenario,
            clearance,
            threads: self.threads,
        })
    }
}
