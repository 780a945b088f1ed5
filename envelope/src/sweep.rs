//! The sweep: every condition of the grid predicted with its clearance, in grid order, each
//! through an evaluator started for it (a condition is one release, so its job is its own; the
//! evaluator may be in process, iceoryx2 workers or zenoh hosts). The model-form evidence of
//! the held-out releases does not depend on the condition and is computed once
//! ([`sepval_predict::discrepancy::evidence`]); each condition carries it to itself. After
//! every condition the rows done are saved ([`crate::progress`]), and a signal stops the sweep
//! between conditions or inside one, losing at most the condition under way.

use std::path::PathBuf;
use std::sync::Arc;

use sepval_common::evaluation::{EvalError, Event, Job};
use sepval_core::cancel;
use sepval_predict::discrepancy::{self, Evidence};
use sepval_predict::{ClearanceSettings, PredictError, Settings, Source, predict_with, prepare};
use sepval_solve::run::{NoProgress, Progress as Step, ProgressObserver};

use crate::grid::Grid;
use crate::progress::{Progress, ProgressError};
use crate::row::Row;
use sepval_predict::record::ConditionRecord;

/// A sweep that could not be completed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SweepError {
    /// A condition's prediction.
    #[error("the prediction at Mach {mach}, altitude {altitude_m} m")]
    Predict {
        /// Mach.
        mach: f64,
        /// Altitude \[m\].
        altitude_m: f64,
        /// Why.
        #[source]
        source: Box<PredictError>,
    },
    /// An evaluator that could not be started.
    #[error("cannot start the evaluator")]
    Start(#[source] EvalError),
    /// The progress file.
    #[error(transparent)]
    Progress(#[from] ProgressError),
    /// A signal asked the process to stop.
    #[error("interrupted by a signal (the conditions done are saved: --resume goes on)")]
    Interrupted,
}

/// What a sweep needs.
pub struct Sweep {
    /// The fit or diagnosis predicted from.
    pub source: Source,
    /// Its releases.
    pub fitted: Job,
    /// Releases held out of its fit.
    pub held_out: Vec<Event>,
    /// The prediction's settings (samples, seed, level, threads).
    pub settings: Settings,
    /// The grid.
    pub grid: Grid,
    /// The clearance.
    pub clearance: ClearanceSettings,
    /// Where the rows done are saved.
    pub progress_path: PathBuf,
}

pub use sepval_common::evaluation::StartEvaluator;

/// What a sweep found.
#[derive(Debug, Clone)]
pub struct Swept {
    /// One row per condition, in grid order.
    pub rows: Vec<Row>,
    /// Simulations run by this process's sweep (the conditions resumed from not included).
    pub evaluations: u64,
    /// Conditions done before (resumed).
    pub resumed: usize,
}

/// Runs the sweep from `progress` (empty, or the rows of an interrupted sweep of the same
/// inputs), saving it after every condition; `observer` hears one step per condition.
pub fn sweep(
    s: &Sweep,
    mut progress: Progress,
    start: &mut StartEvaluator<'_>,
    observer: &mut dyn ProgressObserver,
) -> Result<Swept, SweepError> {
    let base = s.fitted.events()[0].simulator.scenario().clone();
    let n = s.grid.len();
    let resumed = progress.rows.len();
    let mut evaluations = 0;
    let mut evidence: Option<Evidence> = None;
    observer.start("envelope", Some(n));
    for k in 0..n {
        if progress.done(k) {
            continue;
        }
        if cancel::requested() {
            return Err(SweepError::Interrupted);
        }
        let flight = s.grid.flight(k).clone();
        let failed = |source: PredictError| SweepError::Predict {
            mach: flight.mach,
            altitude_m: flight.altitude_m,
            source: Box::new(source),
        };
        let prepared = prepare(
            s.source.clone(),
            s.fitted.clone(),
            s.grid.scenario(&base, k),
            s.held_out.clone(),
            None,
            s.settings,
        )
        .map_err(failed)?
        .with_clearance(s.clearance.clone());
        if evidence.is_none() {
            let ev = discrepancy::evidence(&prepared.calibration())
                .map_err(|e| failed(PredictError::from(e)))?;
            evaluations += ev.evaluations();
            evidence = Some(ev);
        }
        let mut evaluator = start(Arc::new(prepared.job.clone())).map_err(|e| match e {
            EvalError::Interrupted => SweepError::Interrupted,
            e => SweepError::Start(e),
        })?;
        let found = predict_with(
            &prepared,
            evaluator.as_mut(),
            &mut NoProgress,
            evidence.as_ref(),
        );
        drop(evaluator);
        let record = ConditionRecord::of(&flight);
        let row = match found {
            Ok(p) => {
                evaluations += p.evaluations;
                let c = p.clearance.as_ref();
                Row::of(
                    k,
                    record,
                    c.expect("with_clearance makes predict assess it"),
                )
            }
            Err(PredictError::AllDiverged { samples, .. }) => {
                evaluations += samples as u64;
                Row::all_diverged(k, record)
            }
            Err(PredictError::Simulate(e)) if interrupted(&e) => {
                return Err(SweepError::Interrupted);
            }
            Err(e) => return Err(failed(e)),
        };
        progress.rows.push(row);
        progress.write(&s.progress_path)?;
        observer.progress(&Step {
            step: progress.rows.len(),
            steps: Some(n),
            evaluations,
            best: [f64::NAN; 2],
        });
    }
    observer.finish();
    let mut rows = progress.rows;
    rows.sort_by_key(|r| r.index);
    Ok(Swept {
        rows,
        evaluations,
        resumed,
    })
}

/// Whether a simulation error is a signal's.
fn interrupted(e: &sepval_predict::simulate::SimulateError) -> bool {
    matches!(
        e,
        sepval_predict::simulate::SimulateError::Eval(EvalError::Interrupted)
    )
}
