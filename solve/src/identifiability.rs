//! How sure each parameter of a fit is: Cramer-Rao standard errors from the Fisher information
//! of the normalised residuals, corrected for coloured residuals, the correlation matrix, the
//! pairs that compensate each other, and the parameters the data cannot determine.
//!
//! Sources: the Fisher information of an output-error fit M = J^T J (J: derivatives of the
//! residuals normalised by their noise sigma), whose inverse is the Cramer-Rao bound on the
//! parameter covariance when the residuals are white with unit variance. Real residuals are
//! coloured (model error, correlated noise), which makes M^-1 optimistic; following E. A.
//! Morelli and V. Klein, "Aircraft System Identification: Theory and Practice" (2nd ed., 2016),
//! section 6.8, and their SIDPAC routine `m_colores`, the covariance is
//!
//! ```text
//! Cov = M^-1 [ sum_i sum_j S_i^T R(i - j) S_j ] M^-1,
//! R(k) = (1/N) sum_i v(i) v(i + k)^T
//! ```
//!
//! with S_i the 6 x n block of J at sample i and v(i) the 6 residuals there. Choice made here:
//! R(k) is tapered by a Bartlett window up to lag N/5 (which keeps the estimate positive
//! semi-definite) and computed within each event (events are independent).

use nalgebra::{DMatrix, SymmetricEigen};
use serde::{Deserialize, Serialize};

use crate::params::Params;

/// Correlation above which two parameters are reported as compensating each other.
pub const COMPENSATING_RHO: f64 = 0.9;

/// One parameter's estimate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamEstimate {
    /// Name.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Value at the fit.
    pub value: f64,
    /// Standard error corrected for coloured residuals (null: not determined at all).
    pub std_error: Option<f64>,
    /// Standard error assuming white residuals (the plain Cramer-Rao bound).
    pub std_error_white: Option<f64>,
    /// Whether the data determine it: its standard error is narrower than its range.
    pub identifiable: bool,
}

/// Two parameters that compensate each other.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Compensating {
    /// First parameter.
    pub a: String,
    /// Second parameter.
    pub b: String,
    /// Their correlation.
    pub rho: f64,
}

/// The identifiability report of a fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Identifiability {
    /// Every parameter.
    pub parameters: Vec<ParamEstimate>,
    /// Parameter names, in the order of `correlation`.
    pub names: Vec<String>,
    /// Correlation matrix of the estimates (0 where a parameter is not determined).
    pub correlation: Vec<Vec<f64>>,
    /// Pairs with |rho| > 0.9, strongest first.
    pub compensating: Vec<Compensating>,
    /// Parameters whose standard error is wider than their range.
    pub not_identifiable: Vec<String>,
    /// Largest residual autocorrelation lag used by the colour correction.
    pub max_lag: usize,
}

impl Identifiability {
    /// The standard error of parameter `i`, when it is determined.
    pub fn std_error(&self, i: usize) -> Option<f64> {
        self.parameters.get(i).and_then(|p| p.std_error)
    }

    /// The correlation of parameters `i` and `j` (0 where either is not determined or out of
    /// range, as the matrix holds it).
    pub fn rho(&self, i: usize, j: usize) -> f64 {
        self.correlation
            .get(i)
            .and_then(|r| r.get(j))
            .copied()
            .unwrap_or(0.0)
    }
}

/// Most (sample, lag) pairs of the coloured-residual correction per event.
const MAX_COLOUR_PAIRS: usize = 4_000_000;

/// The report when the information matrix cannot be decomposed (non-finite entries): every
/// parameter undetermined.
fn undetermined_everywhere(space: &Params, x: &[f64], event_samples: &[usize]) -> Identifiability {
    let n = space.len();
    Identifiability {
        parameters: (0..n)
            .map(|i| ParamEstimate {
                name: space.names[i].clone(),
                unit: space.units[i].clone(),
                value: x[i],
                std_error: None,
                std_error_white: None,
                identifiable: false,
            })
            .collect(),
        names: space.names.clone(),
        correlation: vec![vec![0.0; n]; n],
        compensating: Vec::new(),
        not_identifiable: space.names.clone(),
        max_lag: event_samples
            .iter()
            .map(|&ns| (ns / 5).max(1))
            .max()
            .unwrap_or(1),
    }
}

/// The identifiability of the parameters `x` of `space`, from the normalised residuals `r`
/// and their Jacobian `jac` (rows in the order of `r`), with the events' sample counts.
pub fn identifiability(
    space: &Params,
    x: &[f64],
    r: &[f64],
    jac: &DMatrix<f64>,
    event_samples: &[usize],
) -> Identifiability {
    let Some(white) = WhiteCovariance::of(jac) else {
        return undetermined_everywhere(space, x, event_samples);
    };
    let colour = ColourCorrection::of(r, jac, event_samples);
    let cov = &white.m_inv * colour.middle * &white.m_inv;
    let (parameters, not_identifiable) = estimates(space, x, &cov, &white);
    let (correlation, compensating) = correlations(space, &cov, &white.undetermined);
    Identifiability {
        parameters,
        names: space.names.clone(),
        correlation,
        compensating,
        not_identifiable,
        max_lag: colour.max_lag,
    }
}

