//! The condition predicted and the prediction's settings, checked before anything runs: the
//! scenario of `--scenario COND.toml` must fly the store that was fitted (the same store,
//! ejector, aerodynamics, interference, factor table and extension terms as the releases
//! fitted: only `[flight]`, the name and the integrator may differ) at a condition within the
//! model's domain ([`sepval_run::domain`]), `--level` lies in (0, 1), and `--samples` is at
//! least [`min_samples`] of the level (20 / (1 - level)), at most [`MAX_SAMPLES`], and their
//! trajectories at the band's points fit [`MAX_VALUE_BYTES`].

use std::path::Path;

use sepval_common::scenario::{Scenario, StoreDifference};
use sepval_common::telemetry::outliers::Policy;
use sepval_core::number_text::Shown;
use sepval_run::inputs;

/// The most samples of one prediction.
pub const MAX_SAMPLES: usize = 100_000;
/// The samples' trajectories held at once (samples x points x 6 doubles) are refused beyond
/// this \[bytes\].
pub const MAX_VALUE_BYTES: usize = 1 << 30;

/// Samples beyond the band's level asked of the fewest samples a level takes: 20 / (1 - level)
/// samples leave 20 outside the level (10 beyond each edge of a two-sided band, 20 below the
/// 5 % quantile of an envelope's clearance), enough for the edge not to be one sample's value.
pub const SAMPLES_OUTSIDE_LEVEL: f64 = 20.0;

/// The fewest samples that give bands at `level`: 20 / (1 - level), rounded up (400 at 0.95).
pub fn min_samples(level: f64) -> usize {
    // Less a hair, so that 20 / (1 - 0.9) = 200.00000000000003 asks for 200.
    (SAMPLES_OUTSIDE_LEVEL / (1.0 - level) - 1e-6).ceil() as usize
}

/// A condition, flown release or setting that cannot be predicted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ConditionError {
    /// `--level` outside (0, 1).
    #[error("--level {}: expected a number between 0 and 1 (exclusive), e.g. 0.95", Shown(*.0))]
    Level(f64),
    /// `--samples` 0 or too many.
    #[error("--samples {samples}: {message}")]
    Samples {
        /// The number given.
        samples: usize,
        /// What is wrong.
        message: String,
    },
    /// A condition outside the model's domain or its scenario's tables.
    #[error("the condition's {domain}")]
    Domain {
        /// Which quantity, and the domain.
        domain: sepval_run::domain::DomainError,
    },
    /// A scenario of another store.
    #[error(
        "its store differs from that of the releases fitted ({fitted}): {difference}; a prediction flies the store that was fitted: change only [flight]"
    )]
    OtherStore {
        /// The first field that differs.
        difference: StoreDifference,
        /// The fitted scenario's name.
        fitted: String,
    },
}

/// A flown release (`--data`) that cannot be checked against a prediction.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FlownError {
    /// The flown release (`--data`) that cannot be read.
    #[error("--data {name}")]
    Read {
        /// Its file.
        name: String,
        /// Why.
        #[source]
        source: Box<sepval_run::inputs::InputError>,
    },
    /// Its metadata that does not read, or its store that is not the condition's (the error
    /// names the file).
    #[error(transparent)]
    Release(Box<sepval_run::inputs::InputError>),
    /// The flown release's metadata names another condition than the prediction's.
    #[error(
        "--data {name}: its metadata says it was flown at {flown}, not at the condition of --scenario ({condition})"
    )]
    Elsewhere {
        /// Its file.
        name: String,
        /// The condition its metadata names, in words.
        flown: String,
        /// The prediction's condition, in words.
        condition: String,
    },
}

/// A flight condition in the words of [`FlownError::Elsewhere`].
fn condition_words(f: &sepval_common::scenario::Flight) -> String {
    format!(
        "Mach {}, altitude {} m, alpha {} deg, beta {} deg, gamma {} deg",
        f.mach, f.altitude_m, f.alpha_deg, f.beta_deg, f.gamma_deg
    )
}

