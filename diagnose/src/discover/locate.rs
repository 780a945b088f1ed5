//! The locator zoom (`docs/discovery.md` section 11.5): each entry to verify has its locator (step
//! or gust time, frequency, decay length) refined on a grid eight times finer than the library's, around
//! the one screened, and its linear coefficients estimated by the regression there (a damping
//! term's raised to reach the model's own damping: `damping::floor`).

use nalgebra::{DMatrix, DVector};
use sepval_common::elementary;
use sepval_common::evaluation::Evaluator;
use sepval_common::extension::{Family, Term};

use super::damping;
use super::screen::Screening;
use super::search::Search;
use crate::library::{self, Entry};
use crate::{Fitted, Result, probe, stepwise};

/// An entry to verify at its refined locator and estimated coefficients.
pub(super) struct Located {
    /// The entry.
    pub entry: Entry,
    /// Its index among the step's screened entries.
    pub index: usize,
}

/// One probe of the zoom: entry `k` of the candidates at locator `locator`, its columns from
/// `from` on.
struct ZoomProbe {
    k: usize,
    locator: f64,
    from: usize,
}

/// The fine grid around a selected term's locator: 17 values spanning one library spacing on
/// each side, or `None` for families without one.
fn fine_grid(term: &Term) -> Option<Vec<f64>> {
    let l = term.locator[0];
    let spacing = match term.regressor.family() {
        Family::Step | Family::Wind => library::STEP_SPACING_S,
        Family::Oscillation => library::FREQUENCY_SPACING_HZ,
        Family::Interference | Family::InterferenceFlowAngle => {
            // sepval's own pow, not the C library's: these decay lengths are simulated (and may
            // end up in DIR/extension.toml), so they must be the same bits on every host.
            return Some(
                (-8..=8)
                    .map(|k| l * elementary::pow(1.5, k as f64 / 8.0))
                    .collect(),
            );
        }
        _ => return None,
    };
    Some(
        (-8..=8)
            .map(|k| l + spacing * k as f64 / 8.0)
            .filter(|v| *v > 0.0)
            .collect(),
    )
}

/// The entries `best` of `s` at their best locators on the fine grid (one batch of probes
/// about `current`), with the regression's coefficients there.
pub(super) fn locate(
    evaluator: &mut dyn Evaluator,
    search: &Search,
    s: &Screening,
    current: &Fitted,
    best: &[usize],
) -> Result<Vec<Located>> {
    let mut tried: Vec<Entry> = best.iter().map(|&b| s.entries[b].clone()).collect();
    let mut zoom_probes = Vec::new();
    let mut zoom_of = Vec::new();
    for (k, e) in tried.iter().enumerate() {
        for locator in fine_grid(&e.terms[0]).unwrap_or_default() {
            let from = zoom_probes.len();
            for t in &e.terms {
                let mut t = *t;
                t.locator[0] = locator;
                t.coefficient = library::probe_size(&t, &s.history);
                zoom_probes.push(t);
            }
            zoom_of.push(ZoomProbe { k, locator, from });
        }
    }
    let zc = if zoom_probes.is_empty() {
        DMatrix::zeros(search.rows.len(), 0)
    } else {
        probe::columns(
            evaluator,
            search.job,
            &s.base,
            &zoom_probes,
            &current.lm.residuals,
            search.noise,
            &search.rows,
        )?
    };
    let (r0, fixed) = (&s.linear.r0, &s.linear.fixed);
    for (k, e) in tried.iter_mut().enumerate() {
        let width = e.terms.len();
        let own: Vec<DVector<f64>> = s.entry_cols[best[k]]
            .iter()
            .map(|&j| s.lib_cols.column(j).into_owned())
            .collect();
        let (mut rss, mut coefs) = stepwise::fit_columns(r0, fixed, &own);
        let mut locator = e.terms[0].locator[0];
        for z in zoom_of.iter().filter(|z| z.k == k) {
            let c: Vec<DVector<f64>> = (z.from..z.from + width)
                .map(|j| zc.column(j).into_owned())
                .collect();
            let (r, b) = stepwise::fit_columns(r0, fixed, &c);
            if r < rss {
                (rss, coefs, locator) = (r, b, z.locator);
            }
        }
        for (t, c) in e.terms.iter_mut().zip(coefs) {
            t.locator[0] = locator;
            t.coefficient = c;
        }
        damping::floor(search, e);
    }
    Ok(tried
        .into_iter()
        .zip(best)
        .map(|(entry, &index)| Located { entry, index })
        .collect())
}
