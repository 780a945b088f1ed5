//! The linear part of the stepwise regression: each library entry's F-to-enter against the
//! fitted model's residuals, the model's own sensitivities (factors and terms already in)
//! always in (what a factor change can absorb is not a finding), and the groups of entries the
//! data cannot tell apart. `discover` re-linearises at every step and verifies each entry by an
//! output-error refit.
//!
//! E. A. Morelli and V. Klein, "Aircraft System Identification: Theory and Practice" (2nd ed.,
//! 2016), section 5.4 (SIDPAC `swr`): at each step the entry with the largest partial F
//! statistic enters if its F test passes at the family-wise level (Bonferroni over the entries
//! still out) and the predicted square error
//!
//! ```text
//! PSE = RSS / N + sigma_max^2 p / N
//! ```
//!
//! (sigma_max^2 the variance of the residuals to explain) decreases; after each entry, an entry
//! already in whose partial F no longer passes is removed. Entries are single columns or
//! sine-cosine pairs (two columns entering together, an F test of two degrees of freedom).
//! Entries whose new part is nearly the same direction as the one entering (|rho| >= 0.95) are
//! reported with it as one group: the data cannot tell them apart.

use nalgebra::{DMatrix, DVector};

use sepval_solve::stats::f_sf;

/// Family-wise significance level of the entries.
pub const ALPHA: f64 = 0.01;
/// Correlation above which two entries form a group.
pub const GROUP_RHO: f64 = 0.95;
/// Most entries selected.
pub const MAX_ENTRIES: usize = 4;
/// Entries verified by an output-error refit at each step: the best by F-to-enter, one per
/// axis and regressor (and then the best of each axis not among them).
pub const VERIFIED_PER_STEP: usize = 6;

/// Orthonormal basis of the span of `cols` (modified Gram-Schmidt; near-dependent columns are
/// dropped).
pub fn orthonormal(cols: &[DVector<f64>]) -> Vec<DVector<f64>> {
    let mut q: Vec<DVector<f64>> = Vec::new();
    for c in cols {
        let mut v = c.clone();
        for b in &q {
            let d = b.dot(&v);
            v.axpy(-d, b, 1.0);
        }
        let n = v.norm();
        if n > 1e-10 * c.norm().max(1e-300) {
            q.push(v / n);
        }
    }
    q
}

/// Orthonormal basis of the span of the columns of `fixed` (the model's own sensitivities).
pub fn column_basis(fixed: &DMatrix<f64>) -> Vec<DVector<f64>> {
    orthonormal(
        &(0..fixed.ncols())
            .map(|j| fixed.column(j).into_owned())
            .collect::<Vec<_>>(),
    )
}

/// Removes from `v` its components along the orthonormal `basis`.
pub fn project_out(v: &mut DVector<f64>, basis: &[DVector<f64>]) {
    for b in basis {
        let d = b.dot(v);
        v.axpy(-d, b, 1.0);
    }
}

/// One entry's score against the residuals to explain.
#[derive(Debug, Clone, PartialEq)]
pub struct Score {
    /// The entry.
    pub entry: usize,
    /// Its partial F (F-to-enter).
    pub f: f64,
    /// Its p-value.
    pub p: f64,
    /// RSS drop.
    pub drop: f64,
    /// Whether the predicted square error falls when it enters.
    pub pse_falls: bool,
}

/// Scores every entry (`entries[k]` lists the columns of `cols` that entry k uses) against
/// residuals `r0`, the columns of `fixed` already in the model; best F first. Entries with no
/// direction beyond `fixed` are left out.
pub fn screen(
    r0: &DVector<f64>,
    fixed: &DMatrix<f64>,
    cols: &DMatrix<f64>,
    entries: &[Vec<usize>],
) -> Vec<Score> {
    let m = r0.len() as f64;
    let basis = column_basis(fixed);
    let p = basis.len() as f64;
    let mut r = r0.clone();
    project_out(&mut r, &basis);
    let rss = r.norm_squared();
    // The variance of the residuals to explain (PSE's sigma_max^2).
    let var_max = {
        let mean = r0.mean();
        r0.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / m
    };
    let mut scores: Vec<Score> = entries
        .iter()
        .enumerate()
        .filter_map(|(e, columns)| {
            let q = new_directions(cols, columns, &basis);
            if q.is_empty() {
                return None;
            }
            let drop: f64 = q.iter().map(|b| b.dot(&r).powi(2)).sum();
            let dof = q.len() as f64;
            let d2 = (m - p - dof).max(1.0);
            let f = (drop / dof) / ((rss - drop) / d2).max(1e-300);
            Some(Score {
                entry: e,
                f,
                p: f_sf(f, dof, d2),
                drop,
                pse_falls: drop > var_max * dof,
            })
        })
        .collect();
    scores.sort_by(|a, b| b.f.total_cmp(&a.f));
    scores
}

