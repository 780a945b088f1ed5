//! Pre-flight trajectories taken into the prior (`sepval campaign init --preflight FILE.csv`,
//! docs/campaign.md "Beginning from pre-flight knowledge"): captive-trajectory tests or CFD
//! releases, fitted as releases are and believed less than flight.
//!
//! Each trajectory states its condition as a campaign release does (`# mach = ...`,
//! `# altitude_m = ...` and every axis of the grid: [`crate::release`]), and is refused
//! otherwise before anything is written. They are fitted together by the fit a campaign round
//! starts from (`sepval fit --method ga+lm`, [`sepval_fit::run_fit`], written to
//! CAMP/preflight/), each residual weighted by
//!
//!   1 / sigma^2,   sigma^2 = noise^2 + allowance^2,
//!
//! the noise estimated from the trajectories (second differences, [`sepval_fit::sigma`]) and the
//! stated model-form allowance (`--preflight-allowance-m`, default [`DEFAULT_ALLOWANCE_M`];
//! `--preflight-allowance-deg`, default [`DEFAULT_ALLOWANCE_DEG`]) added in quadrature: a
//! wind-tunnel or CFD trajectory is not flight, and believing it to its own noise would make
//! the prior as sure as a flight test of that store would (the allowance is the mismatch one
//! is prepared to see between the pre-flight source and flight).
//!
//! The prior becomes the Laplace approximation of the posterior (C. M. Bishop, *Pattern
//! Recognition and Machine Learning*, 2006, section 4.4; D. J. C. MacKay, *Information Theory,
//! Inference, and Learning Algorithms*, 2003, ch. 27) under the residuals linearised about the
//! fit's best factors x_hat (the Gauss-Newton model, J. Nocedal and S. J. Wright, *Numerical
//! Optimization*, 2nd ed., 2006, section 10.3): with J the Jacobian of the weighted residuals
//! r at x_hat (the refinement's, Levenberg-Marquardt's last), H = J^T J, and the prior's
//! precision P0 = diag(1 / sd0^2) about mu0,
//!
//!   Sigma = (H + P0)^-1,   mu = Sigma (H x_hat - J^T r + P0 mu0),
//!
//! the minimiser of |r + J (x - x_hat)|^2 + (x - mu0)^T P0 (x - mu0). Where the data see a
//! factor, mu is the fit's best; a factor they cannot see (its column of J zero) keeps its
//! prior mean and standard deviation. A factor the prior holds (sd0 = 0) stays held, its
//! residuals' part moved back to its mean (r + J_h (mu0_h - x_hat_h)). mu is kept within the
//! factors' ranges. Sigma is kept whole, so the draws are correlated ([`Prior::covariance`]);
//! each factor's belief is its marginal.

use std::path::Path;
use std::sync::Arc;

use nalgebra::{DMatrix, DVector};

use sepval_common::evaluation::{Event, Job};
use sepval_common::simulation::Simulator;
use sepval_core::factors::{Factor, FactorTable};
use sepval_fit::sigma::Sigma;
use sepval_fit::space::ParamSpace;
use sepval_fit::{FitOptions, run_fit};
use sepval_predict::record::ConditionRecord;
use sepval_run::inputs::InputsRecord;
use sepval_solve::ga::GaSettings;
use sepval_solve::lm::LmSettings;
use sepval_solve::run::ProgressObserver;

use crate::assess::StartEvaluator;
use crate::prior::{Belief, Prior, PriorSource};
use crate::release::NewRelease;
pub use crate::sources::{FactorChange, PreflightRecord, TrajectoryRecord};
use crate::{CampaignError, Refusal};

/// The default model-form allowance of a pre-flight trajectory's positions \[m\].
pub const DEFAULT_ALLOWANCE_M: f64 = 0.01;
/// The default model-form allowance of its attitudes \[deg\].
pub const DEFAULT_ALLOWANCE_DEG: f64 = 1.0;
/// The campaign's directory of the pre-flight fit.
pub const FIT_DIR: &str = "preflight";

/// The model-form allowance of pre-flight trajectories (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Allowance {
    /// Positions \[m\].
    pub pos_m: f64,
    /// Attitudes \[deg\].
    pub att_deg: f64,
}

impl Allowance {
    /// The allowance of the flags, each a finite number above 0 (a pre-flight trajectory is
    /// not flight: believing it to its own noise alone is refused).
    pub fn checked(pos_m: f64, att_deg: f64) -> Result<Allowance, CampaignError> {
        for (flag, v, unit) in [
            ("--preflight-allowance-m", pos_m, "m"),
            ("--preflight-allowance-deg", att_deg, "deg"),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(CampaignError::Setting {
                    flag,
                    value: v.to_string(),
                    expected: format!(
                        "expected a finite number of {unit} above 0: a pre-flight trajectory is not flight, and its model-form allowance is what it may differ from flight by"
                    ),
                });
            }
        }
        Ok(Allowance { pos_m, att_deg })
    }
}

