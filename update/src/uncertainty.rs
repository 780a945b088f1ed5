//! How sure the corrections are (docs/update.md section 15.6): the covariance of the penalised
//! estimate at the final refit, its effective number of parameters, and each correction's band.
//!
//! With J the Jacobian of the samples' rows, P = lambda L^T L the penalty's (both from the
//! refit's final Jacobian, whose rows are the samples' then the penalty's), H = J^T J + P:
//!
//! ```text
//! edf = tr(H^-1 J^T J)            (effective number of parameters; Hastie and Tibshirani,
//!                                  Generalized Additive Models, 1990, section 3.5)
//! s^2 = max(1, chi2 / (m - edf))  (the residuals' variance in units of the noise, never below it)
//! Cov = s^2 H^-1                  (the posterior covariance of the penalised estimate, widened
//!                                  by s^2 where the model does not reach the noise)
//! ```
//!
//! A correction's band at x is 2 sqrt(w(x)^T Cov w(x)), w(x) the interpolation weights of its
//! free values at x. An interference correction shares its size with its axis's multiplier,
//! which scales the scenario's increment and the correction together (section 15.4), and its
//! constant part, within the distances the releases reached, with its axis's offset: the
//! covariance is taken given those fitted factors (the rows and columns of `held` left out of H
//! before it is inverted), or the bands would show those shared directions, not what the
//! releases measured of the correction's shape.

use nalgebra::DMatrix;
use sepval_common::correction::weights;

use crate::crossval::Refitted;
use crate::space::UpdateSpace;

/// The uncertainty of a refit.
#[derive(Debug, Clone)]
pub struct Uncertainty {
    /// Effective number of parameters.
    pub effective_parameters: f64,
    /// s^2: the residuals' variance in units of the noise (at least 1).
    pub residual_scale: f64,
    /// The covariance of every parameter (free factors, then free values).
    pub covariance: DMatrix<f64>,
}

impl Uncertainty {
    /// The uncertainty of `fit`, its covariance given the parameters `held` (positions), whose
    /// rows and columns are 0.
    pub fn of(fit: &Refitted, held: &[usize]) -> Uncertainty {
        let j = &fit.lm.jacobian;
        let n = fit.lm.x.len();
        let m = fit.measure.data_rows;
        if j.nrows() < m || j.ncols() != n || n == 0 {
            return Uncertainty {
                effective_parameters: n as f64,
                residual_scale: 1.0,
                covariance: DMatrix::from_element(n, n, f64::NAN),
            };
        }
        let jd = j.rows(0, m);
        let d = jd.tr_mul(&jd);
        let h = j.tr_mul(j);
        let scale = (0..n).map(|k| h[(k, k)]).fold(0.0, f64::max).max(1e-300);
        let mut reg = h.clone();
        for k in 0..n {
            reg[(k, k)] += 1e-12 * scale;
        }
        let Some(inv) = reg.clone().cholesky().map(|c| c.inverse()) else {
            return Uncertainty {
                effective_parameters: n as f64,
                residual_scale: 1.0,
                covariance: DMatrix::from_element(n, n, f64::NAN),
            };
        };
        let edf: f64 = (0..n).map(|k| (inv.row(k) * d.column(k))[(0, 0)]).sum();
        let chi2 = fit.data_chi2();
        let s2 = (chi2 / (m as f64 - edf).max(1.0)).max(1.0);
        let covariance = if held.is_empty() {
            inv * s2
        } else {
            // A unit row and column for each one held: the rest of the inverse is the inverse
            // of H without them.
            let mut given = reg;
            for &k in held.iter().filter(|&&k| k < n) {
                given.row_mut(k).fill(0.0);
                given.column_mut(k).fill(0.0);
                given[(k, k)] = 1.0;
            }
            match given.cholesky().map(|c| c.inverse()) {
                Some(mut inv) => {
                    for &k in held.iter().filter(|&&k| k < n) {
                        inv[(k, k)] = 0.0;
                    }
                    inv * s2
                }
                None => DMatrix::from_element(n, n, f64::NAN),
            }
        };
        Uncertainty {
            effective_parameters: edf,
            residual_scale: s2,
            covariance,
        }
    }

    /// The standard deviation of every breakpoint's value of correction `k` of `space` (0 for
    /// those held).
    pub fn value_std(&self, space: &UpdateSpace, k: usize) -> Vec<f64> {
        let (first, p) = offset(space, k);
        let mut at = first;
        p.pinned
            .iter()
            .map(|&pinned| {
                if pinned {
                    0.0
                } else {
                    let s = self.covariance[(at, at)].max(0.0).sqrt();
                    at += 1;
                    s
                }
            })
            .collect()
    }

    /// The standard deviation of correction `k` of `space` at each of `xs`.
    pub fn band(&self, space: &UpdateSpace, k: usize, xs: &[f64]) -> Vec<f64> {
        let (first, p) = offset(space, k);
        let free: Vec<usize> = (0..p.pinned.len()).filter(|&j| !p.pinned[j]).collect();
        xs.iter()
            .map(|&x| {
                let w = weights(&p.breakpoints, x);
                let mut var = 0.0;
                for (a, &ja) in free.iter().enumerate() {
                    for (b, &jb) in free.iter().enumerate() {
                        var += w[ja] * w[jb] * self.covariance[(first + a, first + b)];
                    }
                }
                var.max(0.0).sqrt()
            })
            .collect()
    }
}

/// The index of correction `k`'s first free value among the parameters, and the correction.
fn offset(space: &UpdateSpace, k: usize) -> (usize, &crate::explored::Proposal) {
    let c = space.corrections();
    let first = space.factor_count() + c[..k].iter().map(|p| p.free_values()).sum::<usize>();
    (first, &c[k])
}
