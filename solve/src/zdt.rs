//! Checks of the Pareto machinery against problems with known fronts: ZDT1, ZDT2 and ZDT3
//! (E. Zitzler, K. Deb and L. Thiele, "Comparison of multiobjective evolutionary algorithms:
//! empirical results", Evolutionary Computation 8(2), 2000), 30 variables in [0, 1]:
//!
//! ```text
//! f1 = x1,  g = 1 + 9 / (n - 1) * sum_{i >= 2} x_i
//! ZDT1: f2 = g (1 - sqrt(f1 / g))
//! ZDT2: f2 = g (1 - (f1 / g)^2)
//! ZDT3: f2 = g (1 - sqrt(f1 / g) - (f1 / g) sin(10 pi f1))
//! ```
//!
//! The genetic algorithm runs exactly as on the store (binary genes, the study's operators and
//! rates); the final population's non-dominated set is scored by its hypervolume with reference
//! point (1.1, 1.1).

use sepval_core::factors::FactorSpec;
use sepval_core::outcome::Outcome;

use crate::ga::{GaError, GaSearch, GaSettings, Member};
use crate::pareto::{hypervolume, non_dominated_fronts};
use crate::run::{Problem, RunError, run};

/// Reference point of the hypervolume.
pub const REFERENCE: [f64; 2] = [1.1, 1.1];

/// One of the ZDT problems.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Zdt {
    /// Convex front.
    Zdt1,
    /// Non-convex front.
    Zdt2,
    /// Disconnected front.
    Zdt3,
}

/// Errors of a self-test.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SelftestError {
    /// Bits per variable out of range.
    #[error("{0} bits per variable: expected 1 to 52")]
    Bits(u32),
    /// Invalid GA settings.
    #[error(transparent)]
    Ga(#[from] GaError),
    /// The search failed.
    #[error(transparent)]
    Run(#[from] RunError),
}

impl Zdt {
    /// The two objectives of `x`.
    pub fn objectives(self, x: &[f64]) -> [f64; 2] {
        let n = x.len();
        let f1 = x[0];
        let g = 1.0 + 9.0 / (n - 1) as f64 * x[1..].iter().sum::<f64>();
        let h = match self {
            Zdt::Zdt1 => 1.0 - (f1 / g).sqrt(),
            Zdt::Zdt2 => 1.0 - (f1 / g).powi(2),
            Zdt::Zdt3 => {
                1.0 - (f1 / g).sqrt() - (f1 / g) * (10.0 * std::f64::consts::PI * f1).sin()
            }
        };
        [f1, g * h]
    }
}

/// A ZDT problem on binary genes.
pub struct ZdtProblem {
    problem: Zdt,
    genes: Vec<FactorSpec>,
}

impl ZdtProblem {
    /// `variables` genes of `bits` bits each, on [0, 1].
    pub fn new(problem: Zdt, variables: usize, bits: u32) -> Self {
        ZdtProblem {
            problem,
            genes: vec![
                FactorSpec {
                    min: 0.0,
                    max: 1.0,
                    bits
                };
                variables
            ],
        }
    }
}

impl Problem<Vec<f64>, Outcome> for ZdtProblem {
    fn evaluate(&mut self, batch: &[Vec<f64>], _: bool) -> Result<Vec<Outcome>, RunError> {
        Ok(batch
            .iter()
            .map(|x| {
                let [f1, f2] = self.problem.objectives(x);
                // The pair travels as the typed "goals" outcome: first and second objective.
                Outcome::Goals {
                    j_pos_m: f1,
                    j_att_deg: f2,
                }
            })
            .collect())
    }
}

/// Runs the genetic algorithm on `problem` for about `evaluations` evaluations (whole
/// generations of 100) and returns the hypervolume of the final population's front.
pub fn run_zdt(
    problem: Zdt,
    evaluations: usize,
    seed: u64,
    bits: u32,
) -> Result<(f64, Vec<[f64; 2]>), SelftestError> {
    if !(1..=52).contains(&bits) {
        return Err(SelftestError::Bits(bits));
    }
    let settings = GaSettings {
        generations: (evaluations / 100).max(1),
        seed,
        ..GaSettings::default()
    };
    let mut p = ZdtProblem::new(problem, 30, bits);
    let mut ga = GaSearch::new(settings, [1.0, 1.0], p.genes.clone())?;
    run(&mut ga, &mut p, &mut [])?;
    let state = ga.state().expect("a finished search has a state").clone();
    let points: Vec<[f64; 2]> = state.population.iter().map(Member::objectives).collect();
    let front: Vec<[f64; 2]> = non_dominated_fronts(&points)
        .first()
        .map(|f| f.iter().map(|&i| points[i]).collect())
        .unwrap_or_default();
    Ok((hypervolume(&front, REFERENCE), front))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_optimal_fronts_have_their_known_hypervolumes() {
        // On the optimal front g = 1; sample it densely.
        for (p, expected) in [(Zdt::Zdt1, 0.8767), (Zdt::Zdt2, 0.5433)] {
            let front: Vec<[f64; 2]> = (0..=10_000)
                .map(|k| {
                    let mut x = vec![0.0; 30];
                    x[0] = k as f64 / 10_000.0;
                    p.objectives(&x)
                })
                .collect();
            let hv = hypervolume(&front, REFERENCE);
            assert!((hv - expected).abs() < 2e-3, "{p:?}: {hv}");
        }
    }

    #[test]
    fn the_ga_makes_progress_on_zdt1() {
        let (early, _) = run_zdt(Zdt::Zdt1, 200, 1, 20).unwrap();
        let (later, front) = run_zdt(Zdt::Zdt1, 3000, 1, 20).unwrap();
        assert!(later > early, "{early} -> {later}");
        assert!(!front.is_empty());
    }
}
