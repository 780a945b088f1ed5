//! A way to begin when nothing is safe to fly (docs/campaign.md, "When nothing is safe to
//! fly"): under the prior, which factors' uncertainty makes the least risky condition risky,
//! and how much narrower each would have to be known for its probability of failing to fall
//! within the fly risk: the pre-flight test to ask for.
//!
//! The least risky condition's samples are flown again (the same draws as its assessment: the
//! same seed and generators, `assess::draws`), each with its smallest clearance and
//! whether it fails (below the criterion, or diverged). For factor j, a prior whose standard
//! deviation is k sd_j (k in (0, 1]) is weighed by importance sampling on those samples: the
//! prior draws every factor independently from a normal truncated to the factor's range, so
//! sample s's weight is the ratio of the two truncated normal densities of its x_sj,
//!
//!   w_s(k) = [phi(z_s / k) / (k Z(k))] / [phi(z_s) / Z(1)],  z_s = (x_sj - mu_j) / sd_j,
//!   Z(k) = Phi((hi_j - mu_j) / (k sd_j)) - Phi((lo_j - mu_j) / (k sd_j)),
//!
//! (Owen, *Monte Carlo theory, methods and examples*, 2013, ch. 9: self-normalised importance
//! sampling), and P_fail(k) = sum_s w_s f_s / sum_s w_s. The effective number of samples is
//! n_eff = (sum w)^2 / sum w^2 (Kish's). A narrowing is said to suffice only when P_fail(k)
//! plus twice its standard error sqrt(P (1 - P) / n_eff), and at least 3 / n_eff (the rule of
//! three: no failure among n_eff samples bounds P near 3 / n_eff at 95 %), is within the fly
//! risk; the largest such k on a grid of shares from 1 down to [`SMALLEST_SHARE`] is the one
//! reported. Where none suffices, the factor alone cannot make the condition safe to fly (or
//! the samples cannot show that it would: more samples would).
//!
//! Only the prior is weighed: after a release the factors are the diagnosis's, correlated,
//! and what they lack is learnt by flying. A prior from pre-flight trajectories is correlated
//! too ([`crate::preflight`]); narrowing one factor's marginal keeps the others' conditional
//! on it, so its weight is still the ratio of its marginals (exact for the normal, near it
//! where the truncation cuts little), while the joint narrowing's product of marginals is then
//! an approximation.

use serde::{Deserialize, Serialize};
use statrs::distribution::{Continuous, ContinuousCDF, Normal};

use sepval_common::scenario::Scenario;
use sepval_common::simulation::sample_times;
use sepval_core::factors::Factor;
use sepval_envelope::Grid;
use sepval_predict::clearance;
use sepval_predict::simulate::{self, GridTrajectory};

use crate::CampaignError;
use crate::assess::{AssessSettings, Model, StartEvaluator, draws, fly};

/// The smallest share of a factor's prior standard deviation tried.
pub const SMALLEST_SHARE: f64 = 0.05;
/// The shares tried, largest first.
const SHARES: [f64; 17] = [
    1.0,
    0.9,
    0.8,
    0.7,
    0.6,
    0.5,
    0.45,
    0.4,
    0.35,
    0.3,
    0.25,
    0.2,
    0.15,
    0.12,
    0.1,
    0.07,
    SMALLEST_SHARE,
];

/// One factor's part in the least risky condition's risk.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FactorNarrowing {
    /// The factor.
    pub factor: String,
    /// Its prior standard deviation.
    pub sd: f64,
    /// P(fail) were it known to half its standard deviation.
    pub p_fail_at_half: f64,
    /// The largest share of its standard deviation that makes the condition safe to fly
    /// (module docs); none: no share down to [`SMALLEST_SHARE`] does, alone.
    pub share_needed: Option<f64>,
    /// That standard deviation (`share_needed` x `sd`).
    pub sd_needed: Option<f64>,
}

/// The most effective factors narrowed together, each to the same share of its spread.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointNarrowing {
    /// The factors.
    pub factors: Vec<String>,
    /// The largest common share of their standard deviations that makes the condition safe
    /// to fly.
    pub share_needed: f64,
}

