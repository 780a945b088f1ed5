//! One envelope of the campaign: every condition of the grid predicted from what the campaign
//! believes in a round ([`Model`]: the prior, or the diagnosis of every release flown), with the
//! clearance of every sample (docs/campaign.md, "An envelope of the campaign").
//!
//! At condition k: `samples` draws of the factors (sample s from its own generator,
//! [`sepval_predict::sampling::sample_rng`], the same draws at every condition: common random
//! numbers), each flown through the evaluator; the model-form band at the releases (none for
//! the prior; the diagnosis's discrepancy calibrated on its releases otherwise,
//! [`sepval_predict::discrepancy`], as `sepval envelope` does), widened with the condition's
//! reach ([`sepval_predict::reach`]); the clearance of every sample
//! ([`sepval_predict::clearance::assess`]) twice: with the model-form band (the condition's
//! probability of failing, its state) and without it (the factors' share of the spread, which
//! the planning needs to tell what a release would settle). Before any release nothing is
//! cleared ([`State::before_release`]). The assessment is the same bits
//! whatever the evaluator and its worker count.

use std::sync::Arc;

use sepval_common::evaluation::{Candidate, Job};
use sepval_common::scenario::{Flight, Scenario};
use sepval_common::simulation::sample_times;
use sepval_core::cancel;
use sepval_envelope::{Grid, Row};
use sepval_fit::space::ParamSpace;
use sepval_predict::discrepancy::{self, Calibration, Evidence};
use sepval_predict::ensemble::Ensemble;
use sepval_predict::record::ConditionRecord;
use sepval_predict::sampling::{ParameterDistribution, STREAM_PARAMETERS, sample_rng};
use sepval_predict::simulate::{self, GridTrajectory};
use sepval_predict::{ClearanceSettings, PredictError, Sampler, Source, clearance, reach};
use sepval_solve::run::{NoProgress, Progress as Step, ProgressObserver};

use crate::CampaignError;
use crate::joint;
use crate::rivals;
use crate::state::{Assessed, State, spread};

pub use sepval_common::evaluation::StartEvaluator;

/// What a round believes: the factors' distribution (the prior's, or the diagnosis's answer's
/// with its rivals) and the model form at the releases.
pub struct Model {
    /// The free parameters (the 17 factors).
    pub space: ParamSpace,
    /// Their distribution.
    pub distribution: ParameterDistribution,
    /// The releases flown so far, with the fit of all of them (none: the prior).
    pub fitted: Option<Fitted>,
}

/// The diagnosis of every release flown.
pub struct Fitted {
    /// The diagnosis as `sepval predict` reads it.
    pub source: Source,
    /// Its answer and rivals.
    pub ensemble: Ensemble,
    /// The releases.
    pub job: Job,
}

impl Model {
    /// The conditions of the releases flown.
    pub fn flown(&self) -> Vec<Flight> {
        self.fitted.as_ref().map_or_else(Vec::new, |f| {
            f.job
                .events()
                .iter()
                .map(|e| e.simulator.scenario().flight.clone())
                .collect()
        })
    }
}

/// How an envelope is assessed.
#[derive(Debug, Clone)]
pub struct AssessSettings {
    /// Samples per condition.
    pub samples: usize,
    /// The seed of the draws.
    pub seed: u64,
    /// Threads of the clearance and the calibration.
    pub threads: usize,
    /// The largest probability of failing at which a condition is cleared.
    pub allowed: f64,
    /// The clearance.
    pub clearance: ClearanceSettings,
}

/// Every condition of `grid` (flown from `base`) assessed with `model`; `observer` hears one
/// step per condition.
pub fn assess(
    model: &Model,
    grid: &Grid,
    base: &Scenario,
    settings: &AssessSettings,
    start: &mut StartEvaluator<'_>,
    observer: &mut dyn ProgressObserver,
) -> Result<Vec<Assessed>, CampaignError> {
    let times = sample_times(base.integrator.t_end_s, base.integrator.rate_hz);
    let points = simulate::Grid::of(&times);
    let (candidates, models) = draws(model, settings)?;
    let noise = model.fitted.as_ref().map(|f| f.source.noise);
    let mut form = FormBand::of(model);
    let mut out = Vec::with_capacity(grid.len());
    observer.start("envelope", Some(grid.len()));
    for k in 0..grid.len() {
        cancel::check()?;
        let scenario = grid.scenario(base, k);
        let (job, runs) = fly(&scenario, &times, &points, &candidates, start)?;
        let ran: Vec<&GridTrajectory> = runs.trajectories.iter().flatten().collect();
        let (sd, r) = form.at(&job, &points, &ran, settings)?;
        let trajectories: Vec<Option<&GridTrajectory>> =
            runs.trajectories.iter().map(|t| t.as_ref().ok()).collect();
        let (seed, threads) = (settings.seed, settings.threads);
        let c = &settings.clearance;
        let full = clearance::assess(c, &trajectories, &sd, &points, seed, threads)?;
        let none = vec![[0.0; 6]; points.len()];
        let (factors, each) =
            clearance::assess_each(c, &trajectories, &none, &points, seed, threads)?;
        let record = ConditionRecord::of(grid.flight(k));
        let row = if full.samples == 0 {
            Row::all_diverged(k, record)
        } else {
            Row::of(k, record, &full)
        };
        out.push(Assessed {
            state: match model.fitted {
                Some(_) => State::of(row.p_fail, settings.allowed),
                None => State::before_release(row.p_fail, settings.allowed),
            },
            reach: r,
            spread_mm: spread(full.min_clearance_mm.p5, full.min_clearance_mm.p95),
            factor_spread_mm: spread(factors.min_clearance_mm.p5, factors.min_clearance_mm.p95),
            rival_spread_mm: rivals::clearance_spread(&models, &each),
            rival_separation: noise.map_or(0.0, |n| rivals::separation(&models, &trajectories, n)),
            joint: joint::samples(&trajectories, &each, noise.unwrap_or(joint::PRIOR_NOISE)),
            row,
        });
        observer.progress(&Step {
            step: k + 1,
            steps: Some(grid.len()),
            evaluations: ((k + 1) * candidates.len()) as u64,
            best: [f64::NAN; 2],
        });
    }
    observer.finish();
    Ok(out)
}