impl crate::Flown {
    /// The flown release at `path` (`--data`), read with `policy` (what the screening left
    /// out told to `tell`), of the store of `condition` (the scenario `scenario_name`), and, when
    /// its metadata names one, flown at `condition`'s flight condition (to 1e-9 relative).
    pub fn read(
        path: &Path,
        (scenario_name, condition): (&str, &Scenario),
        policy: Policy,
        tell: sepval_run::inputs::Tell,
    ) -> Result<crate::Flown, FlownError> {
        let name = path.display().to_string();
        let data = inputs::read(path, policy, tell).map_err(|source| FlownError::Read {
            name: name.clone(),
            source: Box::new(source),
        })?;
        let release = |e| FlownError::Release(Box::new(e));
        let named = inputs::event_scenario(condition, &data, &name).map_err(release)?;
        inputs::check_store(condition, &data, &name, scenario_name).map_err(release)?;
        let (a, b) = (&named.flight, &condition.flight);
        let same = |x: f64, y: f64| (x - y).abs() <= 1e-9 * (1.0 + x.abs().max(y.abs()));
        if !(same(a.mach, b.mach)
            && same(a.altitude_m, b.altitude_m)
            && same(a.alpha_deg, b.alpha_deg)
            && same(a.beta_deg, b.beta_deg)
            && same(a.gamma_deg, b.gamma_deg))
        {
            return Err(FlownError::Elsewhere {
                name,
                flown: condition_words(a),
                condition: condition_words(b),
            });
        }
        Ok(crate::Flown { name, data })
    }
}

/// How a prediction is made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Samples.
    pub samples: usize,
    /// The bands' level (0.95: 95 % bands).
    pub level: f64,
    /// The seed of every draw.
    pub seed: u64,
    /// Whether the measurement noise is a source (always with a flown release to check).
    pub with_noise: bool,
    /// Threads of the calibration's in-process refits.
    pub threads: usize,
}

impl Settings {
    /// Checks the level and the number of samples.
    pub fn check(&self) -> Result<(), ConditionError> {
        if !(self.level > 0.0 && self.level < 1.0) {
            return Err(ConditionError::Level(self.level));
        }
        let least = min_samples(self.level);
        if self.samples < least {
            // Only a level given by --level can need more than MAX_SAMPLES; the commands with a
            // fixed level are told the samples alone.
            let remedy = if least > MAX_SAMPLES {
                format!(
                    "more than the {MAX_SAMPLES} drawn at most: give a --level of at most {}",
                    1.0 - 20.0 / MAX_SAMPLES as f64
                )
            } else {
                format!("give --samples {least} or more")
            };
            return Err(ConditionError::Samples {
                samples: self.samples,
                message: format!(
                    "bands at level {} need at least {least} samples (20 / (1 - level), so that 20 samples fall outside the level); {remedy}",
                    self.level
                ),
            });
        }
        if self.samples > MAX_SAMPLES {
            return Err(ConditionError::Samples {
                samples: self.samples,
                message: format!("expected at most {MAX_SAMPLES}"),
            });
        }
        Ok(())
    }

    /// Checks that the samples' trajectories at `points` band points fit [`MAX_VALUE_BYTES`].
    pub fn check_size(&self, points: usize) -> Result<(), ConditionError> {
        let bytes = self.samples.saturating_mul(points).saturating_mul(6 * 8);
        if bytes > MAX_VALUE_BYTES {
            return Err(ConditionError::Samples {
                samples: self.samples,
                message: format!(
                    "{} samples of {points} band points need {bytes} bytes, above {MAX_VALUE_BYTES}: give fewer samples",
                    self.samples
                ),
            });
        }
        Ok(())
    }
}

/// Checks that `condition` flies the store of `fitted` ([`Scenario::store_difference`]),
/// within the model's domain ([`sepval_run::domain`]).
pub fn check_condition(fitted: &Scenario, condition: &Scenario) -> Result<(), ConditionError> {
    if let Some(difference) = fitted.store_difference(condition) {
        return Err(ConditionError::OtherStore {
            difference,
            fitted: fitted.name.clone(),
        });
    }
    sepval_run::domain::check(condition).map_err(|domain| ConditionError::Domain { domain })
}
