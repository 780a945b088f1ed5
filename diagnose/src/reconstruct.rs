//! Model-error reconstruction: what force and moment the fitted model lacks, as time histories
//! of body-axis coefficient increments (dCA, dCY, dCZ, dCl, dCm, dCn) and of the ejector force
//! (a fraction of it, during the stroke), with confidence bands.
//!
//! Method: a regularised output-error estimate, linearised about the fit. Each increment is
//! piecewise constant on short windows; the sensitivities of the residuals to each window
//! (`W`) and to the 17 factors (`J`, the fit's own Jacobian) give the linear model
//! r0 + J a + W u of the residuals, and u minimises
//!
//! ```text
//! |r0 + J a + W u|^2 + lambda sum_axis s_axis |D u_axis|^2
//! ```
//!
//! (residuals normalised by the noise; D the first difference, a random-walk prior on each
//! increment; s_axis = the mean information of the axis's windows, so one lambda serves every
//! axis), with lambda chosen by generalised cross-validation (G. H. Golub, M. Heath and G. Wahba,
//! Technometrics 21, 1979). This is the smoother of estimation-before-modelling (augmented-state
//! Kalman filter and Rauch-Tung-Striebel smoother with the increments as random-walk states;
//! J. L. Stalford, "High-alpha aerodynamic model identification of T-2C aircraft using the EBM
//! method", AIAA 81-1846; J. A. Mulder, J. K. Sridhar and J. H. Breeman, AGARD-AG-300 vol. 3,
//! 1994) written as the equivalent penalised least squares: with a Gaussian random-walk prior
//! the two give the same estimate. The bands are +-2 standard deviations of the posterior
//! (J^T J + P)^-1. The factors stay free, so what a factor change can absorb is not blamed on an
//! increment. Each event is reconstructed from its own residuals.

use nalgebra::{DMatrix, DMatrixView, DVector, DVectorView};
use sepval_common::evaluation::Job;
use serde::{Deserialize, Serialize};

use sepval_common::extension::{Axis, Term};

/// One increment's history in one event.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IncrementSeries {
    /// `CA`, `CY`, `CZ`, `Cl`, `Cm`, `Cn` or `ejector` (a fraction of the ejector force).
    pub axis: String,
    /// Window midpoints \[s\].
    pub t_s: Vec<f64>,
    /// The increment in each window.
    pub value: Vec<f64>,
    /// Its standard deviation.
    pub std: Vec<f64>,
}

/// The reconstruction of one event.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Reconstruction {
    /// The event.
    pub event: String,
    /// The regularisation chosen by cross-validation.
    pub lambda: f64,
    /// Effective number of parameters (trace of the hat matrix).
    pub effective_parameters: f64,
    /// Residual RMS (normalised) after the increments.
    pub rms_after: f64,
    /// One series per axis.
    pub increments: Vec<IncrementSeries>,
}

/// One regularisation's solution: (GCV score, lambda, posterior covariance, estimate, trace).
type Solved = (f64, f64, DMatrix<f64>, DVector<f64>, f64);

/// Reconstructs one event from its residual rows `r0`, factor sensitivities `jac` and window
/// sensitivities `win` (columns in the order of `windows`), each a view into the discovery's
/// matrices (no copy).
pub fn reconstruct(
    event: &str,
    r0: DVectorView<f64>,
    jac: DMatrixView<f64>,
    win: DMatrixView<f64>,
    windows: &[Term],
) -> Reconstruction {
    let nf = jac.ncols();
    let nw = win.ncols();
    let n = nf + nw;
    let mut a = DMatrix::zeros(r0.len(), n);
    a.columns_mut(0, nf).copy_from(&jac);
    a.columns_mut(nf, nw).copy_from(&win);
    let ata = a.tr_mul(&a);
    let atr = a.tr_mul(&r0);
    // The smoothness penalty: first differences within each axis, scaled by the axis's mean
    // information per window.
    let mut pen = DMatrix::zeros(n, n);
    for axis in Axis::FORCE_AND_MOMENT {
        let idx: Vec<usize> = (0..nw).filter(|&k| windows[k].axis == axis).collect();
        if idx.len() < 2 {
            continue;
        }
        let s = idx.iter().map(|&k| ata[(nf + k, nf + k)]).sum::<f64>() / idx.len() as f64;
        for w in idx.windows(2) {
            let (i, j) = (nf + w[0], nf + w[1]);
            pen[(i, i)] += s;
            pen[(j, j)] += s;
            pen[(i, j)] -= s;
            pen[(j, i)] -= s;
        }
    }
    // A whisper of ridge everywhere keeps every system definite.
    let ridge = 1e-9 * (0..n).map(|k| ata[(k, k)]).fold(0.0, f64::max).max(1e-300);
    let m = r0.len() as f64;
    let mut best: Option<Solved> = None;
    for k in 0..13 {
        let lambda = 10f64.powf(-4.0 + 0.5 * k as f64);
        let mut sys = &ata + &pen * lambda;
        for d in 0..n {
            sys[(d, d)] += ridge;
        }
        let Some(chol) = sys.cholesky() else {
            continue;
        };
        let beta = -chol.solve(&atr);
        let inv = chol.inverse();
        let trace: f64 = (0..n).map(|d| (inv.row(d) * ata.column(d))[(0, 0)]).sum();
        let res = r0 + &a * &beta;
        let rss = res.norm_squared();
        let gcv = m * rss / (m - trace).max(1.0).powi(2);
        if best.as_ref().is_none_or(|b| gcv < b.0) {
            best = Some((gcv, lambda, inv, beta, trace));
        }
    }
    let Some((_, lambda, inv, beta, trace)) = best else {
        return Reconstruction {
            event: event.to_string(),
            lambda: f64::NAN,
            effective_parameters: 0.0,
            rms_after: (r0.norm_squared() / m).sqrt(),
            increments: Vec::new(),
        };
    };
    let res = r0 + &a * &beta;
    let mut increments = Vec::new();
    for axis in Axis::FORCE_AND_MOMENT {
        let idx: Vec<usize> = (0..nw).filter(|&k| windows[k].axis == axis).collect();
        if idx.is_empty() {
            continue;
        }
        increments.push(IncrementSeries {
            axis: axis.name().to_string(),
            t_s: idx
                .iter()
                .map(|&k| 0.5 * (windows[k].locator[0] + windows[k].locator[1]))
                .collect(),
            value: idx.iter().map(|&k| beta[nf + k]).collect(),
            std: idx
                .iter()
                .map(|&k| inv[(nf + k, nf + k)].max(0.0).sqrt())
                .collect(),
        });
    }
    Reconstruction {
        event: event.to_string(),
        lambda,
        effective_parameters: trace,
        rms_after: (res.norm_squared() / m).sqrt(),
        increments,
    }
}

/// The misfit reconstructed per event (`rows` of the residuals, each event's part of `r0`, of
/// the factors' columns `fixed` and of the windows' columns `win`).
pub(crate) fn reconstruct_events(
    job: &Job,
    rows: &[usize],
    r0: &DVector<f64>,
    fixed: &DMatrix<f64>,
    win: DMatrixView<f64>,
    windows: &[Term],
) -> Vec<Reconstruction> {
    crate::probe::event_rows(job, rows)
        .into_iter()
        .zip(job.events())
        .map(|((a, b), e)| {
            reconstruct(
                &e.name,
                r0.rows(a, b - a),
                fixed.rows(a, b - a),
                win.rows(a, b - a),
                windows,
            )
        })
        .collect()
}