/// The pre-flight trajectories of `init`, read and screened, and their allowance.
pub struct Preflight {
    /// The trajectories, each at its own condition.
    pub trajectories: Vec<NewRelease>,
    /// Their allowance.
    pub allowance: Allowance,
}

/// The prior `prior` updated by the pre-flight trajectories `p` (module docs), the fit written
/// to `dir`; `ga` the campaign's genetic search, `scenario` the campaign's scenario file (none:
/// the embedded default).
pub fn posterior(
    prior: &Prior,
    p: &Preflight,
    (table, scenario, ga): (&FactorTable, Option<&Path>, GaSettings),
    dir: &Path,
    start: &mut StartEvaluator<'_>,
    observer: &mut dyn ProgressObserver,
) -> Result<Prior, CampaignError> {
    let events = p
        .trajectories
        .iter()
        .map(|t| Event {
            name: t.given.display().to_string(),
            simulator: Simulator::new(&t.scenario),
            data: t.data.clone(),
        })
        .collect();
    let job = Job::new(events)?;
    let noise =
        Sigma::resolve(&job, None, None).map_err(|reason| Refusal::PreflightNoise { reason })?;
    let sigma = Sigma {
        pos_m: noise.pos_m.hypot(p.allowance.pos_m),
        att_deg: noise.att_deg.hypot(p.allowance.att_deg),
        source: format!(
            "the pre-flight trajectories' noise (estimated from the data) and their model-form allowance ({} m, {} deg) in quadrature",
            p.allowance.pos_m, p.allowance.att_deg
        ),
    };
    let inputs = InputsRecord {
        data: p
            .trajectories
            .iter()
            .map(|t| std::fs::canonicalize(&t.given).unwrap_or_else(|_| t.given.clone()))
            .collect(),
        scenario: scenario.map(Path::to_path_buf),
        extension: None,
        outliers: Default::default(),
    };
    let options = FitOptions::baseline(ga, sigma.clone(), &LmSettings::default(), dir, inputs);
    let mut evaluator = start(Arc::new(job)).map_err(CampaignError::from_eval)?;
    let out = run_fit(&options, evaluator.as_mut(), observer).map_err(|e| {
        if sepval_core::cancel::requested() {
            CampaignError::Interrupted
        } else {
            CampaignError::Preflight(Box::new(e))
        }
    })?;
    let lm = out.refined.ok_or(Refusal::PreflightNotRefined)?;
    let space = ParamSpace::new(table, &sepval_common::effects::EffectSet::NONE);
    let (mean, cov) = laplace(prior, &space, &lm.x, &lm.residuals, &lm.jacobian)?;
    let mut after = prior.clone();
    let mut factors = Vec::new();
    for (j, name) in space.params.names.iter().enumerate() {
        let before = prior.factors.get(name).copied().unwrap_or(Belief {
            mean: mean[j],
            sd: 0.0,
        });
        let b = Belief {
            mean: mean[j],
            sd: cov[(j, j)].max(0.0).sqrt(),
        };
        if before.sd > 0.0 {
            factors.push(FactorChange {
                factor: name.clone(),
                before,
                fitted: lm.x[j],
                after: b,
            });
        }
        after.factors.insert(name.clone(), b);
    }
    after.covariance = Some(
        (0..cov.nrows())
            .map(|i| cov.row(i).iter().copied().collect())
            .collect(),
    );
    after.source = format!("{} and pre-flight trajectories", prior.source);
    after.sources.push(PriorSource::Preflight(PreflightRecord {
        trajectories: p.trajectories.iter().map(record_of).collect(),
        allowance_m: p.allowance.pos_m,
        allowance_deg: p.allowance.att_deg,
        noise_pos_m: noise.pos_m,
        noise_att_deg: noise.att_deg,
        rms_pos_m: lm.goals.j_pos_m,
        rms_att_deg: lm.goals.j_att_deg,
        fit_dir: FIT_DIR.into(),
        factors,
    }));
    Ok(after)
}

fn record_of(t: &NewRelease) -> TrajectoryRecord {
    TrajectoryRecord {
        given: std::fs::canonicalize(&t.given)
            .unwrap_or_else(|_| t.given.clone())
            .display()
            .to_string(),
        sha256: t.sha256.clone(),
        condition: ConditionRecord::of(&t.scenario.flight),
        samples: t.data.len(),
        notes: t.notes.clone(),
    }
}

