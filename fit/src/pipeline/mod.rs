//! The fit pipeline: the study's hill climber and genetic algorithm on the job's data, each
//! optionally refined to the noise floor by Levenberg-Marquardt, every search run through the
//! one loop of [`sepval_solve::run`] with observers for checkpoints and progress; then how sure each
//! parameter is, what one grid step of each factor does, and DIR/result.json.

mod ga_stage;
mod outputs;

pub use ga_stage::{Checkpointer, GaStage, Probing, refinement_due};
pub use outputs::{resolution_advice, write_fit_figures, write_result};

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use sepval_common::atomic_file::WriteError;
use sepval_common::effects::EffectSet;
use sepval_common::evaluation::{EvalError, Evaluator, Job, Outcome};
use sepval_common::factors::Factors;
use sepval_common::propagator::Observation;

use sepval_report::figures::FigureError;
use sepval_solve::ga::{GaError, GaSearch, GaSettings, update_archive};
use sepval_solve::hill::{HillSearch, HillSettings, HillStop};
use sepval_solve::identifiability::identifiability;
use sepval_solve::lm::{LmResult, LmSettings};
use sepval_solve::run::{Observer, ProgressObserver, RunError, ShowProgress, run};

use crate::checkpoint::{Checkpoint, CheckpointError, InputsRecord};
use crate::method::Method;
use crate::problem::{Evaluate, OnModel};
use crate::refine::ModelLm;
use crate::results::{
    EventInfo, FitResult, FloorInfo, HistoryPoint, MethodResult, RESULT_FORMAT, RunInfo,
};
use crate::sigma::Sigma;
use crate::space::{Noise, ParamSpace};
use outputs::{best_samples_of, first_at_floor, lm_first_at_floor, method_result, refined_member};

/// Everything a fit needs besides the evaluator.
#[derive(Clone)]
pub struct FitOptions {
    /// Searches to run.
    pub method: Method,
    /// GA settings.
    pub ga: GaSettings,
    /// Hill-climber settings.
    pub hill: HillSettings,
    /// Noise levels.
    pub sigma: Sigma,
    /// The true factors (synthetic data), for the report.
    pub truth: Option<Factors>,
    /// Run directory.
    pub out: PathBuf,
    /// A checkpoint to resume from.
    pub resume: Option<Checkpoint>,
    /// Where the inputs came from.
    pub inputs: InputsRecord,
    /// The final refinement (`+lm` methods).
    pub lm: LmSettings,
    /// Refinement attempts during a genetic search (`ga+lm`).
    pub lm_probe: LmSettings,
}

/// The floor is reached when both goals are within this factor of their noise sigma.
pub const FLOOR_FACTOR: f64 = 1.1;

/// A finished fit: the result file's content and the best trajectories for figures.
pub struct FitOutput {
    /// DIR/result.json.
    pub result: FitResult,
    /// Per method, the simulated samples of its best member that the figures draw: the first
    /// event's, every k-th of a long record (the whole trajectories are not kept).
    pub best_plotted: BTreeMap<String, Vec<Observation>>,
    /// The best refined fit (`+lm` methods), with its residuals and Jacobian.
    pub refined: Option<LmResult>,
}

