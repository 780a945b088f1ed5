//! The consistency checks of a checkpoint's content (listed in the documentation of
//! [`crate::checkpoint`]). Each returns what disagrees, naming the member, field or count.

use sepval_common::evaluation::{Job, MAX_REASON_BYTES, Outcome};
use sepval_core::factors::FactorSpec;

use super::Checkpoint;
use super::content::{ContentError, MemberError};
use crate::method::Method;
use sepval_solve::ga::{Member, best_weighted};
use sepval_solve::pareto::dominates;
use sepval_solve::rng::{RngState, seeded};

impl Checkpoint {
    /// Everything that can be checked without the job.
    pub(super) fn check_content(&self) -> Result<(), ContentError> {
        self.check_header()?;
        self.check_counts()?;
        self.check_rng()?;
        for (set, members) in [
            ("population", &self.state.population),
            ("archive", &self.state.archive),
        ] {
            for (i, m) in members.iter().enumerate() {
                check_outcome(&m.outcome).map_err(|reason| ContentError::Member {
                    set,
                    index: i,
                    reason,
                })?;
            }
        }
        self.check_archive()?;
        self.check_history()?;
        self.check_probes()
    }

    /// The method, settings, noise levels and hashes.
    fn check_header(&self) -> Result<(), ContentError> {
        match Method::from_name(&self.method) {
            Some(Method::Ga | Method::Both | Method::GaLm) => {}
            _ => {
                return Err(ContentError::Method {
                    method: self.method.clone(),
                });
            }
        }
        self.settings.validate().map_err(ContentError::Settings)?;
        let s = &self.sigma;
        if !(s.pos_m.is_finite() && s.pos_m > 0.0 && s.att_deg.is_finite() && s.att_deg > 0.0) {
            return Err(ContentError::Noise {
                pos_m: s.pos_m,
                att_deg: s.att_deg,
            });
        }
        let h = &self.hill;
        for (name, v) in [
            ("fd_step", h.fd_step),
            ("initial_step", h.initial_step),
            ("min_step", h.min_step),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(ContentError::Hill { name, value: v });
            }
        }
        for (name, hash) in [
            ("data_sha256", &self.data_sha256),
            ("scenario_sha256", &self.scenario_sha256),
        ] {
            let hex = hash.len() == 64
                && hash
                    .bytes()
                    .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b));
            if !hex {
                return Err(ContentError::Hash {
                    name,
                    hash: hash.clone(),
                });
            }
        }
        Ok(())
    }

    /// The generation and simulation counts against the settings.
    fn check_counts(&self) -> Result<(), ContentError> {
        let (s, st) = (&self.settings, &self.state);
        if st.generation < 1 || st.generation > s.generations {
            return Err(ContentError::Generation {
                generation: st.generation,
                generations: s.generations,
            });
        }
        if st.population.len() != s.population {
            return Err(ContentError::Population {
                members: st.population.len(),
                population: s.population,
            });
        }
        // Exact: a generation near usize::MAX must not wrap to a count that matches.
        let expected = st.generation as u128 * s.population as u128;
        if u128::from(st.evaluations) != expected {
            return Err(ContentError::Evaluations {
                evaluations: st.evaluations,
                generation: st.generation,
                population: s.population,
                expected,
            });
        }
        Ok(())
    }

    /// The generator: restores, is written as this sepval writes it, and is the settings'
    /// seed's (a search never changes its key or stream, only its position).
    fn check_rng(&self) -> Result<(), ContentError> {
        let rng = &self.state.rng;
        let restored = rng.restore().map_err(ContentError::Rng)?;
        if RngState::of(&restored) != *rng {
            return Err(ContentError::RngForm { rng: rng.clone() });
        }
        let start = RngState::of(&seeded(self.settings.seed));
        if rng.seed_hex != start.seed_hex || rng.stream != start.stream {
            return Err(ContentError::RngSeed {
                seed: self.settings.seed,
            });
        }
        Ok(())
    }

    /// The archive alone, then the population against it.
    fn check_archive(&self) -> Result<(), ContentError> {
        let archive = &self.state.archive;
        for (i, a) in archive.iter().enumerate() {
            if a.outcome.goals().is_none() {
                return Err(ContentError::ArchiveUnfinished { index: i });
            }
            if let Some(j) = archive[..i]
                .iter()
                .position(|b| b.chromosome == a.chromosome)
            {
                return Err(ContentError::ArchiveTwice {
                    first: j,
                    second: i,
                });
            }
            if i > 0 {
                let (p, q) = (archive[i - 1].objectives(), a.objectives());
                if p[0].total_cmp(&q[0]).then(p[1].total_cmp(&q[1])).is_gt() {
                    return Err(ContentError::ArchiveOrder {
                        first: i - 1,
                        second: i,
                    });
                }
            }
            if let Some(j) = archive
                .iter()
                .position(|b| dominates(&b.objectives(), &a.objectives()))
            {
                return Err(ContentError::ArchiveDominated { index: i, by: j });
            }
        }
        for (i, m) in self.state.population.iter().enumerate() {
            if let Some(j) = archive.iter().position(|a| a.chromosome == m.chromosome) {
                if !m.outcome.same_bits(&archive[j].outcome) {
                    return Err(ContentError::TwoOutcomes {
                        member: i,
                        archived: j,
                        outcome: m.outcome.clone(),
                        archived_outcome: archive[j].outcome.clone(),
                    });
                }
            } else if m.outcome.goals().is_some()
                && !archive
                    .iter()
                    .any(|a| dominates(&a.objectives(), &m.objectives()))
            {
                return Err(ContentError::OutsideArchive {
                    member: i,
                    outcome: m.outcome.clone(),
                });
            }
        }
        Ok(())
    }

    /// One history entry per generation, with its counts; the last one is what the population
    /// gives (the earlier populations are gone: their entries can only be counted).
    fn check_history(&self) -> Result<(), ContentError> {
        let (st, pop) = (&self.state, self.settings.population as u64);
        if st.history.len() != st.generation {
            return Err(ContentError::HistoryLength {
                entries: st.history.len(),
                generation: st.generation,
            });
        }
        for (i, h) in st.history.iter().enumerate() {
            let g = i + 1;
            if h.generation != g || h.evaluations != g as u64 * pop {
                return Err(ContentError::HistoryEntry {
                    index: i,
                    generation: h.generation,
                    evaluations: h.evaluations,
                    expected_generation: g,
                    expected_evaluations: g as u64 * pop,
                });
            }
            for (name, v) in [
                ("best_j_pos_m", h.best_j_pos_m),
                ("best_j_att_deg", h.best_j_att_deg),
                ("best_weighted", h.best_weighted),
            ] {
                if v.is_nan() || v < 0.0 {
                    return Err(ContentError::HistoryValue {
                        generation: g,
                        name,
                        value: v,
                    });
                }
            }
        }
        // As GaSearch computes it: the smallest objectives of the population and the smallest
        // weighted sum of a finished member (infinite when none finished).
        let w = self.sigma.weights();
        let min = |j: usize| {
            st.population
                .iter()
                .map(|m| m.objectives()[j])
                .fold(f64::INFINITY, f64::min)
        };
        let weighted = |m: &Member| {
            let o = m.objectives();
            w[0] * o[0] + w[1] * o[1]
        };
        let last = st.history.last().expect("at least one generation");
        for (name, recorded, population) in [
            ("best_j_pos_m", last.best_j_pos_m, min(0)),
            ("best_j_att_deg", last.best_j_att_deg, min(1)),
            (
                "best_weighted",
                last.best_weighted,
                best_weighted(&st.population, w).map_or(f64::INFINITY, weighted),
            ),
        ] {
            if recorded.to_bits() != population.to_bits() {
                return Err(ContentError::HistoryBest {
                    generation: st.generation,
                    name,
                    recorded,
                    population,
                });
            }
        }
        Ok(())
    }

    /// Probes only for ga+lm, after generations already done, with the simulations before
    /// each one being the generations' and the earlier probes'.
    fn check_probes(&self) -> Result<(), ContentError> {
        if self.probes.is_empty() {
            return Ok(());
        }
        if self.method != Method::GaLm.name() {
            return Err(ContentError::ProbesMethod {
                probes: self.probes.len(),
                method: self.method.clone(),
            });
        }
        // Exact sums: an attempt of nearly 2^64 simulations must not wrap the count of the
        // next one's back to a value that matches.
        let pop = self.settings.population as u128;
        let mut probed = 0u128;
        let mut generation = 0;
        for (i, p) in self.probes.iter().enumerate() {
            if p.generation < generation || p.generation > self.state.generation {
                return Err(ContentError::ProbeGeneration {
                    index: i,
                    generation: p.generation,
                    from: generation,
                    to: self.state.generation,
                });
            }
            let before = p.generation as u128 * pop + probed;
            if u128::from(p.evaluations_before) != before {
                return Err(ContentError::ProbeBefore {
                    index: i,
                    recorded: p.evaluations_before,
                    expected: before,
                });
            }
            if !p.goals.iter().all(|g| g.is_finite() && *g >= 0.0) {
                return Err(ContentError::ProbeGoals {
                    index: i,
                    goals: p.goals,
                });
            }
            probed += u128::from(p.evaluations);
            generation = p.generation;
        }
        Ok(())
    }

    /// What needs the job: every member's chromosome fits the factor table and decodes to its
    /// recorded values; divergences name an event of the job.
    pub(super) fn check_members(&self, job: &Job) -> Result<(), ContentError> {
        let genes: &[FactorSpec] = &job.factor_table().0;
        let events = job.events().len();
        for (set, members) in [
            ("population", &self.state.population),
            ("archive", &self.state.archive),
        ] {
            for (i, m) in members.iter().enumerate() {
                let member = |reason| ContentError::Member {
                    set,
                    index: i,
                    reason,
                };
                check_decoding(m, genes).map_err(member)?;
                if let Outcome::Diverged { event, .. } = m.outcome {
                    if event >= events {
                        return Err(member(MemberError::Event { event, events }));
                    }
                }
            }
        }
        Ok(())
    }
}

