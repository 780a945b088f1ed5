//! One release simulated as `sepval simulate` writes it: the scenario's store flown by the
//! factors and effects given, sampled at the rate asked (noise added with a seed), the tables
//! it left found (docs/model.md section 3), the extension's terms recorded in the file's
//! metadata, and, with the aircraft's geometry, the clearance along it ([`releases::trace`]).

use std::path::Path;

use sepval_common::effects::EffectSet;
use sepval_common::scenario::Scenario;
use sepval_common::simulation::{SimError, Simulator, sample_times};
use sepval_common::synthetic::synthetic_flight_test_logged;
use sepval_common::telemetry::Trajectory;
use sepval_core::factors::Factors;
use sepval_core::limits::{LimitError, check_sampling, check_steps};
use sepval_core::number_text::Shown;
use sepval_geometry::GeometryError;

use crate::clearance::ClearanceSettings;
use crate::releases;

/// What to simulate.
pub struct ReleaseRequest<'a> {
    /// The scenario (its extension applied).
    pub scenario: &'a Scenario,
    /// The factors.
    pub factors: Factors,
    /// The effects.
    pub effects: &'a EffectSet,
    /// The extension file the scenario was extended by (`--extension`), recorded with its
    /// terms in the trajectory's metadata.
    pub extension: Option<&'a Path>,
    /// The end of the record \[s\] (the scenario's when `None`).
    pub t_end_s: Option<f64>,
    /// The sampling rate \[Hz\] (the scenario's when `None`).
    pub rate_hz: Option<f64>,
    /// The seed of the measurement noise added, none for a clean trajectory.
    pub noise_seed: Option<u64>,
    /// The aircraft's geometry, for the clearance along the trajectory.
    pub clearance: Option<&'a ClearanceSettings>,
    /// Refuse a run that leaves a table (`--strict-tables`).
    pub strict_tables: bool,
}

/// A release simulated.
pub struct SimulatedRelease {
    /// The trajectory, with its metadata (the extension's terms, the clearance).
    pub trajectory: Trajectory,
    /// The clearance at each sample \[m\] and its line, with the aircraft's geometry.
    pub clearance: Option<(Vec<f64>, String)>,
    /// The tables the run left, one line each (held at their edge).
    pub tables_left: Vec<String>,
}

/// A release that could not be simulated.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReleaseError {
    /// The integration's work, or the samples asked, over their limits.
    #[error("{flags}")]
    Limits {
        /// The flags that ask for it.
        flags: String,
        /// Why.
        #[source]
        source: LimitError,
    },
    /// The simulation.
    #[error("simulation failed")]
    Simulation(#[source] SimError),
    /// A table left with `strict_tables`.
    #[error("--strict-tables: the run {} (nothing written)", .0.join("; and "))]
    TablesLeft(Vec<String>),
    /// The clearance along the trajectory.
    #[error("the clearance of the trajectory")]
    Clearance(#[source] GeometryError),
}

/// Simulates the release `r` asks for.
pub fn simulate_release(r: &ReleaseRequest<'_>) -> Result<SimulatedRelease, ReleaseError> {
    let s = r.scenario;
    let t_end = r.t_end_s.unwrap_or(s.integrator.t_end_s);
    let rate = r.rate_hz.unwrap_or(s.integrator.rate_hz);
    // The work of the run, refused before the sample times are made.
    let (t_shown, rate_shown) = (Shown(t_end), Shown(rate));
    check_steps(t_end, s.integrator.dt_s).map_err(|source| ReleaseError::Limits {
        flags: format!("--t-end {t_shown}"),
        source,
    })?;
    check_sampling(t_end, rate).map_err(|source| ReleaseError::Limits {
        flags: format!("--t-end {t_shown} with --rate {rate_shown}"),
        source,
    })?;
    let sim = Simulator::new(s);
    let times = sample_times(t_end, rate);
    let (mut trajectory, log) =
        synthetic_flight_test_logged(&sim, &r.factors, r.effects, &times, r.noise_seed)
            .map_err(ReleaseError::Simulation)?;
    // Tables left: held at the edge and reported, or refused (docs/model.md section 3).
    let tables_left: Vec<String> = sim
        .table_excursions(&log)
        .iter()
        .map(|e| e.to_string())
        .collect();
    if r.strict_tables && !tables_left.is_empty() {
        return Err(ReleaseError::TablesLeft(tables_left));
    }
    if let Some(path) = r.extension {
        // The extension's terms as the model held them (the scenario's own terms included),
        // so that the file says what made it.
        trajectory.push_metadata("extension", &path.display().to_string());
        let terms: Vec<String> = sim
            .model()
            .extension
            .iter()
            .map(|t| format!("{} {} = {}", t.axis.name(), t.formula(), t.coefficient))
            .collect();
        trajectory.push_metadata("extension_terms", &terms.join("; "));
    }
    let clearance = match r.clearance {
        Some(c) => {
            // The clearance of the trajectory (its noise included, with a noise seed).
            let trace = releases::trace(c, &trajectory).map_err(ReleaseError::Clearance)?;
            let line = releases::words(c, &trace);
            trajectory.push_metadata("clearance", &line);
            Some((trace.distance_m, line))
        }
        None => None,
    };
    Ok(SimulatedRelease {
        trajectory,
        clearance,
        tables_left,
    })
}
