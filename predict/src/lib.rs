//! The trajectory of a release that was not flown (`sepval predict`), with bands that say how
//! sure it is, and the post-flight check of a flown release against them. What is computed is
//! specified in docs/prediction.md. The bands have three sources, each reported with its
//! share of the width: the factors (drawn from the covariance of the fit), the model's form
//! (the diagnosis's rivals weighted by their evidence, and a discrepancy calibrated on releases
//! held out of the fit), and the measurement. The field's warning is NASA's X-43A: flight
//! results left the Monte Carlo bounds of the parameters in several instances because the
//! model's form was uncertain too (J. T. Karlgaard et al., "Hyper-X post-flight trajectory
//! reconstruction", J. Spacecraft and Rockets 43(1), 2006; L. Baumann et al., AIAA 2005-3247).
//!
//! The prediction is a pipeline of named stages ([`prepare`] and [`predict`] show it whole):
//! 1. [`source`]: the `--from` directory read and checked ([`Source`]);
//! 2. [`ensemble`]: the answer and its rivals rebuilt, with their weights ([`Ensemble`]);
//! 3. [`sampling`]: the answer's parameters drawn from their covariance, each sample from its
//!    own seeded generator ([`Sampler`]);
//! 4. [`simulate`]: every sample at the condition through any [`Evaluator`], in parts, reduced
//!    to the band's time points ([`simulate::Runs`]);
//! 5. [`discrepancy`]: the model-form discrepancy calibrated on held-out releases
//!    ([`Discrepancy`]);
//! 6. [`bands`]: pointwise quantiles and the shares of the sources ([`Bands`]);
//! 7. [`check`]: the post-flight check of a flown release ([`Check`]);
//! 8. [`record`] and [`outputs`]: DIR/prediction.json, DIR/bands.csv, DIR/report.html and
//!    DIR/figures/prediction.png, written atomically.
//!
//! Beside it, [`releases`]: the clearance of the releases a fit or a diagnosis answers with, a
//! stage of those pipelines.

#![deny(clippy::float_cmp)]

pub mod bands;
pub mod check;
pub mod clearance;
pub mod command;
pub mod condition;
pub mod discrepancy;
pub mod ensemble;
mod excess;
pub mod one_release;
pub mod outputs;
mod page;
pub mod reach;
pub mod record;
pub mod releases;
pub mod sampling;
pub mod simulate;
pub mod source;
mod summary;

use sepval_common::evaluation::{Evaluator, Event, Job};
use sepval_common::scenario::Scenario;
use sepval_common::telemetry::Trajectory;
use sepval_solve::run::ProgressObserver;

pub use bands::{Bands, ChannelBand, Shares};
pub use check::Check;
pub use clearance::{ClearanceSettings, ClearanceStats};
pub use condition::{ConditionError, FlownError, Settings, check_condition};
pub use discrepancy::Discrepancy;
pub use ensemble::Ensemble;
pub use outputs::write_outputs;
pub use record::{PREDICTION_FORMAT, PredictionFile, prediction_file};
pub use sampling::Sampler;
pub use source::{
    Source, SourceError, SourceInputs, SourceInputsError, SourceKind, read_source, source_inputs,
};
pub use summary::summary;

use simulate::{Grid, GridTrajectory};

