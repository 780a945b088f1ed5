//! The elitist Pareto genetic algorithm of Anderson's study.
//!
//! Binary chromosomes (docs/model.md section 4), population 100, binary tournament on Pareto rank
//! then crowding distance, single-point crossover 0.9, jump mutation 0.5 % per bit, creep
//! mutation 5 % per parameter, elitism by letting parents and children compete on rank and
//! crowding (NSGA-II's environmental selection), two goals. A generation evaluates one
//! population: `generations` x `population` simulations in all (500 x 100 = 50 000 in the study,
//! the first generation being the random initial population).
//!
//! The state after each generation ([`GaState`]) holds everything the next generation needs,
//! the generator included, so a search resumed from it continues exactly as the uninterrupted
//! one. [`GaSearch`] is the algorithm as a [`Solver`]: it asks for a population (the initial
//! one, then each generation's children) and is told their outcomes.

pub mod operators;

use sepval_core::encoding::Chromosome;
use sepval_core::factors::FactorSpec;
use sepval_core::outcome::{EvalError, Outcome};
use serde::{Deserialize, Serialize};

use crate::best::BestSoFar;
use crate::ga::operators::{
    creep_mutation, crossover, jump_mutation, random_chromosome, tournament,
};
use crate::pareto::{dominates, non_dominated_fronts, rank_and_crowding, select_best};
use crate::rng::{RngState, RngStateError, SearchRng, seeded};
use crate::run::{Ask, Progress, RunError, SearchError, Solver};

/// The largest population: 100 000 chromosomes (the study's is 100). Each is held with its
/// decoded values and outcome, so a population is allocated whole: a bound keeps a mistyped
/// `--population` from exhausting memory.
pub const MAX_POPULATION: usize = 100_000;
/// The most generations of one search: 100 000 (the study's is 500).
pub const MAX_GENERATIONS: usize = 100_000;
/// The most evaluations of one search (population x generations): 1e8, about a day of
/// simulations on the 2-core development machine (a simulation of the default event takes
/// about 0.25-0.5 ms per core, docs/performance.md).
pub const MAX_EVALUATIONS: u128 = 100_000_000;

/// Settings of the genetic algorithm; the defaults are the study's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaSettings {
    /// Population size.
    pub population: usize,
    /// Generations (evaluated populations, the initial one included).
    pub generations: usize,
    /// Probability of single-point crossover per pair.
    pub p_crossover: f64,
    /// Probability of a jump mutation per bit.
    pub p_jump: f64,
    /// Probability of a creep mutation per parameter.
    pub p_creep: f64,
    /// Seed of the generator.
    pub seed: u64,
}

impl Default for GaSettings {
    fn default() -> Self {
        GaSettings {
            population: 100,
            generations: 500,
            p_crossover: 0.9,
            p_jump: 0.005,
            p_creep: 0.05,
            seed: 1,
        }
    }
}

/// Errors in GA settings or state.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GaError {
    /// A setting out of range.
    #[error("GA setting {name} = {value}: {expected}")]
    Setting {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: String,
        /// What is expected.
        expected: &'static str,
    },
    /// A saved generator that cannot be restored.
    #[error(transparent)]
    Rng(#[from] RngStateError),
    /// A state whose population does not have the settings' size.
    #[error("GA state does not fit: population of {members} members, settings say {population}")]
    Population {
        /// The state's members.
        members: usize,
        /// The settings' population.
        population: usize,
    },
    /// The evaluator failed.
    #[error(transparent)]
    Eval(#[from] EvalError),
}

impl GaSettings {
    /// Checks every setting.
    pub fn validate(&self) -> Result<(), GaError> {
        let bad = |name, value: String, expected| {
            Err(GaError::Setting {
                name,
                value,
                expected,
            })
        };
        if self.population < 2 || self.population % 2 == 1 {
            return bad(
                "population",
                self.population.to_string(),
                "expected an even number >= 2",
            );
        }
        if self.population > MAX_POPULATION {
            return bad(
                "population",
                self.population.to_string(),
                "expected at most 100000 (MAX_POPULATION)",
            );
        }
        if self.generations < 1 {
            return bad("generations", "0".into(), "expected at least 1");
        }
        if self.generations > MAX_GENERATIONS {
            return bad(
                "generations",
                self.generations.to_string(),
                "expected at most 100000 (MAX_GENERATIONS)",
            );
        }
        if self.population as u128 * self.generations as u128 > MAX_EVALUATIONS {
            return bad(
                "generations",
                self.generations.to_string(),
                "population x generations expected at most 1e8 evaluations (MAX_EVALUATIONS)",
            );
        }
        for (name, p) in [
            ("p_crossover", self.p_crossover),
            ("p_jump", self.p_jump),
            ("p_creep", self.p_creep),
        ] {
            if !(0.0..=1.0).contains(&p) {
                return bad(name, p.to_string(), "expected a probability in [0, 1]");
            }
        }
        Ok(())
    }
}

/// One evaluated chromosome.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Member {
    /// The chromosome.
    pub chromosome: Chromosome,
    /// Its decoded values.
    pub values: Vec<f64>,
    /// Its outcome.
    pub outcome: Outcome,
}

