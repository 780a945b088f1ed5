//! The model-error reconstruction of docs/discovery.md section 11.6 for a fitted model given from
//! outside a diagnosis (`sepval update` chooses its corrections from it): what the fitted
//! candidate lacks, per event, as coefficient increments on time windows with their bands, and
//! what the store saw at each sample along the fitted trajectory.

use nalgebra::{DMatrix, DVector};
use sepval_common::evaluation::{Candidate, Evaluator};
use sepval_common::extension::Term;
use sepval_fit::space::Noise;

use crate::library::{self, Sample};
use crate::probe;
use crate::reconstruct::{Reconstruction, reconstruct_events};
use crate::{DiagnoseError, Result};

/// What a fitted model lacks, reconstructed.
#[derive(Debug, Clone)]
pub struct Misfit {
    /// Per event, what the store saw at each of its samples along the fitted trajectory.
    pub history: Vec<Vec<Sample>>,
    /// Per event, the reconstructed increments.
    pub reconstructions: Vec<Reconstruction>,
    /// The linear model the reconstruction is made of, for regressions on it.
    pub linear: Linear,
    /// Simulations made (the windows' probes).
    pub evaluations: u64,
}

/// The reconstruction's linear model of the residuals about the fitted candidate: r0 + J a +
/// W u, on a subset of the residual rows (every k-th sample, at most 3 000 samples).
#[derive(Debug, Clone)]
pub struct Linear {
    /// Per event, its rows within the matrices: (first, end).
    pub event_rows: Vec<(usize, usize)>,
    /// The normalised residuals at the fitted candidate.
    pub r0: DVector<f64>,
    /// Their sensitivities to the free parameters.
    pub fixed: DMatrix<f64>,
    /// Their sensitivities to each window's increment (per unit).
    pub windows: DMatrix<f64>,
    /// The windows (axis and time span `locator`).
    pub terms: Vec<Term>,
}

/// The misfit of `base` (a fitted candidate of the evaluator's job) reconstructed per event,
/// from its normalised `residuals` over every sample of the job and their `jacobian`, whose
/// columns `free` (the parameters not held at a bound) stay free in the reconstruction so that
/// what they can absorb is not blamed on an increment.
pub fn reconstruct_misfit(
    evaluator: &mut dyn Evaluator,
    base: &Candidate,
    residuals: &[f64],
    jacobian: &DMatrix<f64>,
    free: &[usize],
    noise: Noise,
) -> Result<Misfit> {
    let job = std::sync::Arc::clone(evaluator.job());
    let history = library::flow_history(&job, base);
    if history.iter().any(Vec::is_empty) {
        return Err(DiagnoseError::NotSimulatedAgain);
    }
    let rows = probe::rows(&job);
    let r0 = DVector::from_iterator(rows.len(), rows.iter().map(|&i| residuals[i]));
    let fixed = DMatrix::from_fn(rows.len(), free.len(), |i, c| jacobian[(rows[i], free[c])]);
    let windows = library::windows(&history);
    let win = probe::columns(evaluator, &job, base, &windows, residuals, noise, &rows)?;
    let reconstructions = reconstruct_events(&job, &rows, &r0, &fixed, win.as_view(), &windows);
    Ok(Misfit {
        history,
        reconstructions,
        evaluations: windows.len() as u64,
        linear: Linear {
            event_rows: probe::event_rows(&job, &rows),
            r0,
            fixed,
            windows: win,
            terms: windows,
        },
    })
}
