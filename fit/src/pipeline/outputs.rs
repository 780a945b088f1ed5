//! What a fit reports: each method's result (best member, Pareto front, history, per-channel
//! residuals), what one grid step of each factor does at the best fit, the results file and the
//! figures.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use sepval_common::atomic_file::write_atomically;
use sepval_common::evaluation::{Candidate, Evaluator, Job, Outcome};
use sepval_common::factors::{FACTOR_COUNT, Factors};
use sepval_common::goals::GoalSums;
use sepval_common::model::StateVector;
use sepval_common::propagator::{Observation, SampleSink, propagate};

use super::{FitError, FitOutput};
use crate::problem::factors_of;
use sepval_solve::lm::LmResult;

use crate::results::{
    Best, ChannelRms, ChannelSums, FitResult, FrontPoint, HistoryPoint, MethodResult, Probe,
    Refinement, ResolutionRow,
};
use crate::space::Noise;
use sepval_solve::ga::Member;

/// Simulations at which the history first has both goals at the floor.
pub(super) fn first_at_floor(
    history: &[HistoryPoint],
    at_floor: &dyn Fn([f64; 2]) -> bool,
) -> Option<u64> {
    history
        .iter()
        .find(|h| at_floor([h.best_j_pos_m, h.best_j_att_deg]))
        .map(|h| h.evaluations)
}

pub(super) fn lm_first_at_floor(
    lm: &LmResult,
    before: u64,
    at_floor: &dyn Fn([f64; 2]) -> bool,
) -> Option<u64> {
    lm.history
        .iter()
        .find(|(_, g)| at_floor(g.as_array()))
        .map(|(n, _)| before + n)
}

/// The refined member, its channel summary and plotted samples (simulated again here, as for
/// a search's best member), and the refinement record.
pub(super) fn refined_member(
    job: &Job,
    lm: &LmResult,
    start: &Member,
    probes: Vec<Probe>,
) -> Result<(Member, ChannelRms, Vec<Observation>, Refinement), FitError> {
    let values = lm.x[..FACTOR_COUNT].to_vec();
    let member = Member {
        chromosome: sepval_common::encoding::Chromosome::encode_values(
            &job.factor_table().0,
            &values,
        ),
        values,
        outcome: Outcome::Goals {
            j_pos_m: lm.goals.j_pos_m,
            j_att_deg: lm.goals.j_att_deg,
        },
    };
    let (rms, plotted) = best_samples_of(job, &member)?;
    let refinement = Refinement {
        start_goals: start.objectives(),
        evaluations: lm.evaluations,
        iterations: lm.iterations,
        stop: lm.stop.clone(),
        probes,
    };
    Ok((member, rms, plotted, refinement))
}

/// Simulates `c` on every event of `job` in this process, handing each sample to
/// `record(event, index, observation)` as it is made (no trajectory is stored unless `record`
/// stores it); the reason when a run does not finish.
///
/// The same runs as [`Job::evaluate`] (an evaluation is a pure function of the job and the
/// candidate, whichever evaluator makes it): the outputs after a search compare long
/// trajectories sample by sample here, where the data already is, instead of bringing each one
/// back whole from a worker (two copies of a long record in each process, issue 13).
fn simulate_locally(
    job: &Job,
    c: &Candidate,
    mut record: impl FnMut(usize, usize, &Observation),
) -> Result<(), String> {
    struct Each<'a, F>(&'a mut F, usize);
    impl<F: FnMut(usize, usize, &Observation)> SampleSink for Each<'_, F> {
        #[inline]
        fn record(&mut self, index: usize, obs: &Observation, _x: &StateVector) {
            (self.0)(self.1, index, obs);
        }
    }
    for (k, event) in job.events().iter().enumerate() {
        let run = event
            .simulator
            .run_setup_with(&c.factors, &c.effects, &c.terms)
            .map_err(|e| e.to_string())?;
        propagate(
            event.simulator.model(),
            &run,
            &event.data.times_s,
            &mut Each(&mut record, k),
        )
        .map_err(|d| format!("diverged at t = {} s (event {k})", d.t_s))?;
    }
    Ok(())
}

/// One grid step of each factor at `factors` (inward at a bound): the change of the goals and
/// of the simulated trajectory, coarse when the trajectory moves by more than the noise.
///
/// The trajectory of `factors` is simulated here and held once; each step is simulated here
/// and compared with it (and with the data) sample by sample, so no stepped trajectory is
/// stored or transferred. The base goals come from `evaluator`. Every number is the one an
/// evaluation with samples gives (the step goals pooled over events as such an evaluation
/// pools them).
pub fn resolution_advice(
    evaluator: &mut dyn Evaluator,
    table: &sepval_common::factors::FactorTable,
    factors: &Factors,
    noise: Noise,
) -> Result<Vec<ResolutionRow>, FitError> {
    use sepval_common::factors::Factor;
    let g0 = evaluator.evaluate(&[Candidate::baseline(*factors)], false)?[0]
        .outcome
        .objectives();
    let job = Arc::clone(evaluator.job());
    let mut base: Vec<Vec<Observation>> = job
        .events()
        .iter()
        .map(|e| Vec::with_capacity(e.data.len()))
        .collect();
    simulate_locally(&job, &Candidate::baseline(*factors), |k, _, o| {
        base[k].push(*o)
    })
    .map_err(|e| FitError::Failed(format!("the best member did not finish: {e}")))?;
    let mut rows = Vec::with_capacity(table.0.len());
    for (i, spec) in table.0.iter().enumerate() {
        let mut f = *factors;
        let step = spec.step();
        f.0[i] = if f.0[i] + step <= spec.max {
            f.0[i] + step
        } else {
            f.0[i] - step
        };
        // Against the data (the step's goals) and against the base trajectory.
        let (mut to_data, mut to_base) = (GoalSums::default(), GoalSums::default());
        let ran = simulate_locally(&job, &Candidate::baseline(f), |k, j, o| {
            let d = &job.events()[k].data;
            to_data.add(o, &d.pos_m[j], &d.att_deg[j]);
            let b = &base[k][j];
            to_base.add(o, &b.pos_m, &b.att_deg);
        });
        let g = to_data.goals();
        let name = Factor::NAMES[i].to_string();
        if ran.is_err() || !(g.j_pos_m.is_finite() && g.j_att_deg.is_finite()) {
            // A step that does not finish (or whose goals are beyond f64, a failed run).
            rows.push(ResolutionRow {
                factor: name,
                step,
                d_j_pos_m: None,
                d_j_att_deg: None,
                traj_rms_pos_m: None,
                traj_rms_att_deg: None,
                coarse: true,
            });
            continue;
        }
        let t = to_base.goals();
        let (rp, ra) = (t.j_pos_m, t.j_att_deg);
        rows.push(ResolutionRow {
            factor: name,
            step,
            d_j_pos_m: Some(g.j_pos_m - g0[0]),
            d_j_att_deg: Some(g.j_att_deg - g0[1]),
            traj_rms_pos_m: Some(rp),
            traj_rms_att_deg: Some(ra),
            coarse: rp > noise.pos_m || ra > noise.att_deg,
        });
    }
    Ok(rows)
}

