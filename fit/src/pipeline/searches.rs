//! The two searches of a fit, each ending the same way: the hill climber and the genetic
//! algorithm run to their end ([`hill`], [`ga`]), then their best member is refined (`+lm`
//! methods) or taken as found, simulated again for its channel summary and figures, and written
//! up as the method's result ([`conclude`]).

use std::sync::Arc;
use std::time::Instant;

use sepval_common::evaluation::{Evaluator, Outcome};
use sepval_common::propagator::Observation;
use sepval_core::factors::Factors;
use sepval_solve::best::BestSoFar;
use sepval_solve::ga::{GaSearch, GaState, Member, update_archive};
use sepval_solve::hill::{HillResult, HillSearch, HillStop};
use sepval_solve::lm::LmResult;
use sepval_solve::run::ProgressObserver;

use super::ga_stage::{Checkpointer, GaStage, Probing};
use super::outputs::{
    Carried, best_samples_of, first_at_floor, lm_first_at_floor, method_result, refined_member,
};
use super::{Context, FitError};
use crate::checkpoint::Checkpoint;
use crate::problem::OnModel;
use crate::results::{HistoryPoint, MethodResult, Probe};

/// One method's outcome, ready for the result file.
pub(super) struct MethodDone {
    /// The method's name in the result file (`hill`, `ga+lm`, ...).
    pub name: String,
    pub result: MethodResult,
    /// The best member's samples the figures draw.
    pub plotted: Vec<Observation>,
    /// The final refinement (`+lm` methods).
    pub refined: Option<LmResult>,
}

/// A search at its end, before its best member is refined and written up.
struct SearchEnd<'a> {
    name: &'static str,
    started: Instant,
    best: Member,
    front: &'a [Member],
    history: Vec<HistoryPoint>,
    stop: String,
    /// Simulations of the search and of its probes.
    evaluations: u64,
    /// The probe that reached the floor, with the simulations before it.
    reached: Option<(LmResult, u64)>,
    /// The probes, for the refinement record.
    probes: Vec<Probe>,
}

/// The hill climber (and its refinement, for `hill+lm`).
pub(super) fn hill(
    cx: &Context,
    evaluator: &mut dyn Evaluator,
    progress: &mut dyn ProgressObserver,
) -> Result<MethodDone, FitError> {
    let o = cx.options;
    let started = Instant::now();
    let table = *cx.job.factor_table();
    let start = table.clamp(&Factors::NOMINAL).0.to_vec();
    let mut climb = OnModel {
        inner: HillSearch::new(table.0.to_vec(), &start, cx.weights, o.hill.clone()),
        space: cx.space.clone(),
    };
    cx.run_shown(&mut climb, evaluator, progress, "hill", None, None)?;
    let r = climb.inner.finish();
    let front = update_archive(&[], &r.visited);
    let history: Vec<HistoryPoint> = r
        .history
        .iter()
        .enumerate()
        .map(|(k, &(evaluations, w, [p, a]))| HistoryPoint {
            step: k,
            best: BestSoFar {
                evaluations,
                best_j_pos_m: p,
                best_j_att_deg: a,
                best_weighted: w,
            },
        })
        .collect();
    let stop = hill_stop(cx, &r)?;
    let end = SearchEnd {
        name: if o.method.refines() {
            "hill+lm"
        } else {
            "hill"
        },
        started,
        best: r.best.clone(),
        front: &front,
        history,
        stop: stop.into(),
        evaluations: r.evaluations,
        reached: None,
        probes: Vec::new(),
    };
    conclude(cx, evaluator, progress, end)
}

/// Why the hill climber stopped, or the error of a start that does not simulate.
fn hill_stop(cx: &Context, r: &HillResult) -> Result<&'static str, FitError> {
    match r.stop {
        HillStop::Budget => Ok("budget spent"),
        HillStop::LocalOptimum => Ok("local optimum (no downhill step above the minimum)"),
        HillStop::StartFailed => {
            let why = match &r.best.outcome {
                Outcome::Diverged { t_s, event } => format!(
                    "it diverges at t = {t_s} s in event `{}`",
                    cx.job.events()[*event].name
                ),
                Outcome::Failed { reason } => reason.clone(),
                Outcome::Goals { .. } => "it was not evaluated".into(),
            };
            Err(FitError::HillStart { why })
        }
    }
}