/// A prediction that cannot be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PredictError {
    /// The `--from` directory.
    #[error(transparent)]
    Source(#[from] SourceError),
    /// A model of the source that cannot be rebuilt.
    #[error("the models of --from")]
    Ensemble(#[from] ensemble::EnsembleError),
    /// The condition, the flown release or the settings.
    #[error(transparent)]
    Condition(#[from] ConditionError),
    /// The simulations.
    #[error(transparent)]
    Simulate(#[from] simulate::SimulateError),
    /// The calibration of the discrepancy.
    #[error("the calibration of the model-form discrepancy")]
    Discrepancy(#[from] discrepancy::DiscrepancyError),
    /// Every sample diverged or failed.
    #[error(
        "every one of the {samples} samples diverged or failed at this condition (the first: {first}): the models do not fly it; predict a condition nearer those fitted"
    )]
    AllDiverged {
        /// Samples.
        samples: usize,
        /// The first one's reason.
        first: simulate::NoTrajectory,
    },
    /// The outputs.
    #[error(transparent)]
    Outputs(#[from] outputs::OutputError),
    /// A signal asked the process to stop.
    #[error(transparent)]
    Cancelled(#[from] sepval_core::cancel::Cancelled),
}

/// A release flown at the condition, to check against the bands.
#[derive(Debug, Clone)]
pub struct Flown {
    /// Its name (the file).
    pub name: String,
    /// Its data.
    pub data: Trajectory,
}

/// A prediction's inputs, checked, before anything is simulated.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The source.
    pub source: Source,
    /// Its models and their weights.
    pub ensemble: Ensemble,
    /// The draws.
    pub sampler: Sampler,
    /// The condition's scenario.
    pub condition: Scenario,
    /// The evaluator's job: one release at the condition.
    pub job: Job,
    /// The band's time points.
    pub grid: Grid,
    /// The releases fitted.
    pub fitted: Job,
    /// Releases held out as they are (`--validate`).
    pub held_out: Vec<Event>,
    /// The flown release to check, if any.
    pub flown: Option<Flown>,
    /// The settings.
    pub settings: Settings,
    /// The clearance to assess, if any ([`Prepared::with_clearance`]).
    pub clearance: Option<ClearanceSettings>,
    /// When the condition lies far from every release fitted ([`sepval_run::domain::far`]),
    /// the sentence that says so: the first of the prediction's summary.
    pub extrapolation: Option<String>,
    /// How far the condition lies from the nearest release fitted beyond the reach the
    /// held-out releases cover ([`reach::uncovered`]), which widens the model-form band
    /// ([`reach`]).
    pub reach: f64,
}

impl Prepared {
    /// The same prediction with the clearance of every sample assessed.
    pub fn with_clearance(self, clearance: ClearanceSettings) -> Prepared {
        Prepared {
            clearance: Some(clearance),
            ..self
        }
    }

    /// What the discrepancy's calibration needs, at this prediction's condition.
    pub fn calibration(&self) -> discrepancy::Calibration<'_> {
        discrepancy::Calibration {
            answer: self.ensemble.answer(),
            identifiability: &self.source.identifiability,
            fitted: &self.fitted,
            held_out: &self.held_out,
            target: &self.job.events()[0],
            noise: self.source.noise,
            threads: self.settings.threads,
            seed: self.settings.seed,
        }
    }
}

/// Rebuilds the models of `source`, fitted to `fitted` (the job of its `inputs`), and the job
/// of the release at `condition` (sampled at the flown release's times, else the first fitted
/// release's): everything checked before any simulation.
pub fn prepare(
    source: Source,
    fitted: Job,
    condition: Scenario,
    held_out: Vec<Event>,
    flown: Option<Flown>,
    settings: Settings,
) -> Result<Prepared, PredictError> {
    settings.check()?;
    let first = &fitted.events()[0];
    check_condition(first.simulator.scenario(), &condition)?;
    let times = match &flown {
        Some(f) => f.data.times_s.clone(),
        None => first.data.times_s.clone(),
    };
    let grid = Grid::of(&times);
    settings.check_size(grid.len())?;
    let ensemble = Ensemble::of(&source, fitted.factor_table())?;
    let answer = ensemble.answer();
    let sampler = Sampler {
        answer: sampling::ParameterDistribution::of(
            &answer.space,
            &answer.x,
            &source.identifiability,
        ),
        seed: settings.seed,
    };
    let job = simulate::release_job(&condition, &times, "prediction")
        .map_err(simulate::SimulateError::from)?;
    let releases: Vec<&sepval_common::scenario::Flight> = fitted
        .events()
        .iter()
        .map(|e| &e.simulator.scenario().flight)
        .collect();
    let extrapolation = sepval_run::domain::far(&releases, &condition.flight);
    let validated: Vec<&sepval_common::scenario::Flight> = held_out
        .iter()
        .map(|e| &e.simulator.scenario().flight)
        .collect();
    let reach = reach::uncovered(
        sepval_run::domain::reach(&releases, &condition.flight),
        sepval_run::domain::covered_reach(&releases, &validated),
    );
    Ok(Prepared {
        source,
        ensemble,
        sampler,
        condition,
        job,
        grid,
        fitted,
        held_out,
        flown,
        settings,
        clearance: None,
        extrapolation,
        reach,
    })
}

/// What a prediction found.
#[derive(Debug, Clone)]
pub struct Prediction {
    /// Each sample's model.
    pub models: Vec<usize>,
    /// Samples that diverged or failed.
    pub failed: usize,
    /// The discrepancy.
    pub discrepancy: Discrepancy,
    /// The bands.
    pub bands: Bands,
    /// The flown release at the grid, when given.
    pub flown: Option<GridTrajectory>,
    /// The post-flight check, when a flown release was given.
    pub check: Option<Check>,
    /// The clearance, when a geometry was given.
    pub clearance: Option<ClearanceStats>,
    /// Simulations run (the calibration's included).
    pub evaluations: u64,
}

/// The prediction's stages from the samples on. `evaluator` must have been started with
/// `prepared.job`.
pub fn predict(
    prepared: &Prepared,
    evaluator: &mut dyn Evaluator,
    progress: &mut dyn ProgressObserver,
) -> Result<Prediction, PredictError> {
    predict_with(prepared, evaluator, progress, None)
}

/// [`predict`] with the held-out releases' evidence already computed
/// ([`discrepancy::evidence`] of [`Prepared::calibration`]), as an envelope does once for all
/// its conditions; `None` computes it.
pub fn predict_with(
    prepared: &Prepared,
    evaluator: &mut dyn Evaluator,
    progress: &mut dyn ProgressObserver,
    evidence: Option<&discrepancy::Evidence>,
) -> Result<Prediction, PredictError> {
    let (ens, n) = (&prepared.ensemble, prepared.settings.samples);
    let samples: Vec<sampling::Sample> = (0..n)
        .map(|i| prepared.sampler.sample(ens, i as u64))
        .collect();
    progress.start("predict", Some(n.div_ceil(part_size(&prepared.job))));
    let runs = simulate::run_candidates(
        evaluator,
        n,
        &|i| samples[i].candidate,
        &prepared.grid,
        progress,
    )?;
    progress.finish();
    if runs.failed() == n {
        let first = runs
            .trajectories
            .first()
            .and_then(|t| t.clone().err())
            .unwrap_or(simulate::NoTrajectory::NoRun);
        return Err(PredictError::AllDiverged { samples: n, first });
    }
    let calibration = prepared.calibration();
    let mut discrepancy = match evidence {
        Some(ev) => discrepancy::carry(&calibration, ev, &prepared.grid)?,
        None => discrepancy::calibrate(&calibration, &prepared.grid)?,
    };
    let ran: Vec<&GridTrajectory> = runs.trajectories.iter().flatten().collect();
    discrepancy.reach = prepared.reach;
    reach::widen(&mut discrepancy.sd, &reach::motion(&ran), prepared.reach);
    let clearance = prepared
        .clearance
        .as_ref()
        .map(|c| {
            let trajectories: Vec<Option<&GridTrajectory>> =
                runs.trajectories.iter().map(|t| t.as_ref().ok()).collect();
            let s = &prepared.settings;
            clearance::assess(
                c,
                &trajectories,
                &discrepancy.sd,
                &prepared.grid,
                s.seed,
                s.threads,
            )
        })
        .transpose()?;
    let flown = prepared
        .flown
        .as_ref()
        .map(|f| simulate::data_on_grid(&f.data, &prepared.grid));
    let with_noise = prepared.settings.with_noise || flown.is_some();
    let models: Vec<usize> = samples.iter().map(|s| s.model).collect();
    let failed = runs.failed();
    let per_sample: Vec<(usize, Option<GridTrajectory>)> = models
        .iter()
        .zip(runs.trajectories)
        .map(|(m, t)| (*m, t.ok()))
        .collect();
    let weights: Vec<f64> = ens.members.iter().map(|m| m.weight).collect();
    let inputs = bands::BandInputs {
        weights: &weights,
        discrepancy: &discrepancy.sd,
        noise: with_noise.then_some(prepared.source.noise),
        level: prepared.settings.level,
        seed: prepared.settings.seed,
        points: prepared.grid.len(),
    };
    let bands = bands::bands(&inputs, per_sample);
    let check = prepared
        .flown
        .as_ref()
        .zip(flown.as_ref())
        .map(|(f, d)| check::check(&f.name, d, &prepared.grid.t_s, &bands.channels));
    let evaluations = runs.evaluations + discrepancy.evaluations;
    Ok(Prediction {
        models,
        failed,
        discrepancy,
        bands,
        flown,
        check,
        clearance,
        evaluations,
    })
}

/// Candidates per part of the evaluator's job.
fn part_size(job: &Job) -> usize {
    (sepval_fit::problem::SAMPLE_BUDGET / job.sample_count().max(1)).max(1)
}

#[cfg(test)]
mod tests;
