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

use sepval_core::encoding::Chromosome;
use sepval_core::factors::FactorSpec;
use sepval_core::outcome::Outcome;
use serde::{Deserialize, Serialize};

use crate::ga::Member;
use crate::run::{Ask, Progress, RunError, SearchError, Solver};

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

/// What the climber waits for.
enum Stage {
    /// The start point.
    Start,
    /// The forward-difference probes around the current point.
    Gradient { probes: Vec<Vec<f64>> },
    /// The line-search trials along the steepest descent.
    Line {
        trials: Vec<Vec<f64>>,
        steps: Vec<f64>,
    },
    /// Finished.
    Done(HillStop),
}

/// The hill climber as ask-and-tell, in coordinates normalised to the unit box.
pub struct HillSearch {
    settings: HillSettings,
    weights: [f64; 2],
    genes: Vec<FactorSpec>,
    u: Vec<f64>,
    f: f64,
    best_outcome: Outcome,
    step: f64,
    evaluations: u64,
    history: Vec<(u64, f64, [f64; 2])>,
    visited: Vec<Member>,
    stage: Stage,
}

impl HillSearch {
    /// A climb over `genes` from `start` (values within their bounds) on the weighted sum.
    pub fn new(
        genes: Vec<FactorSpec>,
        start: &[f64],
        weights: [f64; 2],
        settings: HillSettings,
    ) -> Self {
        let u = genes
            .iter()
            .zip(start)
            .map(|(g, v)| ((v - g.min) / (g.max - g.min)).clamp(0.0, 1.0))
            .collect();
        HillSearch {
            step: settings.initial_step,
            settings,
            weights,
            genes,
            u,
            f: f64::INFINITY,
            best_outcome: Outcome::failed("not evaluated"),
            evaluations: 0,
            history: Vec::new(),
            visited: Vec::new(),
            stage: Stage::Start,
        }
    }

    fn to_values(&self, u: &[f64]) -> Vec<f64> {
        self.genes
            .iter()
            .zip(u)
            .map(|(g, u)| (g.min + u.clamp(0.0, 1.0) * (g.max - g.min)).clamp(g.min, g.max))
            .collect()
    }

    fn weighted(&self, o: &Outcome) -> f64 {
        let [a, b] = o.objectives();
        self.weights[0] * a + self.weights[1] * b
    }

    /// Plans the next gradient, or stops.
    fn next_iteration(&mut self) {
        let n = self.genes.len();
        self.stage = if !self.f.is_finite() {
            Stage::Done(HillStop::StartFailed)
        } else if self.evaluations as usize + n + self.settings.line_points > self.settings.budget {
            Stage::Done(HillStop::Budget)
        } else {
            // Forward differences, inward at a bound.
            let h = self.settings.fd_step;
            let u = &self.u;
            Stage::Gradient {
                probes: (0..n)
                    .map(|i| {
                        let mut p = u.clone();
                        p[i] = if u[i] + h <= 1.0 { u[i] + h } else { u[i] - h };
                        p
                    })
                    .collect(),
            }
        };
    }

    /// The result (after [`Solver::ask`] returned `None`).
    pub fn finish(self) -> HillResult {
        let values = self.to_values(&self.u);
        let stop = match self.stage {
            Stage::Done(s) => s,
            _ => HillStop::Budget,
        };
        HillResult {
            best: Member {
                chromosome: Chromosome::encode_values(&self.genes, &values),
                values,
                outcome: self.best_outcome,
            },
            best_weighted: self.f,
            evaluations: self.evaluations,
            history: self.history,
            visited: self.visited,
            stop,
        }
    }
}

impl Solver for HillSearch {
    type Point = Vec<f64>;
    type Value = Outcome;

    fn ask(&mut self) -> Result<Option<Ask<Vec<f64>>>, RunError> {
        let points = match &self.stage {
            Stage::Start => vec![self.u.clone()],
            Stage::Gradient { probes } => probes.clone(),
            Stage::Line { trials, .. } => trials.clone(),
            Stage::Done(_) => return Ok(None),
        };
        Ok(Some(Ask {
            points: points.iter().map(|u| self.to_values(u)).collect(),
            with_samples: false,
        }))
    }

