//! Distribution functions and tests used by the diagnosis.
//!
//! Sources: the chi-square tail as the regularised upper incomplete gamma function
//! Q(dof / 2, x / 2) of `statrs` (`function::gamma::gamma_ur`, after Cephes); the F tail as the
//! regularised incomplete beta function I_{d2 / (d2 + d1 f)}(d2 / 2, d1 / 2) by its continued
//! fraction (W. H. Press et al., "Numerical Recipes", 3rd ed., sections 5.2, 6.1 and 6.4, in
//! `beta`); the F test of nested least-squares models; the Ljung-Box portmanteau statistic
//! Q = N (N + 2) sum_{k=1}^{h} rho_k^2 / (N - k) (G. M. Ljung and G. E. P. Box, Biometrika 65,
//! 1978), chi-square with h degrees of freedom for white residuals.
//!
//! Why one from statrs and one by hand: the p-values must stay what they were to 1e-12
//! relative (the diagnosis writes them). The tests compare statrs with the former hand-written
//! functions (Numerical Recipes' series and continued fractions, kept there as the reference)
//! over a wide grid. statrs' `gamma_ur` meets that for the chi-square tail (largest relative
//! difference 4.7e-13 over 5 418 cases, 1 to 1 000 degrees of freedom, p down to 1e-300; below
//! 1e-300 statrs gives 0 where the reference gave a subnormal number, since `gamma_ur` returns
//! 0 once its prefactor exp(a ln x - x - ln Gamma(a)) is below exp(-709.78)). statrs'
//! `beta_reg` does not for the F tail: with 30 or more denominator degrees of freedom (every fit
//! has more than 1 000 residuals) it differs by up to 1e-9 relative, not only in deep tails, as
//! both lose digits to the prefactor exp(ln Gamma(a + b) - ln Gamma(a) - ln Gamma(b) + ...)
//! of large a; so the incomplete beta function stays hand-written (`beta`), unchanged.
//!
//! These run on the coordinator only, after the simulations, so they use the standard library's
//! elementary functions (`exp`, `ln`, ...); the simulation itself uses none (docs/model.md
//! section 9, `sepval_common::elementary`).

mod beta;
#[cfg(test)]
mod tests;

use statrs::function::gamma::checked_gamma_ur;

/// Survival function of the chi-square distribution with `dof` degrees of freedom: the
/// regularised upper incomplete gamma function Q(dof / 2, x / 2). 1 for x <= 0, 0 for an
/// infinite x, NaN for a NaN argument or dof <= 0.
pub fn chi2_sf(x: f64, dof: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    if x == f64::INFINITY {
        return 0.0;
    }
    checked_gamma_ur(0.5 * dof, 0.5 * x).unwrap_or(f64::NAN)
}

/// Survival function of the F distribution with (d1, d2) degrees of freedom.
pub fn f_sf(f: f64, d1: f64, d2: f64) -> f64 {
    if f <= 0.0 {
        return 1.0;
    }
    beta::beta_inc(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f))
}

/// The F test of a nested extension: `q` more parameters lowered the residual sum of squares
/// from `rss0` to `rss1`, with `m` residuals and `p1` parameters in the extended model.
/// Returns (F, p-value).
pub fn f_test(rss0: f64, rss1: f64, q: usize, m: usize, p1: usize) -> (f64, f64) {
    let d2 = (m.saturating_sub(p1)).max(1) as f64;
    let f = ((rss0 - rss1).max(0.0) / q as f64) / (rss1 / d2);
    (f, f_sf(f, q as f64, d2))
}

/// Autocorrelation of `x` at lags 1..=h.
pub fn autocorrelation(x: &[f64], h: usize) -> Vec<f64> {
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    let c0: f64 = x.iter().map(|v| (v - mean) * (v - mean)).sum();
    (1..=h)
        .map(|k| {
            if k >= n || c0 <= 0.0 {
                return 0.0;
            }
            (0..n - k)
                .map(|i| (x[i] - mean) * (x[i + k] - mean))
                .sum::<f64>()
                / c0
        })
        .collect()
}

/// The Ljung-Box statistic and its p-value (chi-square, h degrees of freedom).
pub fn ljung_box(x: &[f64], h: usize) -> (f64, f64) {
    let n = x.len() as f64;
    let rho = autocorrelation(x, h);
    let q = n
        * (n + 2.0)
        * rho
            .iter()
            .enumerate()
            .map(|(k, r)| r * r / (n - (k + 1) as f64))
            .sum::<f64>();
    (q, chi2_sf(q, h as f64))
}