/// The plain Cramer-Rao bound: the inverse of the Fisher information M = J^T J on its range,
/// and the parameters it does not determine.
struct WhiteCovariance {
    /// M^-1 (pseudo-inverse; 0 in the directions without information).
    m_inv: DMatrix<f64>,
    /// The parameters in a direction without information, or whose column of J is zero.
    undetermined: Vec<bool>,
}

impl WhiteCovariance {
    /// From the Jacobian, or `None` when M has non-finite entries or its eigen-decomposition
    /// does not converge (a bounded number of sweeps).
    fn of(jac: &DMatrix<f64>) -> Option<Self> {
        let n = jac.ncols();
        // M = J^T J in units where every column of J has norm 1 (D = diag(1 / |J_i|)), so that
        // what counts as "no information" does not depend on the parameters' units: the
        // inverse is D (D M D)^+ D. A column of zeros is undetermined.
        let scale: Vec<f64> = (0..n)
            .map(|i| {
                let c = jac.column(i).norm();
                if c > 0.0 && c.is_finite() {
                    1.0 / c
                } else {
                    0.0
                }
            })
            .collect();
        let mut m = jac.tr_mul(jac);
        for i in 0..n {
            for j in 0..n {
                m[(i, j)] *= scale[i] * scale[j];
            }
        }
        let eig = m
            .iter()
            .all(|v| v.is_finite())
            .then(|| SymmetricEigen::try_new(m.clone(), f64::EPSILON, 1000))
            .flatten()?;
        // Inverse of M on its range; directions with no information are undetermined.
        let lmax = eig.eigenvalues.iter().cloned().fold(0.0, f64::max);
        let tol = lmax * 1e-13;
        let mut m_inv = DMatrix::zeros(n, n);
        let mut undetermined = vec![false; n];
        for k in 0..n {
            let v = eig.eigenvectors.column(k);
            if eig.eigenvalues[k] > tol && eig.eigenvalues[k] > 0.0 {
                m_inv += v * v.transpose() / eig.eigenvalues[k];
            } else {
                for i in 0..n {
                    if v[i].abs() > 1e-6 {
                        undetermined[i] = true;
                    }
                }
            }
        }
        for i in 0..n {
            if scale[i] == 0.0 {
                undetermined[i] = true;
            }
            for j in 0..n {
                m_inv[(i, j)] *= scale[i] * scale[j];
            }
        }
        Some(WhiteCovariance {
            m_inv,
            undetermined,
        })
    }
}

/// The coloured-residual correction (SIDPAC `m_colores`): the middle of
/// M^-1 [ sum_i sum_j S_i^T R(i - j) S_j ] M^-1, per event, Bartlett-tapered.
struct ColourCorrection {
    middle: DMatrix<f64>,
    /// Largest lag used.
    max_lag: usize,
}

impl ColourCorrection {
    fn of(r: &[f64], jac: &DMatrix<f64>, event_samples: &[usize]) -> Self {
        let n = jac.ncols();
        let mut middle = DMatrix::zeros(n, n);
        let mut max_lag = 0;
        let mut row0 = 0;
        for &ns in event_samples {
            // Lags up to a fifth of the event, at most 50, and at most MAX_COLOUR_PAIRS (sample,
            // lag) pairs per event, so that the correction stays cheap on long records (there
            // it uses fewer lags and the standard errors lean low).
            let lag_max = (ns / 5).min(50).min(MAX_COLOUR_PAIRS / ns.max(1)).max(1);
            max_lag = max_lag.max(lag_max);
            for lag in 0..=lag_max.min(ns.saturating_sub(1)) {
                let w = 1.0 - lag as f64 / (lag_max as f64 + 1.0);
                let acc = lag_term(r, jac, row0, ns, lag);
                if lag == 0 {
                    middle += acc * w;
                } else {
                    middle += (&acc + acc.transpose()) * w;
                }
            }
            row0 += 6 * ns;
        }
        ColourCorrection { middle, max_lag }
    }
}

/// sum_i S_i^T R(lag) S_{i+lag} over the event of `ns` samples whose rows start at `row0`, with
/// R(lag) = (1/N) sum_i v(i) v(i + lag)^T (6 x 6).
fn lag_term(r: &[f64], jac: &DMatrix<f64>, row0: usize, ns: usize, lag: usize) -> DMatrix<f64> {
    let v = |i: usize, c: usize| r[row0 + 6 * i + c];
    let mut rk = DMatrix::zeros(6, 6);
    for i in 0..ns - lag {
        for a in 0..6 {
            for b in 0..6 {
                rk[(a, b)] += v(i, a) * v(i + lag, b);
            }
        }
    }
    rk /= ns as f64;
    let mut acc = DMatrix::zeros(jac.ncols(), jac.ncols());
    for i in 0..ns - lag {
        let si = jac.rows(row0 + 6 * i, 6);
        let sj = jac.rows(row0 + 6 * (i + lag), 6);
        acc += si.transpose() * &rk * sj;
    }
    acc
}

