//! The genetic operators of Carroll's GA driver, as used in Anderson's study, on binary
//! chromosomes (docs/model.md section 4): binary tournament, single-point crossover, jump mutation
//! (independent bit flips) and creep mutation (one grid step of one parameter).
//!
//! Source: D. L. Carroll, "FORTRAN genetic algorithm driver" (ga2.f: selectn/crosovr/mutate,
//! creep mutation `icreep`); Anderson's study settings: crossover 0.9, jump mutation 0.5 % per
//! bit, creep mutation 5 % per parameter.
//!
//! Every draw comes from the search's one generator, in a fixed order, so a seed fixes the
//! whole search.

use rand::RngExt;
use sepval_core::encoding::Chromosome;
use sepval_core::factors::FactorSpec;

use crate::pareto::crowded_better;
use crate::rng::SearchRng;

/// Binary tournament: two members drawn at random (with replacement); the better by rank, then
/// crowding distance, wins; a tie goes to the first drawn.
pub fn tournament(rng: &mut SearchRng, rank: &[usize], crowding: &[f64]) -> usize {
    let n = rank.len();
    let a = rng.random_range(0..n);
    let b = rng.random_range(0..n);
    if crowded_better(rank[b], crowding[b], rank[a], crowding[a]) {
        b
    } else {
        a
    }
}

/// Single-point crossover: with probability `p_crossover`, the children swap tails after a
/// cut drawn uniformly between bits 1 and len - 1 (both children differ from the parents in at
/// least their tails); otherwise they are copies. Returns the children and the cut (if any).
pub fn crossover(
    rng: &mut SearchRng,
    a: &Chromosome,
    b: &Chromosome,
    p_crossover: f64,
) -> (Chromosome, Chromosome, Option<usize>) {
    let (mut c, mut d) = (a.clone(), b.clone());
    let len = a.len();
    if len < 2 || rng.random::<f64>() >= p_crossover {
        return (c, d, None);
    }
    let cut = rng.random_range(1..len);
    c.bits_mut()[cut..].copy_from_slice(&b.bits()[cut..]);
    d.bits_mut()[cut..].copy_from_slice(&a.bits()[cut..]);
    (c, d, Some(cut))
}

/// Jump mutation: every bit flips independently with probability `p_jump`. Returns the number
/// of flips.
pub fn jump_mutation(rng: &mut SearchRng, c: &mut Chromosome, p_jump: f64) -> usize {
    let mut flips = 0;
    for bit in c.bits_mut() {
        if rng.random::<f64>() < p_jump {
            *bit = !*bit;
            flips += 1;
        }
    }
    flips
}

/// Creep mutation: each parameter, with probability `p_creep`, is decoded, moved one grid step
/// up or down (each with probability 1/2; at a bound, inward), and re-encoded, so it never
/// leaves its bounds. Returns the number of parameters moved.
pub fn creep_mutation(
    rng: &mut SearchRng,
    c: &mut Chromosome,
    genes: &[FactorSpec],
    p_creep: f64,
) -> usize {
    let mut moved = 0;
    for (i, spec) in genes.iter().enumerate() {
        if rng.random::<f64>() >= p_creep {
            continue;
        }
        let up = rng.random::<bool>();
        let k = c.gene_integers(genes)[i];
        let top = spec.levels_minus_one();
        let new_k = match (up, k) {
            (true, k) if k < top => k + 1,
            (true, k) => k - 1,
            (false, 0) => 1,
            (false, k) => k - 1,
        };
        c.set_gene_integer(genes, i, new_k);
        moved += 1;
    }
    moved
}