/// An outcome a simulation can give.
fn check_outcome(o: &Outcome) -> Result<(), MemberError> {
    let valid = |v: f64| v.is_finite() && v >= 0.0;
    match o {
        Outcome::Goals { j_pos_m, j_att_deg } => {
            if !(valid(*j_pos_m) && valid(*j_att_deg)) {
                return Err(MemberError::Goals {
                    j_pos_m: *j_pos_m,
                    j_att_deg: *j_att_deg,
                });
            }
        }
        Outcome::Diverged { t_s, .. } => {
            if !valid(*t_s) {
                return Err(MemberError::DivergedAt { t_s: *t_s });
            }
        }
        Outcome::Failed { reason } => {
            if reason.len() > MAX_REASON_BYTES {
                return Err(MemberError::Reason {
                    bytes: reason.len(),
                });
            }
        }
    }
    Ok(())
}

/// The member's chromosome has the genes' length and decodes to exactly its values.
fn check_decoding(m: &Member, genes: &[FactorSpec]) -> Result<(), MemberError> {
    let bits: usize = genes.iter().map(|g| g.bits as usize).sum();
    if m.chromosome.len() != bits {
        return Err(MemberError::Bits {
            bits: m.chromosome.len(),
            expected: bits,
        });
    }
    if m.values.len() != genes.len() {
        return Err(MemberError::Values {
            values: m.values.len(),
            factors: genes.len(),
        });
    }
    let decoded = m.chromosome.decode_values(genes);
    if let Some(k) = (0..genes.len()).find(|&k| decoded[k].to_bits() != m.values[k].to_bits()) {
        return Err(MemberError::Decodes {
            gene: k,
            decoded: decoded[k],
            recorded: m.values[k],
        });
    }
    Ok(())
}
