//! The hill climber Anderson's study compares the genetic algorithm against: a gradient-based
//! local search on the weighted goal sum F = w_pos J_pos + w_att J_att (each goal divided by its
//! noise level), started from the nominal factors, within a budget of about 500 simulations.
//!
//! Each iteration estimates the gradient by forward differences (one batch of n simulations,
//! a step of `fd_step` of each factor's range, taken inward at a bound), then searches along
//! the steepest-descent direction in range-normalised coordinates with a batch of geometrically
//! shrinking steps (projected onto the bounds), and moves to the best point if it improves F.
//! When no trial step improves F, the step shrinks; below `min_step` the climber has reached a
//! point it cannot leave (a local optimum at its resolution) and stops.

use sepval_common::evaluation::{EvalError, Outcome};
use serde::{Deserialize, Serialize};

use crate::search::ga::{Member, ParetoProblem};

/// Settings of the hill climber.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HillSettings {
    /// Most simulations to run.
    pub budget: usize,
    /// Finite-difference step, as a fraction of each factor's range.
    pub fd_step: f64,
    /// First line-search step, in range-normalised units.
    pub initial_step: f64,
    /// Step below which the search stops.
    pub min_step: f64,
    /// Trial points per line search.
    pub line_points: usize,
}

impl Default for HillSettings {
    fn default() -> Self {
        HillSettings {
            budget: 500,
            fd_step: 1e-3,
            initial_step: 0.1,
            min_step: 1e-4,
            line_points: 6,
        }
    }
}

/// Why the climber stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HillStop {
    /// The budget does not allow another iteration.
    Budget,
    /// No step down-hill larger than the minimum exists: a local optimum.
    LocalOptimum,
    /// The start could not be simulated.
    StartFailed,
}

/// The result of a climb.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HillResult {
    /// The best point found.
    pub best: Member,
    /// Its weighted goal sum.
    pub best_weighted: f64,
    /// Simulations run.
    pub evaluations: u64,
    /// (simulations so far, best weighted sum, best objectives) after each iteration.
    pub history: Vec<(u64, f64, [f64; 2])>,
    /// Every point evaluated (for the Pareto front of what the climber saw).
    pub visited: Vec<Member>,
    /// Why it stopped.
    pub stop: HillStop,
}