/// What would make the least risky condition safe to fly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Narrowing {
    /// The condition's index in the grid.
    pub index: usize,
    /// Its probability of failing under the prior.
    pub p_fail: f64,
    /// The fly risk.
    pub fly_risk: f64,
    /// The smallest clearance there with every factor at its prior mean \[mm\] (null: that
    /// run diverged).
    #[serde(with = "sepval_core::nonfinite")]
    pub mean_clearance_mm: f64,
    /// Whether the prior's mean clears the criterion there: when it does not, no narrowing
    /// about that mean makes the condition safe to fly.
    pub mean_clears: bool,
    /// Every factor with a spread, the one whose narrowing helps most first.
    pub factors: Vec<FactorNarrowing>,
    /// When no factor alone suffices: the fewest of the most effective (up to
    /// [`JOINT_MOST`]) that suffice narrowed together.
    pub joint: Option<JointNarrowing>,
}

/// The most factors narrowed together.
pub const JOINT_MOST: usize = 5;

impl Narrowing {
    /// The pre-flight test to ask for, in words: the factors that make the condition safe to
    /// fly alone, least narrowing first, else the three that help most.
    pub fn words(&self) -> String {
        if !self.mean_clears {
            return format!(
                "even the prior's mean fails to clear (smallest clearance {} mm): no narrowing about that mean makes it safe to fly; what engineers know before flight must move the mean (pre-flight trajectories, --preflight; the store's data, --prior-daveml; or a --prior of measured values) or the criterion must change",
                number(self.mean_clearance_mm)
            );
        }
        let mut enough: Vec<&FactorNarrowing> = self
            .factors
            .iter()
            .filter(|f| f.share_needed.is_some())
            .collect();
        let share = |f: &&FactorNarrowing| f.share_needed.unwrap_or(0.0);
        enough.sort_by(|a, b| share(b).total_cmp(&share(a)));
        if let (true, Some(j)) = (enough.is_empty(), &self.joint) {
            return format!(
                "it would be safe to fly (P(fail) within {}) with {} known together to {:.0} % of their prior spreads: the pre-flight test to ask for; give it to `campaign init` as pre-flight trajectories (--preflight), the store's data with uncertainty (--prior-daveml) or a --prior",
                self.fly_risk,
                j.factors.join(", "),
                100.0 * j.share_needed
            );
        }
        if enough.is_empty() {
            let top: Vec<String> = self
                .factors
                .iter()
                .take(3)
                .map(|f| {
                    format!(
                        "{} (P(fail) {:.3} at half its spread)",
                        f.factor, f.p_fail_at_half
                    )
                })
                .collect();
            return format!(
                "no single factor known better makes it safe to fly; the spreads that matter most: {}: narrow them together (a pre-flight test of the store's aerodynamics and ejector), or begin from pre-flight knowledge of known accuracy: trajectories (--preflight), the store's data with uncertainty (--prior-daveml) or a --prior",
                top.join(", ")
            );
        }
        let each: Vec<String> = enough
            .iter()
            .take(3)
            .map(|f| {
                format!(
                    "{} known to sd {} ({:.0} % of the prior's {})",
                    f.factor,
                    number(f.sd_needed.unwrap_or(f64::NAN)),
                    100.0 * f.share_needed.unwrap_or(f64::NAN),
                    number(f.sd)
                )
            })
            .collect();
        format!(
            "it would be safe to fly (P(fail) within {}) with {}: the pre-flight test to ask for; give it to `campaign init` as pre-flight trajectories (--preflight), the store's data with uncertainty (--prior-daveml) or a --prior",
            self.fly_risk,
            each.join(", or ")
        )
    }
}

fn number(v: f64) -> String {
    format!("{}", (v * 1e4).round() / 1e4)
}

