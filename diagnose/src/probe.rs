//! Sensitivities of the fitted model's residuals to added terms: for each probe term (a small
//! coefficient on one regressor, or one time window), one simulation of the fitted candidate
//! with the term added, and the change of the normalised residual vector per unit coefficient
//! (a forward difference, as the refinement's Jacobian). The probes go to the workers in parts
//! of at most [`PROBE_SAMPLES`] simulated samples, and each part's trajectories are reduced to
//! their columns and dropped before the next part is asked (issue 21, item 7: a 10 kHz, 1-s
//! record's thousand probes brought back whole were 15 million observations at once); a part
//! is evaluated as one batch, so the workers share its probes.
//!
//! Long records are analysed on a subset of their samples (every k-th, at most
//! [`MAX_ROWS_SAMPLES`] samples in all), which keeps the matrices small; the fits that verify
//! the findings use every sample.

use nalgebra::DMatrix;
use sepval_common::evaluation::{Candidate, Evaluator, Job};
use sepval_common::extension::Term;

use super::DiagnoseError;
use sepval_fit::problem::SAMPLE_BUDGET;
use sepval_fit::space::{Noise, residual_vector};

/// Most simulated samples one part of the probes brings back: a quarter of the fit's
/// [`SAMPLE_BUDGET`] (24 MB as observations), as the column matrix they fill is the larger
/// part of a diagnosis's memory; a record of the default 201 samples still sends its 2 000-odd
/// probes in one batch.
pub const PROBE_SAMPLES: usize = SAMPLE_BUDGET / 4;

/// Most samples (over all events) the discovery's linear algebra uses.
pub const MAX_ROWS_SAMPLES: usize = 3_000;

/// The residual rows the discovery uses: every k-th sample of every event (6 rows each).
pub fn rows(job: &Job) -> Vec<usize> {
    let total = job.sample_count();
    let stride = total.div_ceil(MAX_ROWS_SAMPLES).max(1);
    (0..total)
        .step_by(stride)
        .flat_map(|k| 6 * k..6 * k + 6)
        .collect()
}

/// The rows of each event within `rows`: (first, end) positions.
pub fn event_rows(job: &Job, rows: &[usize]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start_row = 0;
    let mut pos = 0;
    for e in job.events() {
        let end_row = start_row + 6 * e.data.len();
        let first = pos;
        while pos < rows.len() && rows[pos] < end_row {
            pos += 1;
        }
        out.push((first, pos));
        start_row = end_row;
    }
    out
}

/// The sensitivity columns of `probes` at `base` (whose normalised residuals are `r0`),
/// restricted to `rows`: column j = (r(base + probe j) - r0) / coefficient j. A probe that does
/// not simulate gives a zero column. The probes are evaluated in parts of at most
/// [`PROBE_SAMPLES`] samples, each reduced to its columns before the next is asked.
pub fn columns(
    evaluator: &mut dyn Evaluator,
    job: &Job,
    base: &Candidate,
    probes: &[Term],
    r0: &[f64],
    noise: Noise,
    rows: &[usize],
) -> Result<DMatrix<f64>, DiagnoseError> {
    let batch: Vec<Candidate> = probes
        .iter()
        .map(|t| {
            let mut c = *base;
            c.terms.push(*t)?;
            Ok(c)
        })
        .collect::<Result<_, DiagnoseError>>()?;
    let part = (PROBE_SAMPLES / job.sample_count().max(1)).max(1);
    let mut m = DMatrix::zeros(rows.len(), probes.len());
    for (k, chunk) in batch.chunks(part).enumerate() {
        let out = evaluator.evaluate(chunk, true)?;
        let first = k * part;
        for (j, (e, t)) in out.into_iter().zip(&probes[first..]).enumerate() {
            if let Some(samples) = e.samples {
                let r = residual_vector(job, &samples, noise);
                let mut column = m.column_mut(first + j);
                for (i, &row) in rows.iter().enumerate() {
                    column[i] = (r[row] - r0[row]) / t.coefficient;
                }
            }
        }
    }
    Ok(m)
}