/// The Laplace approximation (module docs) of `prior` and the residuals `r` with Jacobian `jac`
/// at `x_hat`, in the order of `space`: the mean and the covariance (held factors' rows and
/// columns 0).
pub fn laplace(
    prior: &Prior,
    space: &ParamSpace,
    x_hat: &[f64],
    r: &[f64],
    jac: &DMatrix<f64>,
) -> Result<(Vec<f64>, DMatrix<f64>), CampaignError> {
    let n = space.len();
    if x_hat.len() != n || jac.ncols() != n || jac.nrows() != r.len() {
        return Err(Refusal::JacobianShape {
            rows: jac.nrows(),
            columns: jac.ncols(),
            residuals: r.len(),
            factors: n,
        }
        .into());
    }
    let belief = |j: usize| {
        prior
            .factors
            .get(&space.params.names[j])
            .copied()
            .unwrap_or(Belief {
                mean: x_hat[j],
                sd: 0.0,
            })
    };
    let free: Vec<usize> = (0..n).filter(|&j| belief(j).sd > 0.0).collect();
    // The residuals with the held factors moved back to their means.
    let mut r0 = DVector::from_column_slice(r);
    for j in (0..n).filter(|j| !free.contains(j)) {
        r0 += jac.column(j) * (belief(j).mean - x_hat[j]);
    }
    let jf = jac.select_columns(&free);
    let m = free.len();
    let h = jf.tr_mul(&jf);
    let mut a = h.clone();
    let mut rhs = &h * DVector::from_fn(m, |a, _| x_hat[free[a]]) - jf.tr_mul(&r0);
    for (k, &j) in free.iter().enumerate() {
        let b = belief(j);
        let p0 = 1.0 / (b.sd * b.sd);
        a[(k, k)] += p0;
        rhs[k] += p0 * b.mean;
    }
    if !a.iter().all(|v| v.is_finite()) {
        return Err(Refusal::JacobianNotFinite.into());
    }
    let chol = nalgebra::Cholesky::new(a).ok_or(Refusal::PrecisionNotPositive)?;
    let mu_free = chol.solve(&rhs);
    let cov_free = chol.inverse();
    let mut mean: Vec<f64> = (0..n).map(|j| belief(j).mean).collect();
    let mut cov = DMatrix::zeros(n, n);
    for (a, &i) in free.iter().enumerate() {
        mean[i] = mu_free[a].clamp(space.params.lo[i], space.params.hi[i]);
        for (b, &j) in free.iter().enumerate() {
            cov[(i, j)] = 0.5 * (cov_free[(a, b)] + cov_free[(b, a)]);
        }
    }
    debug_assert!(
        space
            .params
            .names
            .iter()
            .zip(Factor::NAMES)
            .all(|(a, b)| a == b)
    );
    Ok((mean, cov))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear model seeing two factors: the posterior is the textbook product of Gaussians,
    /// the factors it does not see keep their prior.
    #[test]
    fn the_laplace_posterior_of_a_linear_model_is_the_product_of_gaussians() {
        let table = FactorTable::default();
        let prior = Prior::default_of(&table);
        let space = ParamSpace::new(&table, &sepval_common::effects::EffectSet::NONE);
        let n = space.len();
        // Residuals r = (x0 - 0.6) / 0.01 and (x0 + x1 - 1.5) / 0.02 at x_hat = (0.6, 0.9, ...).
        let mut x_hat: Vec<f64> = (0..n)
            .map(|j| prior.factors[&space.params.names[j]].mean)
            .collect();
        x_hat[0] = 0.6;
        x_hat[1] = 0.9;
        let mut jac = DMatrix::zeros(2, n);
        jac[(0, 0)] = 1.0 / 0.01;
        jac[(1, 0)] = 1.0 / 0.02;
        jac[(1, 1)] = 1.0 / 0.02;
        let r = [0.0, 0.0];
        let (mean, cov) = laplace(&prior, &space, &x_hat, &r, &jac).unwrap();
        let b0 = prior.factors["fwdfac"];
        let b1 = prior.factors["aftfac"];
        let h = jac.columns(0, 2).tr_mul(&jac.columns(0, 2));
        let p0 = DMatrix::from_diagonal(&DVector::from_vec(vec![
            1.0 / (b0.sd * b0.sd),
            1.0 / (b1.sd * b1.sd),
        ]));
        let want = (&h + &p0).try_inverse().unwrap();
        let mu = &want
            * (&h * DVector::from_vec(vec![0.6, 0.9])
                + &p0 * DVector::from_vec(vec![b0.mean, b1.mean]));
        for a in 0..2 {
            assert!((mean[a] - mu[a]).abs() < 1e-9, "{} {}", mean[a], mu[a]);
            for b in 0..2 {
                assert!((cov[(a, b)] - want[(a, b)]).abs() < 1e-12);
            }
        }
        assert!(cov[(0, 1)] < 0.0, "seen together, the two are correlated");
        let j = 5;
        let b = prior.factors[&space.params.names[j]];
        assert!((mean[j] - b.mean).abs() < 1e-12 && (cov[(j, j)].sqrt() - b.sd).abs() < 1e-12);
    }

    #[test]
    fn an_allowance_must_be_a_positive_number() {
        assert!(Allowance::checked(0.01, 1.0).is_ok());
        for (m, d, says) in [
            (0.0, 1.0, "--preflight-allowance-m 0"),
            (-1.0, 1.0, "--preflight-allowance-m -1"),
            (0.01, f64::NAN, "--preflight-allowance-deg NaN"),
        ] {
            let e = Allowance::checked(m, d).unwrap_err().to_string();
            assert!(e.contains(says) && e.contains("not flight"), "{e}");
        }
    }
}
