//! The linear algebra of one Levenberg-Marquardt step: Marquardt's damped normal equations
//! (J^T J + mu diag(J^T J)) d = rhs on the free parameters, solved by Cholesky with a bounded
//! singular value decomposition behind it (D. W. Marquardt, "An algorithm for least-squares
//! estimation of nonlinear parameters", J. SIAM 11, 1963).

use nalgebra::{DMatrix, DVector};

use super::Params;

/// One-sided difference steps at `x`: `fd_step` of each range, forward (backward when
/// `backward`), turned inward at the bound the step would cross.
pub(super) fn fd_steps(params: &Params, x: &[f64], fd_step: f64, backward: bool) -> Vec<f64> {
    (0..params.len())
        .map(|i| {
            let h = fd_step * params.range(i);
            if backward {
                if x[i] - h >= params.lo[i] { -h } else { h }
            } else if x[i] + h <= params.hi[i] {
                h
            } else {
                -h
            }
        })
        .collect()
}

/// Solves (J^T J + mu diag(J^T J)) d = rhs for the free parameters (zero for the others).
pub(super) fn solve_damped(jtj: &DMatrix<f64>, free: &[usize], mu: f64, rhs: &[f64]) -> Vec<f64> {
    let nf = free.len();
    let mut a = DMatrix::zeros(nf, nf);
    let mut b = DVector::zeros(nf);
    for (p, &i) in free.iter().enumerate() {
        b[p] = rhs[i];
        for (q, &j) in free.iter().enumerate() {
            a[(p, q)] = jtj[(i, j)];
        }
        a[(p, p)] += mu * jtj[(i, i)].max(1e-12);
    }
    let d = solve_bounded(a, b);
    let mut full = vec![0.0; jtj.nrows()];
    for (p, &i) in free.iter().enumerate() {
        full[i] = d[p];
    }
    full
}

/// Most sweeps of the singular value decomposition that backs up a failed Cholesky factorisation
/// (it converges in a few dozen on any finite matrix; this bound stops it on a pathological one
/// instead of spinning for ever).
const MAX_SVD_ITERATIONS: usize = 1000;

/// Solves `a d = b` (`a` symmetric): Cholesky, else a bounded SVD pseudo-inverse, else (a
/// non-finite or pathological system) no step at all.
pub(super) fn solve_bounded(a: DMatrix<f64>, b: DVector<f64>) -> DVector<f64> {
    let n = b.len();
    if !(a.iter().all(|v| v.is_finite()) && b.iter().all(|v| v.is_finite())) {
        return DVector::zeros(n);
    }
    if let Some(c) = a.clone().cholesky() {
        return c.solve(&b);
    }
    nalgebra::SVD::try_new(a, true, true, f64::EPSILON, MAX_SVD_ITERATIONS)
        .and_then(|svd| svd.solve(&b, 1e-14).ok())
        .filter(|d| d.iter().all(|v| v.is_finite()))
        .unwrap_or_else(|| DVector::zeros(n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pathological_systems_give_no_step_at_once() {
        let huge = DMatrix::from_element(3, 3, 1e308);
        let d = solve_bounded(huge.clone() * 10.0, DVector::from_element(3, 1.0));
        assert!(d.iter().all(|v| *v == 0.0), "{d}");
        let d = solve_bounded(
            DMatrix::from_element(3, 3, f64::NAN),
            DVector::from_element(3, 1.0),
        );
        assert!(d.iter().all(|v| *v == 0.0), "{d}");
        // Singular but finite: the pseudo-inverse.
        let singular = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
        let d = solve_bounded(singular, DVector::from_row_slice(&[2.0, 2.0]));
        assert!(
            (d[0] - 1.0).abs() < 1e-12 && (d[1] - 1.0).abs() < 1e-12,
            "{d}"
        );
        let d = solve_bounded(huge, DVector::from_element(3, 1e-300));
        assert!(d.iter().all(|v| v.is_finite()));
    }
}
