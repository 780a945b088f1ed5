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
use crate::identifiability::identifiability;
use crate::problem::{FactorProblem, factors_of};
use crate::refine::{LmResult, LmSettings, Noise, ParamSpace, levenberg_marquardt};
use crate::results::{
    Best, ChannelRms, EventInfo, FitResult, FloorInfo, FrontPoint, HistoryPoint, MethodResult,
    Probe, RESULT_FORMAT, Refinement, ResolutionRow, RunInfo, channel_rms, residuals,
};
use crate::search::ga::{GaSettings, GaState, GeneticAlgorithm, Member, update_archive};
use crate::search::hill::{HillSettings, HillStop, climb};
use sepval_common::goals::residual;

/// Which searches to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// The genetic algorithm.
    Ga,
    /// The hill climber.
    Hill,
    /// Both, as in the study's comparison.
    Both,
    /// The genetic algorithm, then Levenberg-Marquardt refinement to the noise floor.
    GaLm,
    /// The hill climber, then Levenberg-Marquardt refinement.
    HillLm,
}

impl Method {
    /// Parses `ga`, `hill` or `both`.
    pub fn parse(text: &str) -> Result<Method> {
        Ok(match text {
            "ga" => Method::Ga,
            "hill" => Method::Hill,
            "both" => Method::Both,
            "ga+lm" => Method::GaLm,
            "hill+lm" => Method::HillLm,
            other => bail!("--method {other}: expected ga, hill, both, ga+lm or hill+lm"),
        })
    }

    /// The name used in files.
    pub fn name(self) -> &'static str {
        match self {
            Method::Ga => "ga",
            Method::Hill => "hill",
            Method::Both => "both",
            Method::GaLm => "ga+lm",
            Method::HillLm => "hill+lm",
        }
    }

    fn runs_ga(self) -> bool {
        matches!(self, Method::Ga | Method::Both | Method::GaLm)
    }

    fn runs_hill(self) -> bool {
        matches!(self, Method::Hill | Method::Both | Method::HillLm)
    }

    fn refines(self) -> bool {
        matches!(self, Method::GaLm | Method::HillLm)
    }
}

/// Noise levels that weight the goals.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Sigma {
    /// Position \[m\].
    pub pos_m: f64,
    /// Attitude \[deg\].
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
    /// Show a progress bar (when stderr is a terminal).
    pub progress: bool,
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
    /// Per method, the simulated samples of its best member (per event).
    pub best_samples: BTreeMap<String, Vec<Vec<Observation>>>,
    /// The best refined fit (`+lm` methods), with its residuals and Jacobian.
    pub refined: Option<LmResult>,
}

