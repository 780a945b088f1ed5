//! What a fit reports: each method's result (best member, Pareto front, history, per-channel
//! residuals), what one grid step of each factor does at the best fit, and the results file (the
//! figures are in `figures.rs`).

use std::path::Path;
use std::sync::Arc;

use sepval_common::evaluation::{Candidate, Evaluator, Job, Outcome};
use sepval_common::goals::GoalSums;
use sepval_common::model::StateVector;
use sepval_common::propagator::{Observation, SampleSink, propagate};
use sepval_core::factors::{FACTOR_COUNT, Factors};

use super::FitError;
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
        .find(|h| at_floor(h.best.goals()))
        .map(|h| h.best.evaluations)
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

/// A method's best member as the result file and the figures carry it.
pub(super) struct Carried {
    /// The member (refined, for `+lm` methods).
    pub member: Member,
    /// Its RMS residual per channel.
    pub channel_rms: ChannelRms,
    /// Its samples the figures draw.
    pub plotted: Vec<Observation>,
    /// The refinement record (`+lm` methods).
    pub refinement: Option<Refinement>,
}

/// The refined member, its channel summary and plotted samples (simulated again here, as for
/// a search's best member), and the refinement record.
pub(super) fn refined_member(
    job: &Job,
    lm: &LmResult,
    start: &Member,
    probes: Vec<Probe>,
) -> Result<Carried, FitError> {
    let values = lm.x[..FACTOR_COUNT].to_vec();
    let member = Member {
        chromosome: sepval_core::encoding::Chromosome::encode_values(
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
    Ok(Carried {
        member,
        channel_rms: rms,
        plotted,
        refinement: Some(refinement),
    })
}

/// Why the best member's simulation did not finish when it was run again for the outputs.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Unfinished {
    /// Its factors do not make a model.
    #[error(transparent)]
    Model(#[from] sepval_common::model::ModelError),
    /// It diverged.
    #[error("diverged at t = {t_s} s (event {event})")]
    Diverged {
        /// When \[s\].
        t_s: f64,
        /// In which event.
        event: usize,
    },
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
) -> Result<(), Unfinished> {
    struct Each<'a, F>(&'a mut F, usize);
    impl<F: FnMut(usize, usize, &Observation)> SampleSink for Each<'_, F> {
        #[inline]
        fn record(&mut self, index: usize, obs: &Observation, _x: &StateVector) {
            (self.0)(self.1, index, obs);
        }
    }
    for (k, event) in job.events().iter().enumerate() {
        let run = c.run_setup(&event.simulator)?;
        propagate(
            event.simulator.model(),
            &run,
            &event.data.times_s,
            &mut Each(&mut record, k),
        )
        .map_err(|d| Unfinished::Diverged {
            t_s: d.t_s,
            event: k,
        })?;
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
    table: &sepval_core::factors::FactorTable,
    factors: &Factors,
    noise: Noise,
) -> Result<Vec<ResolutionRow>, FitError> {
    use sepval_core::factors::Factor;
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
    .map_err(FitError::BestUnfinished)?;
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

/// Most samples of one series a trajectory figure draws.
const MAX_PLOTTED_SAMPLES: usize = 20_000;

/// Every how many samples a trajectory figure draws the first event (a figure has about a
/// thousand pixels across: a long record is thinned to at most [`MAX_PLOTTED_SAMPLES`]).
pub(super) fn plot_stride(job: &Job) -> usize {
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
    .map_err(FitError::BestNotReproduced)?;
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
    sepval_run::sealed::write_record(&dir.join("result.json"), result)?;
    Ok(())
}
