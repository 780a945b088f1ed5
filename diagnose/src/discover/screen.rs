//! One step's screening (`docs/discovery.md` section 11.3): the library's entries not yet in, their
//! sensitivities about the current model (and, at the first step, before them, the
//! reconstruction windows', reduced to the reconstruction and dropped), the regression's F-to-enter against a Bonferroni threshold with the
//! predicted square error, and the entries worth an output-error refit.

use nalgebra::{DMatrix, DVector};
use sepval_common::evaluation::{Candidate, Evaluator, Job};
use sepval_common::extension::Term;

use super::search::{Search, Selection, Trail};
use crate::found::{DiscoveryStep, Screened};
use crate::library::{self, Entry, Sample};
use crate::reconstruct::{Reconstruction, reconstruct_events};
use crate::stepwise::{self, Score};
use crate::{Fitted, Result, probe};

/// What one step's regression saw.
pub(super) struct Screening {
    /// The current model's candidate.
    pub base: Candidate,
    /// What the store saw along its trajectory, per event.
    pub history: Vec<Vec<Sample>>,
    /// The entries screened.
    pub entries: Vec<Entry>,
    /// Each entry's columns in `lib_cols`.
    pub entry_cols: Vec<Vec<usize>>,
    /// The current model linearised: its residual rows and the sensitivities of its free
    /// parameters.
    pub linear: Linearisation,
    /// The entries' sensitivities.
    pub lib_cols: DMatrix<f64>,
    /// The Bonferroni-corrected F-to-enter threshold.
    pub threshold: f64,
    /// The entries' scores, best first.
    pub scores: Vec<Score>,
    /// At the first step, the baseline's misfit reconstructed per event.
    pub reconstruction: Option<Vec<Reconstruction>>,
}

/// A fitted model about its optimum.
pub(super) struct Linearisation {
    /// Its residual rows.
    pub r0: DVector<f64>,
    /// The sensitivities to its parameters that are free to move.
    pub fixed: DMatrix<f64>,
}

/// The residual rows of a fitted model and the sensitivities to its parameters (factors and
/// terms already in) that are free to move: a parameter held at a bound of its range cannot
/// absorb what lies beyond it, so its column is left out.
fn linearisation(job: &Job, f: &Fitted, rows: &[usize]) -> Linearisation {
    let space = f.space(job);
    let free: Vec<usize> = (0..f.lm.jacobian.ncols())
        .filter(|&c| {
            let (x, lo, hi) = (f.lm.x[c], space.params.lo[c], space.params.hi[c]);
            let tol = 1e-6 * (hi - lo);
            x > lo + tol && x < hi - tol
        })
        .collect();
    let r0 = DVector::from_iterator(rows.len(), rows.iter().map(|&i| f.lm.residuals[i]));
    let fixed = DMatrix::from_fn(rows.len(), free.len(), |i, c| {
        f.lm.jacobian[(rows[i], free[c])]
    });
    Linearisation { r0, fixed }
}

