//! The separation of each condition (docs/planning.md section 12.2): how far apart a release
//! there would put every two models once each has absorbed what it can of the other.
//!
//! For two models a and b, "a true, b refitted": b's parameters are refitted (linearised at
//! its own fit, [`crate::refit`]) to a's noise-free trajectories at the releases flown and at
//! the condition, pooled; what b cannot absorb is a chi-square in units of the noise
//! (sigma_pos_m, sigma_att_deg of the diagnosis). A factor change that absorbs the difference
//! leaves nothing: such models are not separated however different their trajectories look.
//! The expected BIC of b minus a's on the pooled releases is then
//!
//! `margin(a -> b) = chi2(a -> b) + (p_b - p_a) ln m`
//!
//! (p: free parameters, m: residuals pooled, 6 per sample). The pair's separation is the
//! smaller of its two margins (whichever is true, the other must lose), and a release
//! separates the pair when it is above [`SEPARATION_THRESHOLD`], the strong evidence of Kass
//! and Raftery that the diagnosis names rivals by. A condition's separation is the smallest
//! over its pairs, the hardest pair's ([`crate::ranking`] counts the pairs separated first).

use serde::{Deserialize, Serialize};

use crate::models::Models;
use crate::refit::Normal;
use crate::simulate::{Missing, Simulated};

/// The margin above which a release separates two models: the BIC distance of strong
/// evidence (Kass and Raftery 1995), the diagnosis's own rival margin.
pub const SEPARATION_THRESHOLD: f64 = sepval_diagnose::RIVAL_MARGIN;

/// Two models at one condition (or at the releases flown alone).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PairSeparation {
    /// The two models (indices into the models: the answer is 0).
    pub models: [usize; 2],
    /// chi2 left when the second is refitted to the first's trajectories, and the other way.
    pub chi2: [f64; 2],
    /// The expected BIC margins of those two refits.
    pub margins: [f64; 2],
    /// The smaller margin.
    pub separation: f64,
}

impl PairSeparation {
    /// Whether the release separates the pair.
    pub fn separated(&self) -> bool {
        self.separation > SEPARATION_THRESHOLD
    }
}

/// The separations of a plan.
#[derive(Debug, Clone)]
pub struct Separations {
    /// Every pair at the releases flown alone (what the new release adds to).
    pub flown: Vec<PairSeparation>,
    /// Per condition: every pair, or why a model could not be compared there.
    pub conditions: Vec<Result<Vec<PairSeparation>, Missing>>,
}

impl Separations {
    /// The separation of condition `k`: the smallest over its pairs (none without rivals or
    /// where a model did not run).
    pub fn of(&self, k: usize) -> Option<f64> {
        let pairs = self.conditions[k].as_ref().ok()?;
        pairs.iter().map(|p| p.separation).reduce(f64::min)
    }
}

/// The separation of every pair at every condition.
pub fn separations(models: &Models, sims: &Simulated) -> Separations {
    let n = models.list.len();
    let pairs: Vec<[usize; 2]> = (0..n)
        .flat_map(|a| (a + 1..n).map(move |b| [a, b]))
        .collect();
    let flown_samples: usize = sims.samples[..sims.flown].iter().sum();
    // Each ordered pair's normal equations over the releases flown.
    let pooled = |a: usize, b: usize| -> Normal {
        let mut n = Normal::zeros(models.list[b].parameters());
        for e in 0..sims.flown {
            let normal = sims.runs[b].normal[e]
                .as_ref()
                .expect("every model runs the releases flown with every step");
            let (rhs, vv) = normal.cross[a]
                .as_ref()
                .expect("every model runs the releases flown");
            n.add(&normal.gram, rhs, *vv);
        }
        n
    };
    let margin = |a: usize, b: usize, chi2: f64, samples: usize| {
        let (pa, pb) = (models.list[a].parameters(), models.list[b].parameters());
        chi2 + (pb as f64 - pa as f64) * ((6 * samples) as f64).ln()
    };
    let pair = |[a, b]: [usize; 2], ab: &Normal, ba: &Normal, samples: usize| {
        let chi2 = [ab.refit_chi2(), ba.refit_chi2()];
        let margins = [
            margin(a, b, chi2[0], samples),
            margin(b, a, chi2[1], samples),
        ];
        PairSeparation {
            models: [a, b],
            chi2,
            margins,
            separation: margins[0].min(margins[1]),
        }
    };
    let base: Vec<(Normal, Normal)> = pairs
        .iter()
        .map(|&[a, b]| (pooled(a, b), pooled(b, a)))
        .collect();
    let flown = pairs
        .iter()
        .zip(&base)
        .map(|(&p, (ab, ba))| pair(p, ab, ba, flown_samples))
        .collect();
    let conditions = (sims.flown..sims.samples.len())
        .map(|e| {
            let samples = flown_samples + sims.samples[e];
            let with = |a: usize, b: usize, n: &Normal| -> Result<Normal, Missing> {
                let normal = sims.runs[b].normal[e]
                    .as_ref()
                    .map_err(|r| Missing::Model {
                        model: models.list[b].name.clone(),
                        why: Box::new(r.clone()),
                    })?;
                let (rhs, vv) = normal.cross[a].as_ref().ok_or_else(|| Missing::DidNotRun {
                    model: models.list[a].name.clone(),
                })?;
                let mut n = n.clone();
                n.add(&normal.gram, rhs, *vv);
                Ok(n)
            };
            pairs
                .iter()
                .zip(&base)
                .map(|(&[a, b], (ab, ba))| {
                    Ok(pair([a, b], &with(a, b, ab)?, &with(b, a, ba)?, samples))
                })
                .collect()
        })
        .collect();
    Separations { flown, conditions }
}
