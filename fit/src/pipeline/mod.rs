//! The fit pipeline: the study's hill climber and genetic algorithm on the job's data, each
//! optionally refined to the noise floor by Levenberg-Marquardt, every search run through the
//! one loop of [`sepval_solve::run`] with observers for checkpoints and progress; then how sure each
//! parameter is, what one grid step of each factor does, and DIR/result.json.

mod figures;
mod ga_stage;
mod outputs;
mod searches;

pub use figures::write_fit_figures;
pub use ga_stage::{Checkpointer, GaStage, Probing, refinement_due};
pub use outputs::{Unfinished, resolution_advice, write_result};

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::{Candidate, EvalError, Evaluation, Evaluator, Job};
use sepval_common::propagator::Observation;
use sepval_core::atomic_file::WriteError;
use sepval_core::factors::Factors;

use sepval_report::figures::FigureError;
use sepval_solve::ga::{GaError, GaSettings};
use sepval_solve::hill::HillSettings;
use sepval_solve::identifiability::{Identifiability, identifiability};
use sepval_solve::lm::{LmResult, LmSettings};
use sepval_solve::run::{Observer, ProgressObserver, RunError, ShowProgress, Solver, run};

use crate::checkpoint::{Checkpoint, CheckpointError};
use crate::method::Method;
use crate::problem::Evaluate;
use crate::refine::ModelLm;
use crate::results::{
    EventInfo, FitResult, FloorInfo, MethodResult, RESULT_FORMAT, ResolutionRow, RunInfo,
};
use crate::sigma::Sigma;
use crate::space::{Noise, ParamSpace};
use searches::MethodDone;
use sepval_run::clearance::ClearReleases;
use sepval_run::inputs::InputsRecord;

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
    /// The clearance of the best fit's releases (`--aircraft`), found before result.json is
    /// written and recorded in it (`clearance`); none for a baseline.
    pub clearance: Option<Arc<dyn ClearReleases>>,
    /// Refuse, before result.json is written, a best fit that leaves a scenario table
    /// (`--strict-tables`).
    pub strict_tables: bool,
}

impl FitOptions {
    /// The baseline fit a diagnosis, an update and a campaign's round start from: the study's
    /// GA with `ga`, then Levenberg-Marquardt with `lm` (the GA's probes refined within 800
    /// simulations), written to `out`.
    pub fn baseline(
        ga: GaSettings,
        sigma: Sigma,
        lm: &LmSettings,
        out: &std::path::Path,
        inputs: InputsRecord,
    ) -> FitOptions {
        FitOptions {
            method: Method::GaLm,
            ga,
            hill: HillSettings::default(),
            sigma,
            truth: None,
            out: out.to_path_buf(),
            resume: None,
            inputs,
            lm: lm.clone(),
            lm_probe: LmSettings {
                budget: lm.budget.min(800),
                ..LmSettings::default()
            },
            clearance: None,
            strict_tables: false,
        }
    }
}

/// The baseline search of a command that fits before it works (diagnose, update): its
/// genetic search, the LM budget of its refinement, and the noise levels given (any not given
/// is estimated from the releases).
#[derive(Debug, Clone)]
pub struct BaselineSearch {
    /// The genetic search.
    pub ga: GaSettings,
    /// The refinement's budget of simulations.
    pub lm_budget: u64,
    /// `--sigma-pos-m`.
    pub sigma_pos_m: Option<f64>,
    /// `--sigma-att-deg`.
    pub sigma_att_deg: Option<f64>,
}

impl BaselineSearch {
    /// The options of the baseline fit of `job` (its record `inputs`) into `out`, and the
    /// refinement's settings (the stages after the baseline refine with them too); the GA's
    /// settings and the noise levels are checked.
    pub fn options(
        &self,
        job: &Job,
        out: &std::path::Path,
        inputs: InputsRecord,
    ) -> Result<(FitOptions, LmSettings), FitError> {
        self.ga.validate()?;
        let sigma =
            Sigma::resolve(job, self.sigma_pos_m, self.sigma_att_deg).map_err(FitError::Sigma)?;
        let lm = LmSettings {
            budget: self.lm_budget,
            ..LmSettings::default()
        };
        let fit = FitOptions::baseline(self.ga.clone(), sigma, &lm, out, inputs);
        Ok((fit, lm))
    }
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
    /// The releases, the scenario, the extension or the truth's factors that cannot be read.
    #[error(transparent)]
    Inputs(Box<sepval_run::inputs::InputError>),
    /// The checkpoint resumed from does not fit the run asked for.
    #[error(transparent)]
    Resume(#[from] crate::resume::ResumeError),
    /// The noise levels given, or their estimate from the releases.
    #[error("the noise levels that weight the goals (--sigma-pos-m, --sigma-att-deg)")]
    Sigma(#[source] crate::sigma::SigmaError),
    /// The figures' directory or a figure in it (or a signal asked the process to stop
    /// between them).
    #[error(transparent)]
    Outputs(#[from] sepval_report::OutputError),
    /// The hill climber's start does not simulate (why: its divergence or failure).
    #[error(
        "the hill climber's start, the nominal factors (clamped to their bounds), does not \
         simulate: {why}; --method ga or ga+lm start from a random population instead"
    )]
    HillStart {
        /// Why it does not.
        why: String,
    },
    /// The best fit left a scenario table and `strict_tables` refuses that: one line per event
    /// and table.
    #[error(
        "--strict-tables: the best fit {} (result.json not written)",
        .0.join("; and ")
    )]
    TablesLeft(Vec<String>),
    /// The clearance of the best fit's releases (`--aircraft`) could not be found.
    #[error(transparent)]
    Clearance(sepval_run::clearance::StageError),
    /// The genetic search ended before its first generation.
    #[error("the genetic search did not start")]
    GaNotStarted,
    /// No member of the final population finished its simulation.
    #[error("no member of the final population finished its simulation")]
    NoFinishedMember,
    /// The best member's simulation did not finish when run for its deviations.
    #[error("the best member did not finish: {0}")]
    BestUnfinished(Unfinished),
    /// The best member's simulation did not finish when run again for its figures.
    #[error("the best member did not finish when re-evaluated: {0}")]
    BestNotReproduced(Unfinished),
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

    /// Runs `solver` to its end on the evaluator, shown to `progress` as `label` (of `steps`
    /// steps, when known) and seen by `watcher` first, when given.
    fn run_shown<S: Solver<Point = Candidate, Value = Evaluation>>(
        &self,
        solver: &mut S,
        evaluator: &mut dyn Evaluator,
        progress: &mut dyn ProgressObserver,
        label: &str,
        steps: Option<usize>,
        watcher: Option<&mut dyn Observer<S>>,
    ) -> Result<(), FitError> {
        progress.start(label, steps);
        let r = {
            let mut shown = ShowProgress(&mut *progress);
            let problem = &mut Evaluate(evaluator);
            match watcher {
                Some(w) => run(solver, problem, &mut [w, &mut shown]),
                None => run(solver, problem, &mut [&mut shown]),
            }
        };
        progress.finish();
        Ok(r?)
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
        let steps = Some(self.options.lm.max_iterations);
        self.run_shown(&mut lm, evaluator, progress, label, steps, None)?;
        Ok(lm.finish())
    }
}