/// The narrowing of the prior `model` that would make condition `index` of `grid` safe to
/// fly (module docs).
pub fn narrowing(
    model: &Model,
    (grid, base): (&Grid, &Scenario),
    index: usize,
    settings: &AssessSettings,
    (p_fail, fly_risk): (f64, f64),
    start: &mut StartEvaluator<'_>,
) -> Result<Narrowing, CampaignError> {
    let times = sample_times(base.integrator.t_end_s, base.integrator.rate_hz);
    let points = simulate::Grid::of(&times);
    let (candidates, _) = draws(model, settings)?;
    let scenario = grid.scenario(base, index);
    let (_, runs) = fly(&scenario, &times, &points, &candidates, start)?;
    let trajectories: Vec<Option<&GridTrajectory>> =
        runs.trajectories.iter().map(|t| t.as_ref().ok()).collect();
    let none = vec![[0.0; 6]; points.len()];
    let c = &settings.clearance;
    let (_, each) = clearance::assess_each(
        c,
        &trajectories,
        &none,
        &points,
        settings.seed,
        settings.threads,
    )?;
    let criterion_mm = 1e3 * c.criterion_m;
    let fails: Vec<bool> = each
        .iter()
        .map(|m| m.is_none_or(|m| m.is_nan() || m < criterion_mm))
        .collect();
    let d = &model.distribution;
    let mut factors: Vec<FactorNarrowing> = (0..d.mean.len().min(Factor::NAMES.len()))
        .filter(|&j| d.std[j] > 0.0)
        .map(|j| {
            let x: Vec<f64> = candidates.iter().map(|c| c.factors.0[j]).collect();
            let marginal = Marginal {
                mean: d.mean[j],
                sd: d.std[j],
                lo: d.lo[j],
                hi: d.hi[j],
            };
            let weighed = |k: f64| weighed_p_fail(&marginal, &x, &fails, k);
            let share = SHARES
                .iter()
                .copied()
                .find(|&k| weighed(k).upper() <= fly_risk);
            FactorNarrowing {
                factor: Factor::NAMES[j].to_string(),
                sd: d.std[j],
                p_fail_at_half: weighed(0.5).p,
                share_needed: share,
                sd_needed: share.map(|k| k * d.std[j]),
            }
        })
        .collect();
    factors.sort_by(|a, b| {
        b.share_needed
            .unwrap_or(0.0)
            .total_cmp(&a.share_needed.unwrap_or(0.0))
            .then(a.p_fail_at_half.total_cmp(&b.p_fail_at_half))
    });
    let joint = if factors.iter().any(|f| f.share_needed.is_some()) {
        None
    } else {
        joint(d, &candidates, &fails, &factors, fly_risk)
    };
    let mean = model
        .space
        .candidate(&d.mean)
        .map_err(CampaignError::Model)?;
    let (_, ran) = fly(&scenario, &times, &points, &[mean], start)?;
    let at_mean: Vec<Option<&GridTrajectory>> =
        ran.trajectories.iter().map(|t| t.as_ref().ok()).collect();
    let (_, m) = clearance::assess_each(c, &at_mean, &none, &points, settings.seed, 1)?;
    let mean_clearance_mm = m[0].unwrap_or(f64::NAN);
    Ok(Narrowing {
        index,
        p_fail,
        fly_risk,
        mean_clearance_mm,
        mean_clears: mean_clearance_mm >= criterion_mm,
        factors,
        joint,
    })
}

/// The fewest of the most effective `factors` (at most [`JOINT_MOST`]) that make the
/// condition safe to fly narrowed together to one share, and that share: the weights are the
/// product of each factor's (the prior draws them independently).
fn joint(
    d: &sepval_predict::sampling::ParameterDistribution,
    candidates: &[sepval_common::evaluation::Candidate],
    fails: &[bool],
    factors: &[FactorNarrowing],
    fly_risk: f64,
) -> Option<JointNarrowing> {
    let index = |name: &str| Factor::NAMES.iter().position(|n| *n == name);
    let chosen: Vec<usize> = factors.iter().filter_map(|f| index(&f.factor)).collect();
    for m in 2..=JOINT_MOST.min(chosen.len()) {
        let set = &chosen[..m];
        let found = SHARES.iter().copied().find(|&k| {
            let mut w = vec![1.0; candidates.len()];
            for &j in set {
                let marginal = Marginal {
                    mean: d.mean[j],
                    sd: d.std[j],
                    lo: d.lo[j],
                    hi: d.hi[j],
                };
                let x: Vec<f64> = candidates.iter().map(|c| c.factors.0[j]).collect();
                for (ws, v) in w.iter_mut().zip(weights(&marginal, &x, k)) {
                    *ws *= v;
                }
            }
            weighed(&w, fails).upper() <= fly_risk
        });
        if let Some(k) = found {
            return Some(JointNarrowing {
                factors: set.iter().map(|&j| Factor::NAMES[j].to_string()).collect(),
                share_needed: k,
            });
        }
    }
    None
}