/// Runs the fit and writes DIR/result.json (and a checkpoint per GA generation).
pub fn run_fit(options: &FitOptions, evaluator: &mut dyn Evaluator) -> Result<FitOutput> {
    let start = Instant::now();
    std::fs::create_dir_all(options.out.join("generations"))
        .with_context(|| format!("cannot create run directory {}", options.out.display()))?;
    let weights = options.sigma.weights();
    let table = *evaluator.job().factor_table();
    let noise = Noise {
        pos_m: options.sigma.pos_m,
        att_deg: options.sigma.att_deg,
    };
    let floor = FloorInfo {
        j_pos_m: FLOOR_FACTOR * noise.pos_m,
        j_att_deg: FLOOR_FACTOR * noise.att_deg,
    };
    let at_floor = |g: [f64; 2]| g[0] <= floor.j_pos_m && g[1] <= floor.j_att_deg;
    let space = ParamSpace::new(&table, &sepval_common::effects::EffectSet::NONE);
    let mut methods = BTreeMap::new();
    let mut best_samples = BTreeMap::new();
    let mut refined: Vec<(String, LmResult)> = Vec::new();

    if options.method.runs_hill() {
        let t0 = Instant::now();
        let mut problem = FactorProblem::new(evaluator);
        let start_values = table.clamp(&Factors::NOMINAL).0.to_vec();
        let r = climb(&mut problem, &start_values, weights, &options.hill)?;
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
        let mut to_floor = first_at_floor(&history, &at_floor);
        let stop = match r.stop {
            HillStop::Budget => "budget spent",
            HillStop::LocalOptimum => "local optimum (no downhill step above the minimum)",
            HillStop::StartFailed => "the start did not simulate",
        };
        let name = if options.method.refines() {
            "hill+lm"
        } else {
            "hill"
        };
        let (best, rms, samples, refinement, evaluations) = if options.method.refines() {
            let lm = refine_from(evaluator, &space, &r.best.values, noise, &options.lm)?;
            if to_floor.is_none() {
                to_floor = lm_first_at_floor(&lm, r.evaluations, &at_floor);
            }
            let (member, rms, samples, refinement) =
                refined_member(evaluator, &space, &lm, &r.best, Vec::new());
            refined.push((name.to_string(), lm.clone()));
            (
                member,
                rms,
                samples,
                Some(refinement),
                r.evaluations + lm.evaluations,
            )
        } else {
            let (rms, samples) = best_samples_of(evaluator, &r.best)?;
            (r.best.clone(), rms, samples, None, r.evaluations)
        };
        best_samples.insert(name.to_string(), samples);
        let mut m = method_result(
            &best,
            &front,
            history,
            evaluations,
            t0.elapsed().as_secs_f64(),
            weights,
            rms,
            stop.into(),
        );
        m.evaluations_to_floor = to_floor;
        m.refinement = refinement;
        methods.insert(name.to_string(), m);
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
        let save = |state: &GaState, probes: &[Probe]| -> Result<()> {
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
                probes: probes.to_vec(),
            };
            checkpoint.save(&Checkpoint::path(&options.out, state.generation))?;
            let h = state
                .history
                .last()
                .expect("every state has its generation's stats");
            bar.set_position(state.generation as u64);
            bar.set_message(format!(
                "J_pos {:.4} m  J_att {:.3} deg  {:.0} sims/s",
                h.best_j_pos_m,
                h.best_j_att_deg,
                state.evaluations as f64 / t0.elapsed().as_secs_f64().max(1e-9)
            ));
            Ok(())
        };
        let (mut state, mut probes) = match &options.resume {
            Some(c) => (c.state.clone(), c.probes.clone()),
            None => {
                let s = ga.initialize(&mut FactorProblem::new(evaluator))?;
                save(&s, &[])?;
                (s, Vec::new())
            }
        };
        let mut reached: Option<(LmResult, u64)> = None;
        let stop = loop {
            if state.generation >= options.ga.generations {
                break format!("{} generations", state.generation);
            }
            // ga+lm: when the search stagnates (or on a doubling schedule), try to refine its
            // best member; once a refinement reaches the floor, further generations are
            // pointless.
            if options.method.refines() && refinement_due(&state, &probes) {
                let best = state
                    .best(weights)
                    .cloned()
                    .context("no finished member to refine")?;
                let before: u64 =
                    state.evaluations + probes.iter().map(|p| p.evaluations).sum::<u64>();
                let lm = refine_from(evaluator, &space, &best.values, noise, &options.lm_probe)?;
                let g = lm.goals.as_array();
                probes.push(Probe {
                    generation: state.generation,
                    evaluations_before: before,
                    evaluations: lm.evaluations,
                    goals: g,
                    reached_floor: at_floor(g),
                });
                if at_floor(g) {
                    reached = Some((lm, before));
                    break format!(
                        "refinement after generation {} reached the noise floor",
                        state.generation
                    );
                }
            }
            state = ga.step(&mut FactorProblem::new(evaluator), &state)?;
            save(&state, &probes)?;
        };
        bar.finish_and_clear();
        let best = state
            .best(weights)
            .cloned()
            .context("no member of the final population finished its simulation")?;
        let front = state.archive.clone();
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
        let mut to_floor = first_at_floor(&history, &at_floor);
        let name = if options.method.refines() {
            "ga+lm"
        } else {
            "ga"
        };
        let (best, rms, samples, refinement, evaluations) = if options.method.refines() {
            // Simulations before the refinement that counts (search and earlier attempts),
            // and in all.
            let (lm, before, total) = match reached {
                Some((lm, before)) => (lm, before, state.evaluations + probe_evals),
                None => {
                    let before = state.evaluations + probe_evals;
                    let lm = refine_from(evaluator, &space, &best.values, noise, &options.lm)?;
                    let total = before + lm.evaluations;
                    (lm, before, total)
                }
            };
            if to_floor.is_none() {
                to_floor = lm_first_at_floor(&lm, before, &at_floor);
            }
            let earlier: Vec<Probe> = probes.clone();
            let (member, rms, samples, refinement) =
                refined_member(evaluator, &space, &lm, &best, earlier);
            refined.push((name.to_string(), lm.clone()));
            (member, rms, samples, Some(refinement), total)
        } else {
            let (rms, samples) = best_samples_of(evaluator, &best)?;
            (best.clone(), rms, samples, None, state.evaluations)
        };
        best_samples.insert(name.to_string(), samples);
        let mut m = method_result(
            &best,
            &front,
            history,
            evaluations,
            t0.elapsed().as_secs_f64(),
            weights,
            rms,
            stop,
        );
        m.evaluations_to_floor = to_floor;
        m.refinement = refinement;
        methods.insert(name.to_string(), m);
    }

    // How sure the parameters are, at the best refined fit.
    let best_refined = refined
        .iter()
        .min_by(|a, b| a.1.cost.total_cmp(&b.1.cost))
        .map(|(_, lm)| lm.clone());
    let job = evaluator.job().clone();
    let event_samples: Vec<usize> = job.events().iter().map(|e| e.data.len()).collect();
    let identifiability = best_refined
        .as_ref()
        .map(|lm| identifiability(&space, &lm.x, &lm.residuals, &lm.jacobian, &event_samples));
    // What one grid step of each factor does at the best fit.
    let best_factors = methods
        .values()
        .min_by(|a, b| a.best.weighted.total_cmp(&b.best.weighted))
        .map(|m| m.best.factors);
    let resolution = match best_factors {
        Some(f) => resolution_advice(evaluator, &table, &f, noise)?,
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
            })
            .collect(),
        data_sha256: job.data_sha256().to_string(),
        scenario_sha256: job.scenario_sha256().to_string(),
        sigma_pos_m: options.sigma.pos_m,
        sigma_att_deg: options.sigma.att_deg,
        sigma_source: options.sigma.source.clone(),
        truth: options.truth,
        floor,
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
        best_samples,
        refined: best_refined,
    })
}