/// What every method run shares, from the options and the evaluator's job.
fn context<'a>(options: &'a FitOptions, job: Arc<Job>) -> Context<'a> {
    let noise = options.sigma.noise();
    Context {
        options,
        space: ParamSpace::new(job.factor_table(), &EffectSet::NONE),
        job,
        weights: options.sigma.weights(),
        noise,
        floor: FloorInfo {
            j_pos_m: FLOOR_FACTOR * noise.pos_m,
            j_att_deg: FLOOR_FACTOR * noise.att_deg,
        },
    }
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
    let cx = context(options, Arc::clone(evaluator.job()));
    let mut done = Vec::new();
    if options.method.runs_hill() {
        done.push(searches::hill(&cx, evaluator, progress)?);
    }
    if options.method.runs_ga() {
        done.push(searches::ga(&cx, evaluator, progress)?);
    }
    let mut methods = BTreeMap::new();
    let mut best_plotted = BTreeMap::new();
    let mut refined: Vec<LmResult> = Vec::new();
    for d in done {
        let MethodDone {
            name,
            result,
            plotted,
            refined: r,
        } = d;
        best_plotted.insert(name.clone(), plotted);
        refined.extend(r);
        methods.insert(name, result);
    }

    // How sure the parameters are, at the best refined fit.
    let best_refined = refined.into_iter().min_by(|a, b| a.cost.total_cmp(&b.cost));
    let identifiability = best_refined.as_ref().map(|lm| how_sure(&cx, lm));
    // What one grid step of each factor does at the best fit.
    let best = methods
        .values()
        .min_by(|a, b| a.best.weighted.total_cmp(&b.best.weighted))
        .map(|m| m.best.factors);
    let resolution = match best {
        Some(f) => resolution_advice(evaluator, cx.job.factor_table(), &f, cx.noise)?,
        None => Vec::new(),
    };
    let found = Found {
        methods,
        identifiability,
        resolution,
        best,
    };
    let mut result = fit_result(&cx, found, evaluator.describe(), start);
    let left = result.tables_left();
    if options.strict_tables && !left.is_empty() {
        return Err(FitError::TablesLeft(left));
    }
    if let (Some(stage), Some(best)) = (&options.clearance, best) {
        let candidate = Candidate::baseline(best);
        let of = stage.releases(evaluator.job(), candidate, &options.out);
        result.clearance = Some(of.map_err(FitError::Clearance)?);
    }
    write_result(&options.out, &result)?;
    Ok(FitOutput {
        result,
        best_plotted,
        refined: best_refined,
    })
}

/// How sure each parameter of the refined fit `lm` is.
fn how_sure(cx: &Context, lm: &LmResult) -> Identifiability {
    let event_samples: Vec<usize> = cx.job.events().iter().map(|e| e.data.len()).collect();
    identifiability(
        &cx.space.params,
        &lm.x,
        &lm.residuals,
        &lm.jacobian,
        &event_samples,
    )
}

/// What the fit found, for the result file.
struct Found {
    methods: BTreeMap<String, MethodResult>,
    identifiability: Option<Identifiability>,
    resolution: Vec<ResolutionRow>,
    /// The best factors of all methods.
    best: Option<Factors>,
}

/// DIR/result.json's content: the events (with the tables the best fit left), the inputs'
/// hashes and noise, what the fit found and how it ran (`describe`: the evaluator).
fn fit_result(cx: &Context, found: Found, describe: String, start: Instant) -> FitResult {
    let (job, options) = (&cx.job, cx.options);
    FitResult {
        format: RESULT_FORMAT.to_string(),
        events: job
            .events()
            .iter()
            .map(|e| EventInfo {
                name: e.name.clone(),
                samples: e.data.len(),
                tables_left: match found.best {
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
        methods: found.methods,
        identifiability: found.identifiability,
        resolution: found.resolution,
        inputs: Some(options.inputs.clone()),
        clearance: None,
        run: RunInfo {
            evaluator: describe,
            wall_s: start.elapsed().as_secs_f64(),
            version: env!("CARGO_PKG_VERSION").to_string(),
        },
    }
}