/// Climbs from `start` (values within the problem's bounds).
pub fn climb(
    problem: &mut dyn ParetoProblem,
    start: &[f64],
    weights: [f64; 2],
    settings: &HillSettings,
) -> Result<HillResult, EvalError> {
    let genes = problem.genes().to_vec();
    let n = genes.len();
    let lo: Vec<f64> = genes.iter().map(|g| g.min).collect();
    let span: Vec<f64> = genes.iter().map(|g| g.max - g.min).collect();
    let to_values = |u: &[f64]| -> Vec<f64> {
        (0..n)
            .map(|i| (lo[i] + u[i].clamp(0.0, 1.0) * span[i]).clamp(genes[i].min, genes[i].max))
            .collect()
    };
    let f_of = |o: &Outcome| {
        let [a, b] = o.objectives();
        weights[0] * a + weights[1] * b
    };
    let mut visited: Vec<Member> = Vec::new();
    let mut evaluations = 0u64;
    let mut eval_batch = |points: &[Vec<f64>],
                          visited: &mut Vec<Member>,
                          evaluations: &mut u64|
     -> Result<Vec<Outcome>, EvalError> {
        let values: Vec<Vec<f64>> = points.iter().map(|u| to_values(u)).collect();
        let outcomes = problem.evaluate(&values)?;
        *evaluations += values.len() as u64;
        for (v, o) in values.into_iter().zip(&outcomes) {
            visited.push(Member {
                chromosome: sepval_common::encoding::Chromosome::encode_values(&genes, &v),
                values: v,
                outcome: o.clone(),
            });
        }
        Ok(outcomes)
    };

    let mut u: Vec<f64> = (0..n)
        .map(|i| ((start[i] - lo[i]) / span[i]).clamp(0.0, 1.0))
        .collect();
    let first = eval_batch(std::slice::from_ref(&u), &mut visited, &mut evaluations)?;
    let mut f = f_of(&first[0]);
    let mut best_outcome = first[0].clone();
    let mut history = vec![(evaluations, f, best_outcome.objectives())];
    let mut step = settings.initial_step;
    let stop = loop {
        if !f.is_finite() {
            break HillStop::StartFailed;
        }
        if evaluations as usize + n + settings.line_points > settings.budget {
            break HillStop::Budget;
        }
        // Forward differences, inward at a bound.
        let h = settings.fd_step;
        let probes: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                let mut p = u.clone();
                p[i] = if u[i] + h <= 1.0 { u[i] + h } else { u[i] - h };
                p
            })
            .collect();
        let fd = eval_batch(&probes, &mut visited, &mut evaluations)?;
        let grad: Vec<f64> = (0..n)
            .map(|i| {
                let fi = f_of(&fd[i]);
                let dh = probes[i][i] - u[i];
                if fi.is_finite() { (fi - f) / dh } else { 0.0 }
            })
            .collect();
        let norm = grad.iter().map(|g| g * g).sum::<f64>().sqrt();
        if norm == 0.0 || !norm.is_finite() {
            break HillStop::LocalOptimum;
        }
        let dir: Vec<f64> = grad.iter().map(|g| -g / norm).collect();
        let steps: Vec<f64> = (0..settings.line_points)
            .map(|j| 2.0 * step / 2f64.powi(j as i32))
            .collect();
        let trials: Vec<Vec<f64>> = steps
            .iter()
            .map(|s| {
                (0..n)
                    .map(|i| (u[i] + s * dir[i]).clamp(0.0, 1.0))
                    .collect()
            })
            .collect();
        let outcomes = eval_batch(&trials, &mut visited, &mut evaluations)?;
        let (k, fk) = outcomes
            .iter()
            .map(f_of)
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("at least one trial");
        if fk < f {
            u = trials[k].clone();
            f = fk;
            best_outcome = outcomes[k].clone();
            step = steps[k];
        } else {
            step = steps[settings.line_points - 1] / 2.0;
        }
        history.push((evaluations, f, best_outcome.objectives()));
        if step < settings.min_step {
            break HillStop::LocalOptimum;
        }
    };
    let values = to_values(&u);
    Ok(HillResult {
        best: Member {
            chromosome: sepval_common::encoding::Chromosome::encode_values(&genes, &values),
            values,
            outcome: best_outcome,
        },
        best_weighted: f,
        evaluations,
        history,
        visited,
        stop,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use sepval_common::factors::FactorSpec;

    /// A smooth bowl with its minimum at (0.3, 0.7) of the unit square.
    struct Bowl {
        genes: Vec<FactorSpec>,
    }

    impl ParetoProblem for Bowl {
        fn genes(&self) -> &[FactorSpec] {
            &self.genes
        }
        fn evaluate(&mut self, batch: &[Vec<f64>]) -> Result<Vec<Outcome>, EvalError> {
            Ok(batch
                .iter()
                .map(|v| Outcome::Goals {
                    j_pos_m: (v[0] - 0.3).powi(2) + 0.01,
                    j_att_deg: (v[1] - 0.7).powi(2) + 0.01,
                })
                .collect())
        }
    }

    #[test]
    fn climbs_a_bowl_within_the_budget() {
        let spec = FactorSpec {
            min: 0.0,
            max: 1.0,
            bits: 8,
        };
        let mut p = Bowl {
            genes: vec![spec; 2],
        };
        let settings = HillSettings {
            budget: 200,
            ..HillSettings::default()
        };
        let r = climb(&mut p, &[0.9, 0.1], [1.0, 1.0], &settings).unwrap();
        assert!(r.evaluations <= 200);
        assert!((r.best.values[0] - 0.3).abs() < 0.01, "{:?}", r.best.values);
        assert!((r.best.values[1] - 0.7).abs() < 0.01, "{:?}", r.best.values);
        assert!(r.history.windows(2).all(|w| w[1].1 <= w[0].1));
        assert_eq!(r.visited.len() as u64, r.evaluations);
    }
}