/// Every how many samples a trajectory figure draws the first event (a figure has about a
/// thousand pixels across: a long record is thinned to at most [`MAX_PLOTTED_SAMPLES`]).
fn plot_stride(job: &Job) -> usize {
    job.events()[0]
        .data
        .len()
        .div_ceil(MAX_PLOTTED_SAMPLES)
        .max(1)
}

/// Simulates a best member here: its per-channel residual RMS and the samples the figures
/// draw (the first event's, thinned), without holding its whole trajectory.
pub(super) fn best_samples_of(
    job: &Job,
    best: &Member,
) -> Result<(ChannelRms, Vec<Observation>), FitError> {
    let stride = plot_stride(job);
    let mut plotted = Vec::with_capacity(job.events()[0].data.len().div_ceil(stride));
    let mut rms = ChannelSums::default();
    simulate_locally(
        job,
        &Candidate::baseline(factors_of(&best.values)),
        |k, j, o| {
            let d = &job.events()[k].data;
            rms.add(o, &d.pos_m[j], &d.att_deg[j]);
            if k == 0 && j % stride == 0 {
                plotted.push(*o);
            }
        },
    )
    .map_err(|e| {
        FitError::Failed(format!(
            "the best member did not finish when re-evaluated: {e}"
        ))
    })?;
    Ok((rms.rms(), plotted))
}

#[allow(clippy::too_many_arguments)]
pub(super) fn method_result(
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
pub fn write_result(dir: &Path, result: &FitResult) -> Result<(), FitError> {
    let json = serde_json::to_vec_pretty(result).expect("a result serialises");
    write_atomically(&dir.join("result.json"), &json)?;
    Ok(())
}

/// Most samples of one series a trajectory figure draws.
const MAX_PLOTTED_SAMPLES: usize = 20_000;

/// Writes the fit's figures into DIR/figures: the study's Figures 1-6 (trajectories of the
/// first event against each method's best), Figure 7 (factors beside the truth, when known),
/// the Pareto fronts and the convergence histories. Returns the files written.
pub fn write_fit_figures(
    dir: &Path,
    job: &Job,
    output: &FitOutput,
) -> Result<Vec<PathBuf>, FitError> {
    use sepval_common::factors::Factor;
    use sepval_report::figures::{
        Series, convergence_figure, factor_figure, pareto_figure, trajectory_figures,
    };
    let fig_dir = dir.join("figures");
    std::fs::create_dir_all(&fig_dir).map_err(|source| FitError::Dir {
        path: fig_dir.clone(),
        source,
    })?;
    let r = &output.result;
    fn label(m: &str) -> String {
        match m {
            "ga" => "genetic algorithm".to_string(),
            "hill" => "hill climber".to_string(),
            other => other.to_string(),
        }
    }
    let first = &job.events()[0];
    // A long record is drawn from every k-th sample (a figure has about a thousand pixels
    // across; the plotted copies stay small).
    let stride = plot_stride(job);
    let pick = |n: usize| (0..n).step_by(stride);
    let data = sepval_common::telemetry::Trajectory {
        times_s: pick(first.data.len())
            .map(|k| first.data.times_s[k])
            .collect(),
        pos_m: pick(first.data.len())
            .map(|k| first.data.pos_m[k])
            .collect(),
        att_deg: pick(first.data.len())
            .map(|k| first.data.att_deg[k])
            .collect(),
        ..Default::default()
    };
    let fits: Vec<(String, sepval_common::telemetry::Trajectory)> = output
        .best_plotted
        .iter()
        .map(|(m, plotted)| {
            let traj = sepval_common::telemetry::Trajectory {
                times_s: data.times_s.clone(),
                pos_m: plotted.iter().map(|o| o.pos_m).collect(),
                att_deg: plotted.iter().map(|o| o.att_deg).collect(),
                ..Default::default()
            };
            (label(m), traj)
        })
        .collect();
    let series: Vec<Series> = fits
        .iter()
        .map(|(l, t)| Series { label: l, traj: t })
        .collect();
    let mut written = trajectory_figures(&fig_dir, &data, &series)?;

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
        sepval_report::figures::correlation_figure(
            &path,
            &names,
            &id.correlation,
            "Correlation of the refined estimates (|rho| > 0.9: compensating)",
        )?;
        written.push(path);
    }
    Ok(written)
}