/// Each parameter's estimate with its standard errors (coloured from `cov`, white from
/// `white`), and the names of those the data do not determine within their range.
fn estimates(
    space: &Params,
    x: &[f64],
    cov: &DMatrix<f64>,
    white: &WhiteCovariance,
) -> (Vec<ParamEstimate>, Vec<String>) {
    let n = space.len();
    let se = |c: &DMatrix<f64>, i: usize| -> Option<f64> {
        if white.undetermined[i] {
            None
        } else {
            Some(c[(i, i)].max(0.0).sqrt())
        }
    };
    let mut parameters = Vec::with_capacity(n);
    let mut not_identifiable = Vec::new();
    for i in 0..n {
        let s = se(cov, i);
        let identifiable = s.is_some_and(|s| s < space.range(i));
        if !identifiable {
            not_identifiable.push(space.names[i].clone());
        }
        parameters.push(ParamEstimate {
            name: space.names[i].clone(),
            unit: space.units[i].clone(),
            value: x[i],
            std_error: s,
            std_error_white: se(&white.m_inv, i),
            identifiable,
        });
    }
    (parameters, not_identifiable)
}

/// The correlation matrix of `cov` (0 where a parameter is not determined) and the pairs with
/// |rho| > [`COMPENSATING_RHO`], strongest first.
fn correlations(
    space: &Params,
    cov: &DMatrix<f64>,
    undetermined: &[bool],
) -> (Vec<Vec<f64>>, Vec<Compensating>) {
    let n = space.len();
    let mut correlation = vec![vec![0.0; n]; n];
    let mut compensating = Vec::new();
    for i in 0..n {
        for j in 0..n {
            if undetermined[i] || undetermined[j] {
                continue;
            }
            let d = (cov[(i, i)] * cov[(j, j)]).sqrt();
            if d > 0.0 {
                correlation[i][j] = (cov[(i, j)] / d).clamp(-1.0, 1.0);
            }
        }
        correlation[i][i] = if undetermined[i] { 0.0 } else { 1.0 };
        for j in (i + 1)..n {
            if correlation[i][j].abs() > COMPENSATING_RHO {
                compensating.push(Compensating {
                    a: space.names[i].clone(),
                    b: space.names[j].clone(),
                    rho: correlation[i][j],
                });
            }
        }
    }
    compensating.sort_by(|p, q| q.rho.abs().total_cmp(&p.rho.abs()));
    (correlation, compensating)
}

#[cfg(test)]
mod tests {
    use super::*;
    use sepval_core::factors::{Factor, FactorTable};

    /// The 17 factors of the default table.
    fn factors() -> Params {
        let mut p = Params::empty();
        for (name, f) in Factor::NAMES.iter().zip(FactorTable::default().0) {
            p.push(*name, "-", f.min, f.max);
        }
        p
    }

    #[test]
    fn white_residuals_give_the_cramer_rao_bound_and_duplicates_are_compensating() {
        // A linear model r = J x - y with white unit noise: Cov = (J^T J)^-1.
        let space = factors();
        let n = space.len();
        let rows = 6 * 50;
        let mut jac = DMatrix::zeros(rows, n);
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for k in 0..rows {
            for i in 0..n {
                jac[(k, i)] = next() * 10.0;
            }
            // Parameter 3 nearly duplicates parameter 2.
            jac[(k, 3)] = jac[(k, 2)] + 0.01 * next();
        }
        let r: Vec<f64> = (0..rows).map(|_| next() * 12f64.sqrt()).collect();
        let x = vec![0.0; n];
        let id = identifiability(&space, &x, &r, &jac, &[50]);
        let first = &id.compensating[0];
        assert_eq!(
            (first.a.as_str(), first.b.as_str()),
            ("xinerfac", "yinerfac")
        );
        assert!(first.rho < -0.9, "{}", first.rho);
        let white = id.parameters[0].std_error_white.unwrap();
        let m_inv = (jac.tr_mul(&jac)).try_inverse().unwrap();
        assert!(
            (white - m_inv[(0, 0)].sqrt()).abs() < 1e-9 * white,
            "{white}"
        );
    }

    #[test]
    fn a_parameter_without_information_is_not_identifiable() {
        let space = factors();
        let n = space.len();
        let mut jac = DMatrix::from_fn(6 * 20, n, |k, i| {
            ((k * 7 + i * 13) % 11) as f64 - 5.0 + (k * i) as f64 * 0.01
        });
        jac.column_mut(5).fill(0.0);
        let r = vec![0.5; 6 * 20];
        let id = identifiability(&space, &vec![0.0; n], &r, &jac, &[20]);
        assert!(id.not_identifiable.contains(&"caoff".to_string()));
        assert_eq!(id.parameters[5].std_error, None);
    }
}
