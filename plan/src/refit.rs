//! The linearised refit behind the separation and the information (docs/planning.md):
//! normal equations pooled over releases, the chi-square a model is left with after its
//! parameters absorb what they can of another model's trajectories, and log det of an
//! information matrix.
//!
//! Parameters are in units of their ranges (the sensitivity columns are scaled by them), and
//! a refit is held to its ranges by a unit prior on each (a ridge of 1: moving a parameter by
//! its whole range costs as much as one noise sigma of misfit). The prior keeps every matrix
//! positive definite, so one Cholesky factorisation answers both questions; without it, a
//! parameter that the releases do not determine would absorb anything at no cost, far beyond
//! its bounds.

use nalgebra::{DMatrix, DVector};

/// Normal equations of a least-squares refit: min over delta of |v - J delta|^2 + |delta|^2,
/// kept as J^T J, J^T v and v^T v (summed over releases).
#[derive(Debug, Clone, PartialEq)]
pub struct Normal {
    /// J^T J.
    pub gram: DMatrix<f64>,
    /// J^T v.
    pub rhs: DVector<f64>,
    /// v^T v.
    pub vv: f64,
}

impl Normal {
    /// No rows yet, for `p` parameters.
    pub fn zeros(p: usize) -> Normal {
        Normal {
            gram: DMatrix::zeros(p, p),
            rhs: DVector::zeros(p),
            vv: 0.0,
        }
    }

    /// Adds the rows of one release.
    pub fn add(&mut self, gram: &DMatrix<f64>, rhs: &DVector<f64>, vv: f64) {
        self.gram += gram;
        self.rhs += rhs;
        self.vv += vv;
    }

    /// The chi-square left after the refit: v^T v - (J^T v)^T (J^T J + I)^-1 J^T v (at least
    /// 0; the refit's prior cost |delta|^2 included, so that a change the parameters absorb
    /// only by leaving their ranges still counts).
    pub fn refit_chi2(&self) -> f64 {
        let p = self.rhs.len();
        let a = &self.gram + DMatrix::identity(p, p);
        match a.cholesky() {
            Some(ch) => {
                let delta = ch.solve(&self.rhs);
                (self.vv - self.rhs.dot(&delta)).max(0.0)
            }
            // J^T J + I is positive definite unless the sums are not finite.
            None => f64::NAN,
        }
    }
}

/// log det of the information `gram` + I (the unit prior of each parameter's range), or NaN
/// when it is not finite.
pub fn log_det_with_prior(gram: &DMatrix<f64>) -> f64 {
    let p = gram.nrows();
    match (gram + DMatrix::identity(p, p)).cholesky() {
        Some(ch) => 2.0 * ch.l().diagonal().iter().map(|d| d.ln()).sum::<f64>(),
        None => f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_difference_in_the_span_is_absorbed_and_one_across_it_is_not() {
        // J: two parameters over four rows.
        let j = DMatrix::from_row_slice(4, 2, &[10.0, 0.0, 0.0, 10.0, 5.0, 5.0, 0.0, 0.0]);
        let normal = |v: DVector<f64>| {
            let mut n = Normal::zeros(2);
            n.add(&(j.transpose() * &j), &(j.transpose() * &v), v.dot(&v));
            n
        };
        // In the span: v = J (0.01, -0.02), absorbed but for the prior's small cost.
        let inside = &j * DVector::from_row_slice(&[0.01, -0.02]);
        let chi2 = normal(inside).refit_chi2();
        assert!(chi2 < 1e-3, "{chi2}");
        // Across it: the fourth row, which no parameter moves.
        let across = DVector::from_row_slice(&[0.0, 0.0, 0.0, 3.0]);
        let chi2 = normal(across).refit_chi2();
        assert!((chi2 - 9.0).abs() < 1e-12, "{chi2}");
        // log det of diag(3, 8) + I = ln 4 + ln 9.
        let g = DMatrix::from_row_slice(2, 2, &[3.0, 0.0, 0.0, 8.0]);
        assert!((log_det_with_prior(&g) - (4.0f64 * 9.0).ln()).abs() < 1e-12);
    }
}
