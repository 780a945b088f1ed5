//! The simulator as users call it: a scenario set up once, then trajectories and goals for
//! factor and effect sets.

use crate::effects::EffectSet;
use crate::goals::{GoalAccumulator, GoalSums, Goals};
use crate::model::flowfield_grid::GridExcursions;
use crate::model::{Model, ModelError, RunSetup, StateVector};
use crate::propagator::{Diverged, Observation, RunLog, SampleSink, propagate};
use crate::scenario::Scenario;
use crate::table::Variable;
use crate::telemetry::Trajectory;
use sepval_core::factors::Factors;

/// Errors of one simulation.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum SimError {
    /// The factors or effects are invalid.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The run diverged.
    #[error(transparent)]
    Diverged(#[from] Diverged),
    /// The sample times ask for more work than one run may do.
    #[error(transparent)]
    Limit(#[from] sepval_core::limits::LimitError),
}

/// A scenario set up for simulation.
#[derive(Debug, Clone)]
pub struct Simulator {
    model: Model,
}

impl Simulator {
    /// Sets up a (validated) scenario.
    pub fn new(scenario: &Scenario) -> Self {
        Simulator {
            model: Model::new(scenario),
        }
    }

    /// The embedded default scenario, set up.
    pub fn embedded_default() -> Self {
        Simulator::new(&Scenario::embedded_default())
    }

    /// The model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The scenario.
    pub fn scenario(&self) -> &Scenario {
        self.model.scenario()
    }

    /// The scenario's telemetry times: 0, 1/rate, ..., t_end.
    pub fn default_times(&self) -> Vec<f64> {
        let n = &self.scenario().integrator;
        sample_times(n.t_end_s, n.rate_hz)
    }

    /// The run of `factors` (checked against the factor table) and `effects`.
    pub fn run_setup(
        &self,
        factors: &Factors,
        effects: &EffectSet,
    ) -> Result<RunSetup, ModelError> {
        RunSetup::new(&self.model, factors, effects)
    }

    /// The run of `factors`, `effects` and extension `terms` (beyond the scenario's own).
    pub fn run_setup_with(
        &self,
        factors: &Factors,
        effects: &EffectSet,
        terms: &crate::extension::TermSet,
    ) -> Result<RunSetup, ModelError> {
        RunSetup::with_terms(&self.model, factors, effects, terms)
    }

    /// Simulates at `times_s` (strictly increasing) and returns the trajectory with its log.
    pub fn simulate_logged(
        &self,
        factors: &Factors,
        effects: &EffectSet,
        times_s: &[f64],
    ) -> Result<(Trajectory, RunLog), SimError> {
        let span = times_s.last().copied().unwrap_or(0.0).max(0.0);
        sepval_core::limits::check_steps(span, self.scenario().integrator.dt_s)?;
        if times_s.len() > sepval_core::limits::MAX_SAMPLES {
            return Err(sepval_core::limits::LimitError::Samples {
                samples: times_s.len() as f64,
            }
            .into());
        }
        let run = self.run_setup(factors, effects)?;
        let mut sink = Reported {
            run: &run,
            samples: Vec::with_capacity(times_s.len()),
            field_grid: GridExcursions::default(),
        };
        let mut log = propagate(&self.model, &run, times_s, &mut sink)?;
        log.field_grid = sink.field_grid;
        let samples = sink.samples;
        let traj = Trajectory {
            times_s: times_s.to_vec(),
            pos_m: samples.iter().map(|o| o.pos_m).collect(),
            att_deg: samples.iter().map(|o| o.att_deg).collect(),
            ..Trajectory::default()
        };
        Ok((traj, log))
    }

    /// The tables a run left (docs/model.md section 3: held at the edge and recorded), named,
    /// from its log; empty for a scenario without tables or a run that stayed inside them.
    /// The flowfield's tables over position count as one table, `flowfield` (section 3b),
    /// counted at the samples.
    pub fn table_excursions(&self, log: &RunLog) -> Vec<crate::table::TableExcursion> {
        let mut out = self.model.tables.report(&log.tables);
        let ex = &log.field_grid;
        if let (Some(grid), true) = (&self.model.field_grid, ex.outside > 0) {
            let axes = [Variable::X, Variable::Y, Variable::Z]
                .into_iter()
                .enumerate()
                .filter_map(|(j, variable)| {
                    let range = grid.range(j)?;
                    (ex.worst_m[j] > 0.0).then(|| crate::table::AxisExcursion {
                        variable: variable.key().to_string(),
                        range,
                        worst_excursion: ex.worst_m[j],
                    })
                })
                .collect();
            out.push(crate::table::TableExcursion {
                table: "flowfield".to_string(),
                evaluations_outside: ex.outside,
                evaluations: ex.samples,
                axes,
                at_samples: true,
            });
        }
        out
    }

    /// Simulates at `times_s` (strictly increasing).
    pub fn simulate(
        &self,
        factors: &Factors,
        effects: &EffectSet,
        times_s: &[f64],
    ) -> Result<Trajectory, SimError> {
        self.simulate_logged(factors, effects, times_s)
            .map(|(t, _)| t)
    }

    /// Goal sums of one run against `measured` (no trajectory is stored).
    pub fn goal_sums(&self, run: &RunSetup, measured: &Trajectory) -> Result<GoalSums, Diverged> {
        let mut acc = GoalAccumulator::new(measured);
        propagate(&self.model, run, &measured.times_s, &mut acc)?;
        Ok(acc.sums)
    }

    /// Goals of `factors` and `effects` against `measured`.
    pub fn goals(
        &self,
        factors: &Factors,
        effects: &EffectSet,
        measured: &Trajectory,
    ) -> Result<Goals, SimError> {
        let run = self.run_setup(factors, effects)?;
        Ok(self.goal_sums(&run, measured)?.goals())
    }
}

/// Telemetry times 0, 1/rate, ..., up to t_end (inclusive within 1e-9 s).
pub fn sample_times(t_end_s: f64, rate_hz: f64) -> Vec<f64> {
    let n = (t_end_s * rate_hz + 1e-9).floor() as usize + 1;
    (0..n).map(|j| j as f64 / rate_hz).collect()
}

/// The sink of a reported run: the samples, and whether the flowfield's points were beyond its
/// grid at them ([`RunLog::field_grid`]).
struct Reported<'a> {
    run: &'a RunSetup,
    samples: Vec<Observation>,
    field_grid: GridExcursions,
}

impl SampleSink for Reported<'_> {
    fn record(&mut self, _index: usize, obs: &Observation, x: &StateVector) {
        self.samples.push(*obs);
        if let Some(f) = &self.run.flowfield
            && let Some(beyond) = f.beyond_grid(x, self.run.aero_reference_x_m)
        {
            self.field_grid.note(beyond);
        }
    }
}