/// A refinement is tried during ga+lm when the search has stagnated (the best weighted goal
/// improved by less than 1 % over the last 10 generations) or at generations 10, 20, 40, 80,
/// ..., and at least 10 generations after the previous attempt.
pub fn refinement_due(state: &GaState, probes: &[Probe]) -> bool {
    let g = state.generation;
    if g < 10 || probes.last().is_some_and(|p| g < p.generation + 10) {
        return false;
    }
    let scheduled = (g % 10 == 0) && (g / 10).is_power_of_two();
    let h = &state.history;
    let stagnant = h.len() > 10 && {
        let then = h[h.len() - 11].best_weighted;
        let now = h[h.len() - 1].best_weighted;
        then.is_finite() && (then - now) < 0.01 * then
    };
    scheduled || stagnant
}

fn refine_from(
    evaluator: &mut dyn Evaluator,
    space: &ParamSpace,
    start: &[f64],
    noise: Noise,
    settings: &LmSettings,
) -> Result<LmResult> {
    levenberg_marquardt(evaluator, space, start, noise, settings)
}

/// Simulations at which the history first has both goals at the floor.
fn first_at_floor(history: &[HistoryPoint], at_floor: &dyn Fn([f64; 2]) -> bool) -> Option<u64> {
    history
        .iter()
        .find(|h| at_floor([h.best_j_pos_m, h.best_j_att_deg]))
        .map(|h| h.evaluations)
}

fn lm_first_at_floor(
    lm: &LmResult,
    before: u64,
    at_floor: &dyn Fn([f64; 2]) -> bool,
) -> Option<u64> {
    lm.history
        .iter()
        .find(|(_, g)| at_floor(g.as_array()))
        .map(|(n, _)| before + n)
}

