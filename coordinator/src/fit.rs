//! The fit pipeline: the study's genetic algorithm and hill climber on the job's data, with
//! checkpoints, progress and results.

use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use sepval_common::atomic_file::write_atomically;
use sepval_common::evaluation::{Candidate, Evaluator, Job};
use sepval_common::factors::Factors;
use sepval_common::noise::estimate_noise;
use sepval_common::propagator::Observation;

use crate::checkpoint::{CHECKPOINT_FORMAT, Checkpoint, InputsRecord};
use crate::problem::{FactorProblem, factors_of};
use crate::results::{
    Best, ChannelRms, EventInfo, FitResult, FrontPoint, HistoryPoint, MethodResult, RESULT_FORMAT,
    RunInfo, channel_rms, residuals,
};
use crate::search::ga::{Control, GaSettings, GaState, GeneticAlgorithm, Member, update_archive};
use crate::search::hill::{HillSettings, HillStop, climb};

/// Which searches to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// The genetic algorithm.
    Ga,
    /// The hill climber.
    Hill,
    /// Both, as in the study's comparison.
    Both,
}

impl Method {
    /// Parses `ga`, `hill` or `both`.
    pub fn parse(text: &str) -> Result<Method> {
        Ok(match text {
            "ga" => Method::Ga,
            "hill" => Method::Hill,
            "both" => Method::Both,
            other => bail!("--method {other}: expected ga, hill or both"),
        })
    }

    /// The name used in files.
    pub fn name(self) -> &'static str {
        match self {
            Method::Ga => "ga",
            Method::Hill => "hill",
            Method::Both => "both",
        }
    }

    fn runs_ga(self) -> bool {
        matches!(self, Method::Ga | Method::Both)
    }

    fn runs_hill(self) -> bool {
        matches!(self, Method::Hill | Method::Both)
    }
}

/// Noise levels that weight the goals.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Sigma {
    /// Position [m].
    pub pos_m: f64,
    /// Attitude [deg].
    pub att_deg: f64,
    /// Where they came from.
    pub source: String,
}

impl Sigma {
    /// The given sigmas, or those estimated from the data (pooled over events by sample
    /// count) for any not given.
    pub fn resolve(job: &Job, pos_m: Option<f64>, att_deg: Option<f64>) -> Result<Sigma> {
        let mut est = (0.0, 0.0, 0usize);
        for e in job.events() {
            let (p, a) = estimate_noise(&e.data).with_context(|| {
                format!(
                    "event {}: too few samples to estimate the noise; give --sigma-pos-m and --sigma-att-deg",
                    e.name
                )
            })?;
            let n = e.data.len();
            est = (
                est.0 + p * p * n as f64,
                est.1 + a * a * n as f64,
                est.2 + n,
            );
        }
        let n = est.2 as f64;
        let (est_p, est_a) = ((est.0 / n).sqrt(), (est.1 / n).sqrt());
        let pos = pos_m.unwrap_or(est_p);
        let att = att_deg.unwrap_or(est_a);
        for (name, v) in [("sigma_pos_m", pos), ("sigma_att_deg", att)] {
            if !(v.is_finite() && v > 0.0) {
                bail!(
                    "{name} = {v}: the noise level must be a finite number > 0 (data without noise? give --sigma-pos-m and --sigma-att-deg)"
                );
            }
        }
        let source = match (pos_m, att_deg) {
            (Some(_), Some(_)) => "given".to_string(),
            (None, None) => "estimated from the data (second differences)".to_string(),
            _ => "partly given, partly estimated from the data".to_string(),
        };
        Ok(Sigma {
            pos_m: pos,
            att_deg: att,
            source,
        })
    }

    /// Weights (1/sigma_pos, 1/sigma_att).
    pub fn weights(&self) -> [f64; 2] {
        [1.0 / self.pos_m, 1.0 / self.att_deg]
    }
}

/// Everything a fit needs besides the evaluator.
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
    /// Show a progress bar (when stderr is a terminal).
    pub progress: bool,
}

/// A finished fit: the result file's content and the best trajectories for figures.
pub struct FitOutput {
    /// DIR/result.json.
    pub result: FitResult,
    /// Per method, the simulated samples of its best member (per event).
    pub best_samples: BTreeMap<String, Vec<Vec<Observation>>>,
}