/// Errors of a fit.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FitError {
    /// A directory that cannot be created.
    #[error("cannot create {path}")]
    Dir {
        /// The directory.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A search failed.
    #[error(transparent)]
    Run(#[from] RunError),
    /// Invalid GA settings or state.
    #[error(transparent)]
    Ga(#[from] GaError),
    /// A checkpoint failed.
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    /// A file that cannot be written.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// A figure that cannot be drawn.
    #[error(transparent)]
    Figure(#[from] FigureError),
    /// The fit has no answer.
    #[error("{0}")]
    Failed(String),
}

impl From<EvalError> for FitError {
    fn from(e: EvalError) -> Self {
        FitError::Run(e.into())
    }
}

/// What every stage of a fit shares.
struct Context<'a> {
    options: &'a FitOptions,
    job: Arc<Job>,
    space: ParamSpace,
    weights: [f64; 2],
    noise: Noise,
    floor: FloorInfo,
}

impl Context<'_> {
    fn at_floor(&self, g: [f64; 2]) -> bool {
        g[0] <= self.floor.j_pos_m && g[1] <= self.floor.j_att_deg
    }

    /// The final refinement of a method from `start`.
    fn refine(
        &self,
        evaluator: &mut dyn Evaluator,
        start: &[f64],
        progress: &mut dyn ProgressObserver,
        label: &str,
    ) -> Result<LmResult, FitError> {
        let mut lm = ModelLm::new(
            self.space.clone(),
            Arc::clone(&self.job),
            start,
            self.noise,
            self.options.lm.clone(),
        );
        progress.start(label, Some(self.options.lm.max_iterations));
        let r = run(
            &mut lm,
            &mut Evaluate(evaluator),
            &mut [&mut ShowProgress(&mut *progress)],
        );
        progress.finish();
        r?;
        Ok(lm.finish())
    }
}

/// One method's outcome, ready for the result file.
struct Stage {
    name: String,
    result: MethodResult,
    /// The best member's samples the figures draw.
    plotted: Vec<Observation>,
    refined: Option<LmResult>,
}

/// The hill climber (and its refinement, for `hill+lm`).
fn hill_stage(
    cx: &Context,
    evaluator: &mut dyn Evaluator,
    progress: &mut dyn ProgressObserver,
) -> Result<Stage, FitError> {
    let o = cx.options;
    let t0 = Instant::now();
    let table = *cx.job.factor_table();
    let start = table.clamp(&Factors::NOMINAL).0.to_vec();
    let mut climb = OnModel {
        inner: HillSearch::new(table.0.to_vec(), &start, cx.weights, o.hill.clone()),
        space: cx.space.clone(),
    };
    let name = if o.method.refines() {
        "hill+lm"
    } else {
        "hill"
    };
    progress.start("hill", None);
    let r = run(
        &mut climb,
        &mut Evaluate(evaluator),
        &mut [&mut ShowProgress(&mut *progress)],
    );
    progress.finish();
    r?;
    let r = climb.inner.finish();
    let front = update_archive(&[], &r.visited);
    let history: Vec<HistoryPoint> = r
        .history
        .iter()
        .enumerate()
        .map(|(k, &(evaluations, w, [p, a]))| HistoryPoint {
            step: k,
            evaluations,
            best_j_pos_m: p,
            best_j_att_deg: a,
            best_weighted: w,
        })
        .collect();
    let mut to_floor = first_at_floor(&history, &|g| cx.at_floor(g));
    let stop = match r.stop {
        HillStop::Budget => "budget spent",
        HillStop::LocalOptimum => "local optimum (no downhill step above the minimum)",
        HillStop::StartFailed => {
            let why = match &r.best.outcome {
                Outcome::Diverged { t_s, event } => format!(
                    "it diverges at t = {t_s} s in event `{}`",
                    cx.job.events()[*event].name
                ),
                Outcome::Failed { reason } => reason.clone(),
                Outcome::Goals { .. } => "it was not evaluated".into(),
            };
            return Err(FitError::Failed(format!(
                "the hill climber's start, the nominal factors (clamped to their bounds), does \
                 not simulate: {why}; --method ga or ga+lm start from a random population instead"
            )));
        }
    };
    let (best, rms, samples, refinement, evaluations, refined) = if o.method.refines() {
        let lm = cx.refine(evaluator, &r.best.values, progress, name)?;
        if to_floor.is_none() {
            to_floor = lm_first_at_floor(&lm, r.evaluations, &|g| cx.at_floor(g));
        }
        let (member, rms, samples, refinement) = refined_member(&cx.job, &lm, &r.best, Vec::new())?;
        let evaluations = r.evaluations + lm.evaluations;
        (
            member,
            rms,
            samples,
            Some(refinement),
            evaluations,
            Some(lm),
        )
    } else {
        let (rms, samples) = best_samples_of(&cx.job, &r.best)?;
        (r.best.clone(), rms, samples, None, r.evaluations, None)
    };
    let mut m = method_result(
        &best,
        &front,
        history,
        evaluations,
        t0.elapsed().as_secs_f64(),
        cx.weights,
        rms,
        stop.into(),
    );
    m.evaluations_to_floor = to_floor;
    m.refinement = refinement;
    Ok(Stage {
        name: name.to_string(),
        result: m,
        plotted: samples,
        refined,
    })
}

/// The genetic algorithm (with probes and the final refinement, for `ga+lm`), one checkpoint
/// per generation.
fn ga_stage(
    cx: &Context,
    evaluator: &mut dyn Evaluator,
    progress: &mut dyn ProgressObserver,
) -> Result<Stage, FitError> {
    let o = cx.options;
    let t0 = Instant::now();
    let genes = cx.job.factor_table().0.to_vec();
    let (ga, probes) = match &o.resume {
        Some(c) => (
            GaSearch::resume(o.ga.clone(), cx.weights, genes, c.state.clone())?,
            c.probes.clone(),
        ),
        None => (GaSearch::new(o.ga.clone(), cx.weights, genes)?, Vec::new()),
    };
    let probing = o.method.refines().then(|| Probing {
        lm: o.lm_probe.clone(),
        noise: cx.noise,
        floor: [cx.floor.j_pos_m, cx.floor.j_att_deg],
    });
    let mut stage = GaStage::new(ga, Arc::clone(&cx.job), cx.weights, probing, probes);
    let mut checkpoints = Checkpointer {
        out: o.out.clone(),
        method: o.method.name().to_string(),
        settings: o.ga.clone(),
        hill: o.hill.clone(),
        sigma: o.sigma.clone(),
        data_sha256: cx.job.data_sha256().to_string(),
        scenario_sha256: cx.job.scenario_sha256().to_string(),
        inputs: o.inputs.clone(),
    };
    progress.start("ga", Some(o.ga.generations));
    let r = {
        let mut observers: [&mut dyn Observer<GaStage>; 2] =
            [&mut checkpoints, &mut ShowProgress(&mut *progress)];
        run(&mut stage, &mut Evaluate(evaluator), &mut observers)
    };
    progress.finish();
    r?;
    let (state, probes, reached) = stage.finish();
    let state = state.ok_or_else(|| FitError::Failed("the genetic search did not start".into()))?;
    let stop = match &reached {
        Some(_) => format!(
            "refinement after generation {} reached the noise floor",
            state.generation
        ),
        None => format!("{} generations", state.generation),
    };
    let best = state.best(cx.weights).cloned().ok_or_else(|| {
        FitError::Failed("no member of the final population finished its simulation".into())
    })?;
    let history: Vec<HistoryPoint> = state
        .history
        .iter()
        .map(|h| HistoryPoint {
            step: h.generation,
            evaluations: h.evaluations,
            best_j_pos_m: h.best_j_pos_m,
            best_j_att_deg: h.best_j_att_deg,
            best_weighted: h.best_weighted,
        })
        .collect();
    let probe_evals: u64 = probes.iter().map(|p| p.evaluations).sum();
    let mut to_floor = first_at_floor(&history, &|g| cx.at_floor(g));
    let name = if o.method.refines() { "ga+lm" } else { "ga" };
    let (member, rms, samples, refinement, evaluations, refined) = if o.method.refines() {
        // Simulations before the refinement that counts (search and earlier attempts), and in
        // all.
        let (lm, before, total) = match reached {
            Some((lm, before)) => (lm, before, state.evaluations + probe_evals),
            None => {
                let before = state.evaluations + probe_evals;
                let lm = cx.refine(evaluator, &best.values, progress, name)?;
                let total = before + lm.evaluations;
                (lm, before, total)
            }
        };
        if to_floor.is_none() {
            to_floor = lm_first_at_floor(&lm, before, &|g| cx.at_floor(g));
        }
        let (member, rms, samples, refinement) =
            refined_member(&cx.job, &lm, &best, probes.clone())?;
        (member, rms, samples, Some(refinement), total, Some(lm))
    } else {
        let (rms, samples) = best_samples_of(&cx.job, &best)?;
        (best.clone(), rms, samples, None, state.evaluations, None)
    };
    let mut m = method_result(
        &member,
        &state.archive,
        history,
        evaluations,
        t0.elapsed().as_secs_f64(),
        cx.weights,
        rms,
        stop,
    );
    m.evaluations_to_floor = to_floor;
    m.refinement = refinement;
    Ok(Stage {
        name: name.to_string(),
        result: m,
        plotted: samples,
        refined,
    })
}

/// Runs the fit and writes DIR/result.json (and a checkpoint per GA generation). `progress`
/// hears every search's steps.
pub fn run_fit(
    options: &FitOptions,
    evaluator: &mut dyn Evaluator,
    progress: &mut dyn ProgressObserver,
) -> Result<FitOutput, FitError> {
    let start = Instant::now();
    let generations = options.out.join("generations");
    std::fs::create_dir_all(&generations).map_err(|source| FitError::Dir {
        path: generations,
        source,
    })?;
    let job = Arc::clone(evaluator.job());
    let noise = Noise {
        pos_m: options.sigma.pos_m,
        att_deg: options.sigma.att_deg,
    };
    let cx = Context {
        options,
        space: ParamSpace::new(job.factor_table(), &EffectSet::NONE),
        job,
        weights: options.sigma.weights(),
        noise,
        floor: FloorInfo {
            j_pos_m: FLOOR_FACTOR * noise.pos_m,
            j_att_deg: FLOOR_FACTOR * noise.att_deg,
        },
    };
    let mut stages = Vec::new();
    if options.method.runs_hill() {
        stages.push(hill_stage(&cx, evaluator, progress)?);
    }
    if options.method.runs_ga() {
        stages.push(ga_stage(&cx, evaluator, progress)?);
    }
    let mut methods = BTreeMap::new();
    let mut best_plotted = BTreeMap::new();
    let mut refined: Vec<LmResult> = Vec::new();
    for s in stages {
        best_plotted.insert(s.name.clone(), s.plotted);
        refined.extend(s.refined);
        methods.insert(s.name, s.result);
    }

    // How sure the parameters are, at the best refined fit.
    let best_refined = refined.into_iter().min_by(|a, b| a.cost.total_cmp(&b.cost));
    let job = &cx.job;
    let event_samples: Vec<usize> = job.events().iter().map(|e| e.data.len()).collect();
    let identifiability = best_refined.as_ref().map(|lm| {
        identifiability(
            &cx.space.params,
            &lm.x,
            &lm.residuals,
            &lm.jacobian,
            &event_samples,
        )
    });
    // What one grid step of each factor does at the best fit.
    let best = methods
        .values()
        .min_by(|a, b| a.best.weighted.total_cmp(&b.best.weighted))
        .map(|m| m.best.factors);
    let resolution = match best {
        Some(f) => resolution_advice(evaluator, job.factor_table(), &f, noise)?,
        None => Vec::new(),
    };

    let result = FitResult {
        format: RESULT_FORMAT.to_string(),
        events: job
            .events()
            .iter()
            .map(|e| EventInfo {
                name: e.name.clone(),
                samples: e.data.len(),
                tables_left: match best {
                    Some(f) if e.simulator.model().tables.any() => e
                        .simulator
                        .simulate_logged(&f, &EffectSet::NONE, &e.data.times_s)
                        .map(|(_, log)| e.simulator.table_excursions(&log))
                        .unwrap_or_default(),
                    _ => Vec::new(),
                },
            })
            .collect(),
        data_sha256: job.data_sha256().to_string(),
        scenario_sha256: job.scenario_sha256().to_string(),
        sigma_pos_m: options.sigma.pos_m,
        sigma_att_deg: options.sigma.att_deg,
        sigma_source: options.sigma.source.clone(),
        truth: options.truth,
        floor: cx.floor.clone(),
        methods,
        identifiability,
        resolution,
        run: RunInfo {
            evaluator: evaluator.describe(),
            wall_s: start.elapsed().as_secs_f64(),
            version: env!("CARGO_PKG_VERSION").to_string(),
        },
    };
    write_result(&options.out, &result)?;
    Ok(FitOutput {
        result,
        best_plotted,
        refined: best_refined,
    })
}