/// The release of `scenario` at `times` (its job) and `candidates` flown there through an
/// evaluator started for it, at the band's `points`.
pub(crate) fn fly(
    scenario: &Scenario,
    times: &[f64],
    points: &simulate::Grid,
    candidates: &[Candidate],
    start: &mut StartEvaluator<'_>,
) -> Result<(Job, simulate::Runs), CampaignError> {
    let job = simulate::release_job(scenario, times, "campaign")
        .map_err(|e| condition(simulate::SimulateError::from(e).into()))?;
    let mut evaluator = start(Arc::new(job.clone())).map_err(CampaignError::from_eval)?;
    let runs = simulate::run_candidates(
        evaluator.as_mut(),
        candidates.len(),
        &|i| candidates[i],
        points,
        &mut NoProgress,
    )
    .map_err(|e| condition(e.into()))?;
    Ok((job, runs))
}

/// The samples' candidates and the model each was drawn from (0: the answer, or the prior):
/// draw s from its own generator; with releases flown, its model chosen among the diagnosis's
/// answer and rivals by their weights first ([`sepval_predict::Sampler`]).
pub(crate) fn draws(
    model: &Model,
    settings: &AssessSettings,
) -> Result<(Vec<Candidate>, Vec<usize>), CampaignError> {
    if let Some(f) = &model.fitted {
        let sampler = Sampler {
            answer: model.distribution.clone(),
            seed: settings.seed,
        };
        return Ok((0..settings.samples)
            .map(|s| {
                let sample = sampler.sample(&f.ensemble, s as u64);
                (sample.candidate, sample.model)
            })
            .unzip());
    }
    let candidates = (0..settings.samples)
        .map(|s| {
            let mut rng = sample_rng(settings.seed, s as u64, STREAM_PARAMETERS);
            let x = model.distribution.draw(&mut rng);
            model.space.candidate(&x).map_err(CampaignError::Model)
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((candidates, vec![0; settings.samples]))
}

/// The model-form band of a round at a release: the diagnosis's discrepancy calibrated on its
/// releases (none for the prior), widened with the release's reach beyond what the releases
/// held out in turn cover ([`sepval_predict::reach`]). The held-out evidence is computed once,
/// at the first release asked for, and kept.
pub(crate) struct FormBand<'m> {
    model: &'m Model,
    flown: Vec<Flight>,
    covered: f64,
    evidence: Option<Evidence>,
}

impl<'m> FormBand<'m> {
    pub(crate) fn of(model: &'m Model) -> FormBand<'m> {
        let flown = model.flown();
        let refs: Vec<&Flight> = flown.iter().collect();
        let covered = sepval_run::domain::covered_reach(&refs, &[]);
        FormBand {
            model,
            flown,
            covered,
            evidence: None,
        }
    }

    /// The band's standard deviation at each of `points` of the release `job` (its first
    /// event's condition), `ran` the samples flown there, and the release's reach.
    pub(crate) fn at(
        &mut self,
        job: &Job,
        points: &simulate::Grid,
        ran: &[&GridTrajectory],
        settings: &AssessSettings,
    ) -> Result<(Vec<[f64; 6]>, f64), CampaignError> {
        let mut sd = match &self.model.fitted {
            None => vec![[0.0; 6]; points.len()],
            Some(f) => {
                let cal = calibration(f, job, settings);
                if self.evidence.is_none() {
                    let ev = discrepancy::evidence(&cal).map_err(|e| condition(e.into()))?;
                    self.evidence = Some(ev);
                }
                let ev = self.evidence.as_ref().expect("computed above");
                discrepancy::carry(&cal, ev, points)
                    .map_err(|e| condition(e.into()))?
                    .sd
            }
        };
        let refs: Vec<&Flight> = self.flown.iter().collect();
        let flight = &job.events()[0].simulator.scenario().flight;
        let r = reach::uncovered(sepval_run::domain::reach(&refs, flight), self.covered);
        reach::widen(&mut sd, &reach::motion(ran), r);
        Ok((sd, r))
    }
}

/// The calibration of the diagnosis's discrepancy at the release of `job`.
fn calibration<'a>(f: &'a Fitted, job: &'a Job, s: &AssessSettings) -> Calibration<'a> {
    Calibration {
        answer: f.ensemble.answer(),
        identifiability: &f.source.identifiability,
        fitted: &f.job,
        held_out: &[],
        target: &job.events()[0],
        noise: f.source.noise,
        threads: s.threads,
        seed: s.seed,
    }
}

fn condition(e: PredictError) -> CampaignError {
    CampaignError::Condition(Box::new(e))
}