/// Runs the fit and writes DIR/result.json (and a checkpoint per GA generation).
pub fn run_fit(options: &FitOptions, evaluator: &mut dyn Evaluator) -> Result<FitOutput> {
    let start = Instant::now();
    std::fs::create_dir_all(options.out.join("generations"))
        .with_context(|| format!("cannot create run directory {}", options.out.display()))?;
    let weights = options.sigma.weights();
    let table = *evaluator.job().factor_table();
    let mut methods = BTreeMap::new();
    let mut best_samples = BTreeMap::new();

    if options.method.runs_hill() {
        let t0 = Instant::now();
        let mut problem = FactorProblem::new(evaluator);
        let start_values = table.clamp(&Factors::NOMINAL).0.to_vec();
        let r = climb(&mut problem, &start_values, weights, &options.hill)?;
        let front = update_archive(&[], &r.visited);
        let history = r
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
        let wall_s = t0.elapsed().as_secs_f64();
        let (rms, samples) = best_samples_of(evaluator, &r.best)?;
        best_samples.insert("hill".to_string(), samples);
        let stop = match r.stop {
            HillStop::Budget => "budget spent",
            HillStop::LocalOptimum => "local optimum (no downhill step above the minimum)",
            HillStop::StartFailed => "the start did not simulate",
        };
        methods.insert(
            "hill".to_string(),
            method_result(
                &r.best,
                &front,
                history,
                r.evaluations,
                wall_s,
                weights,
                rms,
                stop.into(),
            ),
        );
    }

    if options.method.runs_ga() {
        let t0 = Instant::now();
        let ga = GeneticAlgorithm::new(options.ga.clone(), weights)?;
        let job = evaluator.job();
        let job_hashes = (
            job.data_sha256().to_string(),
            job.scenario_sha256().to_string(),
        );
        let bar = progress_bar(options.progress, options.ga.generations as u64);
        let resume_state = options.resume.as_ref().map(|c| c.state.clone());
        if let Some(s) = &resume_state {
            bar.set_position(s.generation as u64);
        }
        let mut problem = FactorProblem::new(evaluator);
        let mut observe = |state: &GaState| -> Result<Control> {
            let checkpoint = Checkpoint {
                format: CHECKPOINT_FORMAT.to_string(),
                method: options.method.name().to_string(),
                settings: options.ga.clone(),
                hill: options.hill.clone(),
                sigma: options.sigma.clone(),
                data_sha256: job_hashes.0.clone(),
                scenario_sha256: job_hashes.1.clone(),
                inputs: options.inputs.clone(),
                state: state.clone(),
            };
            checkpoint.save(&Checkpoint::path(&options.out, state.generation))?;
            let h = state
                .history
                .last()
                .expect("every state has its generation's stats");
            let rate = state.evaluations as f64 / t0.elapsed().as_secs_f64().max(1e-9);
            bar.set_position(state.generation as u64);
            bar.set_message(format!(
                "J_pos {:.4} m  J_att {:.3} deg  {:.0} sims/s",
                h.best_j_pos_m, h.best_j_att_deg, rate
            ));
            Ok(Control::Continue)
        };
        let state = ga.run(&mut problem, resume_state, &mut observe)?;
        bar.finish_and_clear();
        let best = state
            .best(weights)
            .cloned()
            .context("no member of the final population finished its simulation")?;
        let front = state.archive.clone();
        let history = state
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
        let wall_s = t0.elapsed().as_secs_f64();
        let (rms, samples) = best_samples_of(evaluator, &best)?;
        best_samples.insert("ga".to_string(), samples);
        let stop = format!("{} generations", state.generation);
        methods.insert(
            "ga".to_string(),
            method_result(
                &best,
                &front,
                history,
                state.evaluations,
                wall_s,
                weights,
                rms,
                stop,
            ),
        );
    }

    let job = evaluator.job();
    let result = FitResult {
        format: RESULT_FORMAT.to_string(),
        events: job
            .events()
            .iter()
            .map(|e| EventInfo {
                name: e.name.clone(),
                samples: e.data.len(),
            })
            .collect(),
        data_sha256: job.data_sha256().to_string(),
        scenario_sha256: job.scenario_sha256().to_string(),
        sigma_pos_m: options.sigma.pos_m,
        sigma_att_deg: options.sigma.att_deg,
        sigma_source: options.sigma.source.clone(),
        truth: options.truth,
        methods,
        run: RunInfo {
            evaluator: evaluator.describe(),
            wall_s: start.elapsed().as_secs_f64(),
            version: env!("CARGO_PKG_VERSION").to_string(),
        },
    };
    write_result(&options.out, &result)?;
    Ok(FitOutput {
        result,
        best_samples,
    })
}

/// Re-evaluates a best member with its samples: its per-channel residual RMS and trajectory.
fn best_samples_of(
    evaluator: &mut dyn Evaluator,
    best: &Member,
) -> Result<(ChannelRms, Vec<Vec<Observation>>)> {
    let batch = [Candidate::baseline(factors_of(&best.values))];
    let e = evaluator.evaluate(&batch, true)?.remove(0);
    let samples = e
        .samples
        .context("the best member did not finish when re-evaluated")?;
    Ok((channel_rms(&residuals(evaluator.job(), &samples)), samples))
}