/// The genetic algorithm (with probes and the final refinement, for `ga+lm`), one checkpoint
/// per generation.
pub(super) fn ga(
    cx: &Context,
    evaluator: &mut dyn Evaluator,
    progress: &mut dyn ProgressObserver,
) -> Result<MethodDone, FitError> {
    let o = cx.options;
    let started = Instant::now();
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
    let mut checkpoints = Checkpointer::new(&o.out, checkpoint_template(cx));
    let steps = Some(o.ga.generations);
    cx.run_shown(
        &mut stage,
        evaluator,
        progress,
        "ga",
        steps,
        Some(&mut checkpoints),
    )?;
    let (state, probes, reached) = stage.finish();
    let state = state.ok_or_else(|| FitError::GaNotStarted)?;
    let stop = match &reached {
        Some(_) => format!(
            "refinement after generation {} reached the noise floor",
            state.generation
        ),
        None => format!("{} generations", state.generation),
    };
    let best = state
        .best(cx.weights)
        .cloned()
        .ok_or_else(|| FitError::NoFinishedMember)?;
    // The probes count for `ga+lm` only (a `ga+lm` checkpoint may be resumed as `ga`).
    let evaluations = match o.method.refines() {
        true => state.evaluations + probes.iter().map(|p| p.evaluations).sum::<u64>(),
        false => state.evaluations,
    };
    let end = SearchEnd {
        name: if o.method.refines() { "ga+lm" } else { "ga" },
        started,
        best,
        front: &state.archive,
        history: ga_history(&state),
        stop,
        evaluations,
        reached,
        probes,
    };
    conclude(cx, evaluator, progress, end)
}

/// The GA's history as the result file records it.
fn ga_history(state: &GaState) -> Vec<HistoryPoint> {
    state
        .history
        .iter()
        .map(|h| HistoryPoint {
            step: h.generation,
            best: h.best.clone(),
        })
        .collect()
}

/// What every checkpoint of this fit holds besides the search state and the probes.
fn checkpoint_template(cx: &Context) -> Checkpoint {
    let o = cx.options;
    Checkpointer::template(
        o.method.name(),
        &o.ga,
        &o.hill,
        &o.sigma,
        &cx.job,
        &o.inputs,
    )
}

/// The end every search shares: the best member refined (`+lm` methods: by the probe that
/// reached the floor, or by a final refinement from it) or taken as found, simulated again, and
/// written up with the simulations it took to reach the floor.
fn conclude(
    cx: &Context,
    evaluator: &mut dyn Evaluator,
    progress: &mut dyn ProgressObserver,
    end: SearchEnd,
) -> Result<MethodDone, FitError> {
    let mut to_floor = first_at_floor(&end.history, &|g| cx.at_floor(g));
    let (carried, evaluations, refined) = if cx.options.method.refines() {
        // Simulations before the refinement that counts (search and earlier attempts), and in
        // all.
        let (lm, before, total) = match end.reached {
            Some((lm, before)) => (lm, before, end.evaluations),
            None => {
                let before = end.evaluations;
                let lm = cx.refine(evaluator, &end.best.values, progress, end.name)?;
                let total = before + lm.evaluations;
                (lm, before, total)
            }
        };
        if to_floor.is_none() {
            to_floor = lm_first_at_floor(&lm, before, &|g| cx.at_floor(g));
        }
        let carried = refined_member(&cx.job, &lm, &end.best, end.probes)?;
        (carried, total, Some(lm))
    } else {
        let (channel_rms, plotted) = best_samples_of(&cx.job, &end.best)?;
        let carried = Carried {
            member: end.best,
            channel_rms,
            plotted,
            refinement: None,
        };
        (carried, end.evaluations, None)
    };
    let mut result = method_result(
        &carried.member,
        end.front,
        end.history,
        evaluations,
        end.started.elapsed().as_secs_f64(),
        cx.weights,
        carried.channel_rms,
        end.stop,
    );
    result.evaluations_to_floor = to_floor;
    result.refinement = carried.refinement;
    Ok(MethodDone {
        name: end.name.to_string(),
        result,
        plotted: carried.plotted,
        refined,
    })
}