/// The refined member, its channel summary and samples, and the refinement record.
fn refined_member(
    evaluator: &mut dyn Evaluator,
    space: &ParamSpace,
    lm: &LmResult,
    start: &Member,
    probes: Vec<Probe>,
) -> (Member, ChannelRms, Vec<Vec<Observation>>, Refinement) {
    let values = lm.x[..sepval_common::factors::FACTOR_COUNT].to_vec();
    let member = Member {
        chromosome: sepval_common::encoding::Chromosome::encode_values(
            &evaluator.job().factor_table().0,
            &values,
        ),
        values,
        outcome: sepval_common::evaluation::Outcome::Goals {
            j_pos_m: lm.goals.j_pos_m,
            j_att_deg: lm.goals.j_att_deg,
        },
    };
    let _ = space;
    let rms = channel_rms(&residuals(evaluator.job(), &lm.samples));
    let refinement = Refinement {
        start_goals: start.objectives(),
        evaluations: lm.evaluations,
        iterations: lm.iterations,
        stop: lm.stop.clone(),
        probes,
    };
    (member, rms, lm.samples.clone(), refinement)
}

/// One grid step of each factor at `factors` (inward at a bound): the change of the goals and
/// of the simulated trajectory, coarse when the trajectory moves by more than the noise.
pub fn resolution_advice(
    evaluator: &mut dyn Evaluator,
    table: &sepval_common::factors::FactorTable,
    factors: &Factors,
    noise: Noise,
) -> Result<Vec<ResolutionRow>> {
    use sepval_common::factors::Factor;
    let mut batch = vec![Candidate::baseline(*factors)];
    for (i, spec) in table.0.iter().enumerate() {
        let mut f = *factors;
        let step = spec.step();
        f.0[i] = if f.0[i] + step <= spec.max {
            f.0[i] + step
        } else {
            f.0[i] - step
        };
        batch.push(Candidate::baseline(f));
    }
    let out = evaluator.evaluate(&batch, true)?;
    let base = out[0]
        .samples
        .clone()
        .context("the best fit did not simulate")?;
    let g0 = out[0].outcome.objectives();
    let mut rows = Vec::new();
    for (i, e) in out.iter().enumerate().skip(1) {
        let name = Factor::NAMES[i - 1].to_string();
        let step = table.0[i - 1].step();
        let Some(s) = &e.samples else {
            rows.push(ResolutionRow {
                factor: name,
                step,
                d_j_pos_m: f64::INFINITY,
                d_j_att_deg: f64::INFINITY,
                traj_rms_pos_m: f64::INFINITY,
                traj_rms_att_deg: f64::INFINITY,
                coarse: true,
            });
            continue;
        };
        let (mut dp, mut da, mut n) = (0.0, 0.0, 0usize);
        for (ev_a, ev_b) in s.iter().zip(&base) {
            for (a, b) in ev_a.iter().zip(ev_b) {
                let (p, q) = residual(a, &b.pos_m, &b.att_deg);
                dp += p.iter().map(|v| v * v).sum::<f64>();
                da += q.iter().map(|v| v * v).sum::<f64>();
                n += 1;
            }
        }
        let n3 = 3.0 * n.max(1) as f64;
        let (rp, ra) = ((dp / n3).sqrt(), (da / n3).sqrt());
        let g = e.outcome.objectives();
        rows.push(ResolutionRow {
            factor: name,
            step,
            d_j_pos_m: g[0] - g0[0],
            d_j_att_deg: g[1] - g0[1],
            traj_rms_pos_m: rp,
            traj_rms_att_deg: ra,
            coarse: rp > noise.pos_m || ra > noise.att_deg,
        });
    }
    Ok(rows)
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
        evaluations_to_floor: None,
        refinement: None,
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

    if let Some(id) = &r.identifiability {
        let names: Vec<&str> = id.names.iter().map(String::as_str).collect();
        let path = fig_dir.join("correlation.png");
        crate::figures::correlation_figure(
            &path,
            &names,
            &id.correlation,
            "Correlation of the refined estimates (|rho| > 0.9: compensating)",
        )?;
        written.push(path);
    }
    Ok(written)
}