    fn tell(&mut self, outcomes: Vec<Outcome>) -> Result<Option<Progress>, RunError> {
        let points = match &self.stage {
            Stage::Start => vec![self.u.clone()],
            Stage::Gradient { probes } => probes.clone(),
            Stage::Line { trials, .. } => trials.clone(),
            Stage::Done(_) => {
                return Err(RunError::Search(SearchError::Protocol(
                    "a finished climb was told",
                )));
            }
        };
        self.evaluations += outcomes.len() as u64;
        for (u, o) in points.iter().zip(&outcomes) {
            let values = self.to_values(u);
            self.visited.push(Member {
                chromosome: Chromosome::encode_values(&self.genes, &values),
                values,
                outcome: o.clone(),
            });
        }
        let n = self.genes.len();
        match std::mem::replace(&mut self.stage, Stage::Done(HillStop::Budget)) {
            Stage::Start => {
                self.f = self.weighted(&outcomes[0]);
                self.best_outcome = outcomes[0].clone();
                self.history
                    .push((self.evaluations, self.f, self.best_outcome.objectives()));
                self.next_iteration();
                Ok(None)
            }
            Stage::Gradient { probes } => {
                let grad: Vec<f64> = (0..n)
                    .map(|i| {
                        let fi = self.weighted(&outcomes[i]);
                        let dh = probes[i][i] - self.u[i];
                        if fi.is_finite() {
                            (fi - self.f) / dh
                        } else {
                            0.0
                        }
                    })
                    .collect();
                let norm = grad.iter().map(|g| g * g).sum::<f64>().sqrt();
                if norm == 0.0 || !norm.is_finite() {
                    self.stage = Stage::Done(HillStop::LocalOptimum);
                    return Ok(None);
                }
                let dir: Vec<f64> = grad.iter().map(|g| -g / norm).collect();
                let steps: Vec<f64> = (0..self.settings.line_points)
                    .map(|j| 2.0 * self.step / 2f64.powi(j as i32))
                    .collect();
                let trials = steps
                    .iter()
                    .map(|s| {
                        (0..n)
                            .map(|i| (self.u[i] + s * dir[i]).clamp(0.0, 1.0))
                            .collect()
                    })
                    .collect();
                self.stage = Stage::Line { trials, steps };
                Ok(None)
            }
            Stage::Line { trials, steps } => {
                let (k, fk) = outcomes
                    .iter()
                    .map(|o| self.weighted(o))
                    .enumerate()
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                    .ok_or_else(|| {
                        RunError::Search(SearchError::Protocol("an empty line search"))
                    })?;
                if fk < self.f {
                    self.u = trials[k].clone();
                    self.f = fk;
                    self.best_outcome = outcomes[k].clone();
                    self.step = steps[k];
                } else {
                    self.step = steps[self.settings.line_points - 1] / 2.0;
                }
                self.history
                    .push((self.evaluations, self.f, self.best_outcome.objectives()));
                if self.step < self.settings.min_step {
                    self.stage = Stage::Done(HillStop::LocalOptimum);
                } else {
                    self.next_iteration();
                }
                Ok(Some(Progress {
                    step: self.history.len() - 1,
                    steps: None,
                    evaluations: self.evaluations,
                    best: self.best_outcome.objectives(),
                }))
            }
            Stage::Done(_) => unreachable!("checked above"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::run::{Problem, RunError, run};

    /// A smooth bowl with its minimum at (0.3, 0.7) of the unit square.
    struct Bowl;

    impl Problem<Vec<f64>, Outcome> for Bowl {
        fn evaluate(&mut self, batch: &[Vec<f64>], _: bool) -> Result<Vec<Outcome>, RunError> {
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
        let settings = HillSettings {
            budget: 200,
            ..HillSettings::default()
        };
        let mut climb = HillSearch::new(vec![spec; 2], &[0.9, 0.1], [1.0, 1.0], settings);
        run(&mut climb, &mut Bowl, &mut []).unwrap();
        let r = climb.finish();
        assert!(r.evaluations <= 200);
        assert!((r.best.values[0] - 0.3).abs() < 0.01, "{:?}", r.best.values);
        assert!((r.best.values[1] - 0.7).abs() < 0.01, "{:?}", r.best.values);
        assert!(r.history.windows(2).all(|w| w[1].1 <= w[0].1));
        assert_eq!(r.visited.len() as u64, r.evaluations);
    }
}