/// The orthonormal directions entry `columns` adds beyond `basis`.
pub fn new_directions(
    cols: &DMatrix<f64>,
    columns: &[usize],
    basis: &[DVector<f64>],
) -> Vec<DVector<f64>> {
    let new: Vec<DVector<f64>> = columns
        .iter()
        .map(|&j| {
            let mut v = cols.column(j).into_owned();
            project_out(&mut v, basis);
            v
        })
        .collect();
    orthonormal(&new)
}

/// The entries whose direction beyond `fixed` is nearly that of `lead` (|rho| >= [`GROUP_RHO`],
/// first columns compared), strongest first: the data cannot tell them from it.
pub fn group(
    fixed: &DMatrix<f64>,
    cols: &DMatrix<f64>,
    entries: &[Vec<usize>],
    lead: usize,
) -> Vec<(usize, f64)> {
    let basis = column_basis(fixed);
    let first = |e: usize| {
        let mut v = cols.column(entries[e][0]).into_owned();
        project_out(&mut v, &basis);
        let n = v.norm();
        (n > 0.0).then(|| v / n)
    };
    let Some(l) = first(lead) else {
        return Vec::new();
    };
    let mut out: Vec<(usize, f64)> = (0..entries.len())
        .filter(|&e| e != lead)
        .filter_map(|e| first(e).map(|v| (e, v.dot(&l))))
        .filter(|(_, rho)| rho.abs() >= GROUP_RHO)
        .collect();
    out.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
    out
}

/// The least-squares fit of `cols` (with the columns of `fixed` always in) to residuals `r0`:
/// the residual sum of squares and the coefficients of `cols` minimising |r0 + A beta|.
pub fn fit_columns(
    r0: &DVector<f64>,
    fixed: &DMatrix<f64>,
    cols: &[DVector<f64>],
) -> (f64, Vec<f64>) {
    let mut all: Vec<DVector<f64>> = (0..fixed.ncols())
        .map(|j| fixed.column(j).into_owned())
        .collect();
    all.extend(cols.iter().cloned());
    let a = DMatrix::from_columns(&all);
    let n = a.ncols();
    let beta = nalgebra::SVD::try_new(a.clone(), true, true, f64::EPSILON, 1000)
        .and_then(|svd| svd.solve(&(-r0), 1e-12).ok())
        .filter(|b| b.iter().all(|v| v.is_finite()))
        .unwrap_or_else(|| DVector::zeros(n));
    let rss = (r0 + &a * &beta).norm_squared();
    (rss, beta.iter().skip(fixed.ncols()).copied().collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic stand-in for noise.
    fn noise(n: usize, seed: u64) -> DVector<f64> {
        let mut s = seed;
        DVector::from_fn(n, |_, _| {
            let mut u = 0.0;
            for _ in 0..12 {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                u += (s >> 11) as f64 / (1u64 << 53) as f64;
            }
            u - 6.0
        })
    }

    #[test]
    fn the_hidden_column_scores_first_and_noise_passes_no_threshold() {
        let m = 600;
        let t: Vec<f64> = (0..m).map(|i| i as f64 / m as f64).collect();
        let fixed = DMatrix::from_fn(m, 2, |i, j| if j == 0 { 1.0 } else { t[i] });
        let cols = DMatrix::from_fn(m, 6, |i, j| match j {
            0 => (t[i] * 7.0).sin(),
            1 => (t[i] * 7.3).sin(),
            2 => t[i] * t[i],
            3 => f64::from(u8::from(t[i] > 0.5)),
            4 => (t[i] * 20.0).sin(),
            _ => (t[i] * 20.0).cos(),
        });
        let entries = vec![vec![0], vec![1], vec![2], vec![3], vec![4, 5]];
        let threshold = ALPHA / entries.len() as f64;
        // A step of 0.8 hidden in noise.
        let r0 = noise(m, 3) - cols.column(3) * 0.8;
        let s = screen(&r0, &fixed, &cols, &entries);
        assert_eq!(s[0].entry, 3, "{s:?}");
        assert!(s[0].p < threshold && s[0].pse_falls, "{s:?}");
        // An oscillation pair enters with two degrees of freedom.
        let r1 = noise(m, 5) - cols.column(4) * 0.3 - cols.column(5) * 0.5;
        assert_eq!(screen(&r1, &fixed, &cols, &entries)[0].entry, 4);
        // Columns 0 and 1 are nearly the same direction: a group.
        let r2 = noise(m, 4) + cols.column(0) * 2.0;
        let s = screen(&r2, &fixed, &cols, &entries);
        let g = group(&fixed, &cols, &entries, s[0].entry);
        assert!(
            s[0].entry <= 1 && g.iter().any(|(e, _)| *e == 1 - s[0].entry),
            "{g:?}"
        );
        for seed in 10..30 {
            let s = screen(&noise(m, seed), &fixed, &cols, &entries);
            assert!(s[0].p > threshold, "seed {seed}: {:?}", s[0]);
        }
        // The fit of the hidden column recovers its size.
        let (_, beta) = fit_columns(&r0, &fixed, &[cols.column(3).into_owned()]);
        assert!((beta[0] - 0.8).abs() < 0.2, "{beta:?}");
    }
}