/// Screens the library about `sel`'s model at `step` (0: against the baseline); `None` when
/// the selection cannot go on (the trajectory does not simulate again, or no entry is left).
pub(super) fn screen(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    sel: &Selection,
    step: usize,
    trail: &mut Trail,
) -> Result<Option<Screening>> {
    let job = search.job;
    let base = sel.current.candidate(job)?;
    let history = library::flow_history(job, &base);
    if history.iter().any(Vec::is_empty) {
        trail
            .notes
            .push("the fitted trajectory could not be simulated again: discovery stopped".into());
        return Ok(None);
    }
    let used = sel.picked.term_count();
    let entries: Vec<Entry> = library::library(job, &history, search.rate_hz)
        .into_iter()
        .filter(|e| {
            used + e.terms.len() <= search.room
                && !sel.picked.entries().iter().any(|p| p.same_kind(e))
        })
        .collect();
    if entries.is_empty() {
        return Ok(None);
    }
    let linear = linearisation(job, &sel.current, &search.rows);
    // At the first step, the reconstruction, from the windows' columns alone, which go before
    // the library's are made (issue 21, item 7: the two matrices are never held together).
    let reconstruction = if step == 0 {
        Some(reconstruction(
            evaluator, search, sel, &base, &history, &linear,
        )?)
    } else {
        None
    };

    // Every entry's sensitivity.
    let mut probes: Vec<Term> = Vec::new();
    let mut entry_cols: Vec<Vec<usize>> = Vec::new();
    for e in &entries {
        entry_cols.push((probes.len()..probes.len() + e.terms.len()).collect());
        probes.extend(e.terms.iter().copied());
    }
    let lib_cols = probe::columns(
        evaluator,
        job,
        &base,
        &probes,
        &sel.current.lm.residuals,
        search.noise,
        &search.rows,
    )?;

    // F-to-enter against the Bonferroni threshold, and the PSE.
    let threshold = stepwise::ALPHA / entries.len() as f64;
    let scores = stepwise::screen(&linear.r0, &linear.fixed, &lib_cols, &entry_cols);
    Ok(Some(Screening {
        base,
        history,
        entries,
        entry_cols,
        linear,
        lib_cols,
        threshold,
        scores,
        reconstruction,
    }))
}

/// The baseline's misfit (the model of `sel`, linearised as `linear`, at `base`; `history`:
/// what the store saw) reconstructed per event from the sensitivities of the time windows.
fn reconstruction(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    sel: &Selection,
    base: &Candidate,
    history: &[Vec<Sample>],
    linear: &Linearisation,
) -> Result<Vec<Reconstruction>> {
    let windows = library::windows(history);
    let win = probe::columns(
        evaluator,
        search.job,
        base,
        &windows,
        &sel.current.lm.residuals,
        search.noise,
        &search.rows,
    )?;
    Ok(reconstruct_events(
        search.job,
        &search.rows,
        &linear.r0,
        &linear.fixed,
        win.as_view(),
        &windows,
    ))
}

impl Screening {
    /// The step's record so far: the ten best entries by F-to-enter.
    pub fn record(&self, step: usize, chi2: f64) -> DiscoveryStep {
        DiscoveryStep {
            step: step + 1,
            chi2,
            threshold: self.threshold,
            screened: self
                .scores
                .iter()
                .take(10)
                .map(|sc| {
                    let e = &self.entries[sc.entry];
                    Screened {
                        axis: e.axis().name().to_string(),
                        term: e.formula(),
                        f: sc.f,
                        p_value: sc.p,
                    }
                })
                .collect(),
            verified: Vec::new(),
            accepted: None,
        }
    }

    /// The entries to verify: the best by F-to-enter, one per axis and regressor, then the best
    /// of each axis not yet among them, so that a misfit the regression spreads over several
    /// axes has each axis's best candidate refitted.
    pub fn to_verify(&self) -> Vec<usize> {
        let entries = &self.entries;
        let passing: Vec<usize> = self
            .scores
            .iter()
            .filter(|s| s.p < self.threshold && s.pse_falls)
            .map(|s| s.entry)
            .collect();
        let mut best: Vec<usize> = Vec::new();
        for &e in &passing {
            if best.len() == stepwise::VERIFIED_PER_STEP {
                break;
            }
            if !best.iter().any(|&b| entries[b].same_kind(&entries[e])) {
                best.push(e);
            }
        }
        for &e in &passing {
            if !best.iter().any(|&b| entries[b].axis() == entries[e].axis()) {
                best.push(e);
            }
        }
        best
    }

    /// Why the step ends with nothing to verify.
    pub fn nothing_significant(&self, step: usize) -> String {
        format!(
            "step {}: no library term is significant in the regression (best F-to-enter p = {:.2e}, threshold {:.1e} over {} entries)",
            step + 1,
            self.scores.first().map_or(1.0, |s| s.p),
            self.threshold,
            self.entries.len()
        )
    }
}