/// One factor's prior: a normal truncated to its range.
struct Marginal {
    mean: f64,
    sd: f64,
    lo: f64,
    hi: f64,
}

/// A probability weighed from samples, with its effective number of samples.
struct Weighed {
    p: f64,
    n_eff: f64,
}

impl Weighed {
    /// The bound a narrowing must meet (module docs).
    fn upper(&self) -> f64 {
        if self.n_eff.is_nan() || self.n_eff <= 0.0 {
            return 1.0;
        }
        let se = (self.p * (1.0 - self.p) / self.n_eff).sqrt();
        (self.p + 2.0 * se).max(3.0 / self.n_eff)
    }
}

/// Each sample's importance weight (module docs) were the factor's prior's standard
/// deviation `k` times its own; `x` the samples' values of the factor.
fn weights(m: &Marginal, x: &[f64], k: f64) -> Vec<f64> {
    let n = Normal::new(0.0, 1.0).expect("the standard normal");
    let mass = |k: f64| n.cdf((m.hi - m.mean) / (k * m.sd)) - n.cdf((m.lo - m.mean) / (k * m.sd));
    let (z1, zk) = (mass(1.0), mass(k));
    x.iter()
        .map(|v| {
            let z = (v - m.mean) / m.sd;
            let w = (n.pdf(z / k) / (k * zk)) / (n.pdf(z) / z1);
            if w.is_finite() { w } else { 0.0 }
        })
        .collect()
}

/// The weighed share of the samples that fail.
fn weighed(w: &[f64], fails: &[bool]) -> Weighed {
    let (mut sw, mut sw2, mut swf) = (0.0, 0.0, 0.0);
    for (w, f) in w.iter().zip(fails) {
        sw += w;
        sw2 += w * w;
        if *f {
            swf += w;
        }
    }
    if sw <= 0.0 {
        return Weighed { p: 1.0, n_eff: 0.0 };
    }
    Weighed {
        p: swf / sw,
        n_eff: sw * sw / sw2,
    }
}

/// P(fail) of the samples `x` (the factor's values) and `fails` were the factor's prior's
/// standard deviation `k` times its own.
fn weighed_p_fail(m: &Marginal, x: &[f64], fails: &[bool], k: f64) -> Weighed {
    weighed(&weights(m, x, k), fails)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples of a standard normal factor that fail beyond 1.5: the weighed P(fail) at share
    /// k is the truncated normal's tail beyond 1.5 at sd k, within its error.
    #[test]
    fn a_narrowed_factor_is_weighed_as_its_narrower_prior_would_fail() {
        let n = Normal::new(0.0, 1.0).unwrap();
        let m = Marginal {
            mean: 0.0,
            sd: 1.0,
            lo: -3.0,
            hi: 3.0,
        };
        // Stratified draws of the truncated prior: its quantiles.
        let (a, b) = (n.cdf(-3.0), n.cdf(3.0));
        let x: Vec<f64> = (0..20_000)
            .map(|i| n.inverse_cdf(a + (b - a) * (i as f64 + 0.5) / 20_000.0))
            .collect();
        let fails: Vec<bool> = x.iter().map(|v| *v > 1.5).collect();
        for k in [1.0, 0.7, 0.5] {
            let w = weighed_p_fail(&m, &x, &fails, k);
            let z = n.cdf(3.0 / k) - n.cdf(-3.0 / k);
            let truth = (n.cdf(3.0 / k) - n.cdf(1.5 / k)) / z;
            assert!(
                (w.p - truth).abs() < 4.0 * (truth / w.n_eff).sqrt() + 1e-4,
                "{k}: {} {truth}",
                w.p
            );
        }
        // Narrower, fewer effective samples; and the bound is never below the rule of three.
        let (w1, w5) = (
            weighed_p_fail(&m, &x, &fails, 1.0),
            weighed_p_fail(&m, &x, &fails, 0.5),
        );
        assert!(w5.n_eff < w1.n_eff && w5.upper() >= 3.0 / w5.n_eff);
    }
}