impl Member {
    /// The two objectives ((inf, inf) when the run did not finish).
    pub fn objectives(&self) -> [f64; 2] {
        self.outcome.objectives()
    }
}

/// The best of one generation. The goals are infinite when no member of the population
/// finished; in JSON they are then the string `"inf"` ([`sepval_core::nonfinite`]). Its
/// fields after `generation` are [`BestSoFar`]'s, read through `Deref` as before
/// (`stats.best_j_pos_m`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GenerationStats {
    /// Generation number (1 = the initial population).
    pub generation: usize,
    /// The best of the population and the simulations so far.
    #[serde(flatten)]
    pub best: BestSoFar,
}

impl std::ops::Deref for GenerationStats {
    type Target = BestSoFar;

    fn deref(&self) -> &BestSoFar {
        &self.best
    }
}

impl std::ops::DerefMut for GenerationStats {
    fn deref_mut(&mut self) -> &mut BestSoFar {
        &mut self.best
    }
}

/// The search's state after a generation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GaState {
    /// Generations done (1 after the initial population).
    pub generation: usize,
    /// Simulations run so far.
    pub evaluations: u64,
    /// The current population.
    pub population: Vec<Member>,
    /// The non-dominated set of every finished run so far.
    pub archive: Vec<Member>,
    /// The generator, ready for the next generation.
    pub rng: RngState,
    /// The best goals of every generation so far.
    pub history: Vec<GenerationStats>,
}

impl GaState {
    /// The search before its first generation: nothing evaluated, the generator as seeded
    /// by `seed` (what the first generation draws its population from).
    pub fn unstarted(seed: u64) -> Self {
        GaState {
            generation: 0,
            evaluations: 0,
            population: Vec::new(),
            archive: Vec::new(),
            rng: RngState::of(&seeded(seed)),
            history: Vec::new(),
        }
    }

    /// The member of the population with the smallest weighted sum of objectives.
    pub fn best(&self, weights: [f64; 2]) -> Option<&Member> {
        best_weighted(&self.population, weights)
    }
}

/// The member with the smallest weighted sum among finished runs.
pub fn best_weighted(members: &[Member], weights: [f64; 2]) -> Option<&Member> {
    members
        .iter()
        .filter(|m| m.outcome.goals().is_some())
        .min_by(|a, b| weighted(a, weights).total_cmp(&weighted(b, weights)))
}

fn weighted(m: &Member, w: [f64; 2]) -> f64 {
    let o = m.objectives();
    w[0] * o[0] + w[1] * o[1]
}

/// A population drawn and not yet evaluated.
struct Pending {
    chromosomes: Vec<Chromosome>,
    values: Vec<Vec<f64>>,
    /// The generator after drawing them.
    rng: RngState,
}

/// The genetic algorithm as ask-and-tell: the initial population, then one generation's
/// children per ask, until the settings' count of generations.
pub struct GaSearch {
    settings: GaSettings,
    weights: [f64; 2],
    genes: Vec<FactorSpec>,
    state: Option<GaState>,
    pending: Option<Pending>,
}

impl GaSearch {
    /// A new search over `genes`; `weights` scalarise the objectives for reporting the best
    /// member (the search itself is Pareto-based and does not use them).
    pub fn new(
        settings: GaSettings,
        weights: [f64; 2],
        genes: Vec<FactorSpec>,
    ) -> Result<Self, GaError> {
        settings.validate()?;
        Ok(GaSearch {
            settings,
            weights,
            genes,
            state: None,
            pending: None,
        })
    }

    /// A search continuing from `state` (a checkpoint's).
    pub fn resume(
        settings: GaSettings,
        weights: [f64; 2],
        genes: Vec<FactorSpec>,
        state: GaState,
    ) -> Result<Self, GaError> {
        let mut s = GaSearch::new(settings, weights, genes)?;
        if state.population.len() != s.settings.population {
            return Err(GaError::Population {
                members: state.population.len(),
                population: s.settings.population,
            });
        }
        state.rng.restore()?;
        s.state = Some(state);
        Ok(s)
    }

    /// The settings.
    pub fn settings(&self) -> &GaSettings {
        &self.settings
    }

    /// The state after the last completed generation.
    pub fn state(&self) -> Option<&GaState> {
        self.state.as_ref()
    }

    /// Whether the settings' generations are done.
    pub fn finished(&self) -> bool {
        self.state
            .as_ref()
            .is_some_and(|s| s.generation >= self.settings.generations)
    }

