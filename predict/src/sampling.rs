//! The factor samples (docs/prediction.md section 13.3): the answer's parameters drawn from a
//! multivariate normal about its estimate with the covariance of its refit,
//! C_ij = s_i s_j rho_ij (s: the white-residual standard errors of `identifiability`, the
//! Cramer-Rao bound of the noise, rho: its correlation matrix; a parameter whose standard error
//! is not determined is held at its estimate). The coloured-residual standard errors are not
//! used: what colours the residuals is the model's form, which the discrepancy carries
//! ([`crate::discrepancy`]); counting it in the factors too would count it twice. C is factored as C = V diag(lambda) V^T (its symmetric eigen
//! decomposition, negative eigenvalues of rounding set to 0: a correlation of 0.999 leaves C
//! singular to rounding, where a Cholesky factor fails), and a draw is x = x_hat + V
//! diag(sqrt(lambda)) z, z standard normal. A draw outside the parameters' bounds is rejected
//! and drawn again (the normal truncated to the box), at most [`MAX_REDRAWS`] times, after
//! which the last draw is clamped into the box.
//!
//! Every sample has its own generator, ChaCha8 seeded from the seed and the sample's index
//! ([`sample_rng`]), so a sample is the same whichever part, batch or worker it goes through,
//! and the bands depend only on the seed and the number of samples. Each sample first chooses
//! its model by the ensemble's weights (one uniform), then draws its parameters.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use sepval_common::evaluation::Candidate;
use sepval_fit::space::ParamSpace;
use sepval_solve::identifiability::Identifiability;

use crate::ensemble::{Ensemble, SHARED};

/// Draws outside the bounds rejected before the last is clamped.
pub const MAX_REDRAWS: usize = 64;

/// The stream of a sample's generator that draws its model and parameters.
pub const STREAM_PARAMETERS: u64 = 0;
/// The stream that draws its model-form deviation and its measurement noise.
pub const STREAM_BANDS: u64 = 1;

/// The generator of sample `index` on `stream`, from `seed`: ChaCha8 seeded with a SplitMix64
/// mix of the three.
pub fn sample_rng(seed: u64, index: u64, stream: u64) -> ChaCha8Rng {
    let mut z = seed
        ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ stream.wrapping_mul(0xD1B5_4A32_D192_ED03);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ChaCha8Rng::seed_from_u64(z ^ (z >> 31))
}

/// A standard normal deviate.
pub fn normal(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

/// The multivariate normal of a model's parameters, truncated to their bounds.
#[derive(Debug, Clone)]
pub struct ParameterDistribution {
    /// The estimate.
    pub mean: Vec<f64>,
    /// V diag(sqrt(lambda)): a draw is mean + factor z.
    pub factor: DMatrix<f64>,
    /// Lower bounds.
    pub lo: Vec<f64>,
    /// Upper bounds.
    pub hi: Vec<f64>,
    /// Standard deviation of each parameter (0: held).
    pub std: Vec<f64>,
}

impl ParameterDistribution {
    /// The distribution of the parameters `space` at `mean` with the standard errors and
    /// correlations of `id`, matched by name (a parameter `id` does not name, or whose standard
    /// error is not determined, is held).
    pub fn of(space: &ParamSpace, mean: &[f64], id: &Identifiability) -> ParameterDistribution {
        let n = space.len();
        let at: Vec<Option<usize>> = space
            .params
            .names
            .iter()
            .map(|name| id.names.iter().position(|m| m == name))
            .collect();
        let std: Vec<f64> = at
            .iter()
            .map(|k| {
                k.and_then(|k| id.parameters.get(k)?.std_error_white)
                    .filter(|s| s.is_finite() && *s > 0.0)
                    .unwrap_or(0.0)
            })
            .collect();
        let cov = DMatrix::from_fn(n, n, |i, j| {
            let rho = match (at[i], at[j]) {
                (Some(a), Some(b)) if i == j => f64::from(u8::from(a == b)),
                (Some(a), Some(b)) => id
                    .correlation
                    .get(a)
                    .and_then(|r| r.get(b))
                    .copied()
                    .filter(|r| r.is_finite())
                    .unwrap_or(0.0),
                _ => 0.0,
            };
            std[i] * std[j] * rho
        });
        ParameterDistribution {
            mean: mean.to_vec(),
            factor: square_root(cov),
            lo: space.params.lo.clone(),
            hi: space.params.hi.clone(),
            std,
        }
    }

    /// One draw within the bounds.
    pub fn draw(&self, rng: &mut ChaCha8Rng) -> Vec<f64> {
        let n = self.mean.len();
        let mut x = self.mean.clone();
        for _ in 0..=MAX_REDRAWS {
            let z = DVector::from_fn(n, |_, _| normal(rng));
            let d = &self.factor * z;
            x = self.mean.iter().zip(d.iter()).map(|(m, d)| m + d).collect();
            if self.inside(&x) {
                return x;
            }
        }
        x.iter()
            .zip(self.lo.iter().zip(&self.hi))
            .map(|(v, (lo, hi))| v.clamp(*lo, *hi))
            .collect()
    }

    fn inside(&self, x: &[f64]) -> bool {
        x.iter()
            .zip(self.lo.iter().zip(&self.hi))
            .all(|(v, (lo, hi))| v.is_finite() && *v >= *lo && *v <= *hi)
    }
}

/// V diag(sqrt(max(lambda, 0))) of the symmetric matrix `c`.
fn square_root(c: DMatrix<f64>) -> DMatrix<f64> {
    let n = c.nrows();
    if n == 0 || c.iter().all(|v| *v == 0.0) {
        return DMatrix::zeros(n, n);
    }
    let eig = SymmetricEigen::new(c);
    let mut f = eig.eigenvectors;
    for (j, l) in eig.eigenvalues.iter().enumerate() {
        let s = if l.is_finite() {
            l.max(0.0).sqrt()
        } else {
            0.0
        };
        f.column_mut(j).scale_mut(s);
    }
    f
}

/// One sample: its model and candidate.
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    /// The index of its model in the ensemble.
    pub model: usize,
    /// Its candidate.
    pub candidate: Candidate,
}

/// The samples of a prediction: the answer's distribution and the ensemble they are drawn
/// from.
#[derive(Debug, Clone)]
pub struct Sampler {
    /// The answer's parameter distribution.
    pub answer: ParameterDistribution,
    /// The seed.
    pub seed: u64,
}

impl Sampler {
    /// Sample `index`: its model by the weights, then its parameters.
    pub fn sample(&self, ensemble: &Ensemble, index: u64) -> Sample {
        let mut rng = sample_rng(self.seed, index, STREAM_PARAMETERS);
        let u: f64 = rng.random();
        let mut model = ensemble.members.len() - 1;
        let mut acc = 0.0;
        for (i, m) in ensemble.members.iter().enumerate() {
            acc += m.weight;
            if u < acc {
                model = i;
                break;
            }
        }
        let drawn = self.answer.draw(&mut rng);
        let m = &ensemble.members[model];
        let x: Vec<f64> = if model == 0 {
            drawn
        } else {
            // A rival: the answer's deviations of the shared factors, within its bounds.
            let mut x = m.x.clone();
            for i in 0..SHARED {
                let v = m.x[i] + drawn[i] - self.answer.mean[i];
                x[i] = v.clamp(m.space.params.lo[i], m.space.params.hi[i]);
            }
            x
        };
        let candidate = m.space.candidate(&x).unwrap_or(m.candidate);
        Sample { model, candidate }
    }
}