/// A chromosome of uniformly random bits.
pub fn random_chromosome(rng: &mut SearchRng, len: usize) -> Chromosome {
    Chromosome::from_bits((0..len).map(|_| rng.random::<bool>()).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;
    use sepval_core::factors::FactorTable;

    #[test]
    fn creep_moves_exactly_one_step_and_stays_in_bounds() {
        let table = FactorTable::default();
        let genes = &table.0;
        let mut rng = seeded(1);
        for trial in 0..2000 {
            let mut c = random_chromosome(&mut rng, table.total_bits());
            // Put some genes at their bounds.
            if trial % 3 == 0 {
                c.set_gene_integer(genes, 0, 0);
                c.set_gene_integer(genes, 1, genes[1].levels_minus_one());
            }
            let before = c.gene_integers(genes);
            let mut after_c = c.clone();
            let moved = creep_mutation(&mut rng, &mut after_c, genes, 1.0);
            assert_eq!(moved, genes.len());
            let after = after_c.gene_integers(genes);
            for i in 0..genes.len() {
                assert_eq!(before[i].abs_diff(after[i]), 1, "gene {i}");
                assert!(after[i] <= genes[i].levels_minus_one());
            }
        }
    }

    #[test]
    fn crossover_point_is_uniform() {
        let mut rng = seeded(2);
        let len = 93;
        let a = Chromosome::from_bits(vec![false; len]);
        let b = Chromosome::from_bits(vec![true; len]);
        let mut counts = vec![0usize; len];
        let draws = 92_000;
        for _ in 0..draws {
            let (c, d, cut) = crossover(&mut rng, &a, &b, 1.0);
            let cut = cut.unwrap();
            counts[cut] += 1;
            assert!(c.bits()[..cut].iter().all(|x| !x) && c.bits()[cut..].iter().all(|x| *x));
            assert!(d.bits()[..cut].iter().all(|x| *x) && d.bits()[cut..].iter().all(|x| !x));
        }
        assert_eq!(counts[0], 0);
        // Chi-square against uniform over 1..=92 (91 degrees of freedom; 99.9 % point 136).
        let expected = draws as f64 / 92.0;
        let chi2: f64 = counts[1..]
            .iter()
            .map(|&c| (c as f64 - expected).powi(2) / expected)
            .sum();
        assert!(chi2 < 136.0, "chi2 {chi2}");
    }

    #[test]
    fn measured_rates_match_the_settings() {
        let mut rng = seeded(3);
        let table = FactorTable::default();
        let (mut flips, mut crossed, mut moved) = (0usize, 0usize, 0usize);
        let n = 20_000;
        for _ in 0..n {
            let mut c = random_chromosome(&mut rng, 93);
            flips += jump_mutation(&mut rng, &mut c, 0.005);
            moved += creep_mutation(&mut rng, &mut c, &table.0, 0.05);
            let (_, _, cut) = crossover(&mut rng, &c, &c, 0.9);
            crossed += usize::from(cut.is_some());
        }
        let jump = flips as f64 / (n * 93) as f64;
        let creep = moved as f64 / (n * 17) as f64;
        let cross = crossed as f64 / n as f64;
        // Binomial standard errors: jump 5e-5, creep 3.7e-4, crossover 2.1e-3; allow 4 of them.
        assert!((jump - 0.005).abs() < 2e-4, "jump {jump}");
        assert!((creep - 0.05).abs() < 1.5e-3, "creep {creep}");
        assert!((cross - 0.9).abs() < 8.5e-3, "crossover {cross}");
    }

    #[test]
    fn tournament_prefers_rank_then_crowding() {
        let mut rng = seeded(4);
        let rank = [0, 1, 0];
        let crowd = [1.0, 5.0, 2.0];
        let mut wins = [0usize; 3];
        for _ in 0..30_000 {
            wins[tournament(&mut rng, &rank, &crowd)] += 1;
        }
        // Member 1 (rank 1) wins only against itself: 1/9; member 2 beats everyone: 5/9;
        // member 0 beats member 1 and itself: 3/9.
        assert!(
            (wins[1] as f64 / 30_000.0 - 1.0 / 9.0).abs() < 0.01,
            "{wins:?}"
        );
        assert!(
            (wins[2] as f64 / 30_000.0 - 5.0 / 9.0).abs() < 0.015,
            "{wins:?}"
        );
    }
}