    /// Draws the next population: the initial one, or the children of the current state.
    fn draw(&self) -> Result<Pending, GaError> {
        let s = &self.settings;
        let (chromosomes, rng) = match &self.state {
            None => {
                let mut rng = seeded(s.seed);
                let len: usize = self.genes.iter().map(|g| g.bits as usize).sum();
                let c: Vec<Chromosome> = (0..s.population)
                    .map(|_| random_chromosome(&mut rng, len))
                    .collect();
                (c, rng)
            }
            Some(state) => {
                let mut rng: SearchRng = state.rng.restore()?;
                let objectives: Vec<[f64; 2]> =
                    state.population.iter().map(Member::objectives).collect();
                let (rank, crowd) = rank_and_crowding(&objectives);
                let mut children = Vec::with_capacity(s.population);
                while children.len() < s.population {
                    let a = tournament(&mut rng, &rank, &crowd);
                    let b = tournament(&mut rng, &rank, &crowd);
                    let (mut c, mut d, _) = crossover(
                        &mut rng,
                        &state.population[a].chromosome,
                        &state.population[b].chromosome,
                        s.p_crossover,
                    );
                    for child in [&mut c, &mut d] {
                        jump_mutation(&mut rng, child, s.p_jump);
                        creep_mutation(&mut rng, child, &self.genes, s.p_creep);
                    }
                    children.push(c);
                    children.push(d);
                }
                (children, rng)
            }
        };
        let values = chromosomes
            .iter()
            .map(|c| c.decode_values(&self.genes))
            .collect();
        Ok(Pending {
            chromosomes,
            values,
            rng: RngState::of(&rng),
        })
    }

    fn stats(&self, state: &GaState) -> GenerationStats {
        let objectives: Vec<[f64; 2]> = state.population.iter().map(Member::objectives).collect();
        let min = |j: usize| {
            objectives
                .iter()
                .map(|o| o[j])
                .fold(f64::INFINITY, f64::min)
        };
        GenerationStats {
            generation: state.generation,
            best: BestSoFar {
                evaluations: state.evaluations,
                best_j_pos_m: min(0),
                best_j_att_deg: min(1),
                best_weighted: state
                    .best(self.weights)
                    .map_or(f64::INFINITY, |m| weighted(m, self.weights)),
            },
        }
    }
}

impl Solver for GaSearch {
    type Point = Vec<f64>;
    type Value = Outcome;

    fn ask(&mut self) -> Result<Option<Ask<Vec<f64>>>, RunError> {
        if self.finished() {
            return Ok(None);
        }
        let pending = self
            .draw()
            .map_err(|e| RunError::Search(SearchError::State(std::sync::Arc::new(e))))?;
        let points = pending.values.clone();
        self.pending = Some(pending);
        Ok(Some(Ask {
            points,
            with_samples: false,
        }))
    }

    fn tell(&mut self, outcomes: Vec<Outcome>) -> Result<Option<Progress>, RunError> {
        let Pending {
            chromosomes,
            values,
            rng,
        } = self.pending.take().ok_or_else(|| {
            RunError::Search(SearchError::Protocol("the GA was told without being asked"))
        })?;
        let members: Vec<Member> = chromosomes
            .into_iter()
            .zip(values)
            .zip(outcomes)
            .map(|((chromosome, values), outcome)| Member {
                chromosome,
                values,
                outcome,
            })
            .collect();
        let mut next = match self.state.take() {
            None => GaState {
                generation: 1,
                evaluations: members.len() as u64,
                archive: update_archive(&[], &members),
                population: members,
                rng,
                history: Vec::new(),
            },
            Some(state) => {
                let mut pool: Vec<Member> = state.population;
                let evaluations = state.evaluations + members.len() as u64;
                let archive = update_archive(&state.archive, &members);
                pool.extend(members);
                let objectives: Vec<[f64; 2]> = pool.iter().map(Member::objectives).collect();
                let chosen = select_best(&objectives, self.settings.population);
                GaState {
                    generation: state.generation + 1,
                    evaluations,
                    archive,
                    population: chosen.iter().map(|&i| pool[i].clone()).collect(),
                    rng,
                    history: state.history,
                }
            }
        };
        let stats = self.stats(&next);
        let progress = Progress {
            step: next.generation,
            steps: Some(self.settings.generations),
            evaluations: next.evaluations,
            best: [stats.best_j_pos_m, stats.best_j_att_deg],
        };
        next.history.push(stats);
        self.state = Some(next);
        Ok(Some(progress))
    }
}

/// The non-dominated set of `archive` and the finished runs of `new`, without duplicate
/// chromosomes, in a deterministic order (by first objective).
pub fn update_archive(archive: &[Member], new: &[Member]) -> Vec<Member> {
    let mut all: Vec<Member> = archive.to_vec();
    for m in new {
        if m.outcome.goals().is_some() && !all.iter().any(|a| a.chromosome == m.chromosome) {
            all.push(m.clone());
        }
    }
    let objectives: Vec<[f64; 2]> = all.iter().map(Member::objectives).collect();
    let mut front: Vec<Member> = match non_dominated_fronts(&objectives).first() {
        Some(f) => f.iter().map(|&i| all[i].clone()).collect(),
        None => Vec::new(),
    };
    front.sort_by(|a, b| {
        let (x, y) = (a.objectives(), b.objectives());
        x[0].total_cmp(&y[0]).then(x[1].total_cmp(&y[1]))
    });
    debug_assert!(front.iter().all(|a| {
        !front
            .iter()
            .any(|b| dominates(&b.objectives(), &a.objectives()))
    }));
    front
}