#[allow(clippy::too_many_arguments)]
fn method_result(
    best: &Member,
    front: &[Member],
    history: Vec<HistoryPoint>,
    evaluations: u64,
    wall_s: f64,
    weights: [f64; 2],
    channel_rms: ChannelRms,
    stop: String,
) -> MethodResult {
    let [j_pos_m, j_att_deg] = best.objectives();
    MethodResult {
        best: Best {
            factors: factors_of(&best.values),
            j_pos_m,
            j_att_deg,
            weighted: weights[0] * j_pos_m + weights[1] * j_att_deg,
            evaluations,
            wall_s,
            channel_rms,
        },
        pareto_front: front
            .iter()
            .map(|m| {
                let [p, a] = m.objectives();
                FrontPoint {
                    factors: factors_of(&m.values),
                    j_pos_m: p,
                    j_att_deg: a,
                }
            })
            .collect(),
        history,
        stop,
    }
}

/// Writes DIR/result.json atomically.
pub fn write_result(dir: &Path, result: &FitResult) -> Result<()> {
    let json = serde_json::to_vec_pretty(result).context("serialising the result")?;
    write_atomically(&dir.join("result.json"), &json)?;
    Ok(())
}

fn progress_bar(enabled: bool, len: u64) -> ProgressBar {
    if !enabled || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("gen {pos:>4}/{len} {wide_bar} {msg}")
            .expect("a valid template"),
    );
    bar
}

/// Writes the fit's figures into DIR/figures: the study's Figures 1-6 (trajectories of the
/// first event against each method's best), Figure 7 (factors beside the truth, when known),
/// the Pareto fronts and the convergence histories. Returns the files written.
pub fn write_fit_figures(dir: &Path, job: &Job, output: &FitOutput) -> Result<Vec<PathBuf>> {
    use crate::figures::{
        Series, convergence_figure, factor_figure, pareto_figure, trajectory_figures,
    };
    use sepval_common::factors::Factor;
    let fig_dir = dir.join("figures");
    std::fs::create_dir_all(&fig_dir)
        .with_context(|| format!("cannot create {}", fig_dir.display()))?;
    let r = &output.result;
    fn label(m: &str) -> String {
        match m {
            "ga" => "genetic algorithm".to_string(),
            "hill" => "hill climber".to_string(),
            other => other.to_string(),
        }
    }
    let first = &job.events()[0];
    let fits: Vec<(String, sepval_common::telemetry::Trajectory)> = output
        .best_samples
        .iter()
        .map(|(m, samples)| {
            let obs = &samples[0];
            let traj = sepval_common::telemetry::Trajectory {
                times_s: first.data.times_s.clone(),
                pos_m: obs.iter().map(|o| o.pos_m).collect(),
                att_deg: obs.iter().map(|o| o.att_deg).collect(),
                ..Default::default()
            };
            (label(m), traj)
        })
        .collect();
    let series: Vec<Series> = fits
        .iter()
        .map(|(l, t)| Series { label: l, traj: t })
        .collect();
    let mut written = trajectory_figures(&fig_dir, &first.data, &series)?;

    let table = job.factor_table();
    let ranges: Vec<(f64, f64)> = table.0.iter().map(|s| (s.min, s.max)).collect();
    let method_values: Vec<(String, Vec<f64>)> = r
        .methods
        .iter()
        .map(|(m, v)| (label(m), v.best.factors.0.to_vec()))
        .collect();
    let methods: Vec<(&str, &[f64])> = method_values
        .iter()
        .map(|(l, v)| (l.as_str(), v.as_slice()))
        .collect();
    let truth = r.truth.map(|t| t.0.to_vec());
    let path = fig_dir.join("fig7_factors.png");
    factor_figure(&path, &Factor::NAMES, &ranges, &methods, truth.as_deref())?;
    written.push(path);

    let fronts_data: Vec<(String, Vec<[f64; 2]>)> = r
        .methods
        .iter()
        .map(|(m, v)| {
            (
                label(m),
                v.pareto_front
                    .iter()
                    .map(|p| [p.j_pos_m, p.j_att_deg])
                    .collect(),
            )
        })
        .collect();
    let fronts: Vec<(&str, &[[f64; 2]])> = fronts_data
        .iter()
        .map(|(l, v)| (l.as_str(), v.as_slice()))
        .collect();
    let path = fig_dir.join("pareto_front.png");
    pareto_figure(&path, &fronts, Some((r.sigma_pos_m, r.sigma_att_deg)))?;
    written.push(path);

    let hist_data: Vec<(String, Vec<(u64, f64)>)> = r
        .methods
        .iter()
        .map(|(m, v)| {
            (
                label(m),
                v.history
                    .iter()
                    .map(|h| (h.evaluations, h.best_weighted))
                    .collect(),
            )
        })
        .collect();
    let hists: Vec<(&str, &[(u64, f64)])> = hist_data
        .iter()
        .map(|(l, v)| (l.as_str(), v.as_slice()))
        .collect();
    let path = fig_dir.join("convergence.png");
    convergence_figure(&path, &hists, Some(2.0))?;
    written.push(path);
    Ok(written)
}
