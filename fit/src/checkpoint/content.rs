//! What makes a checkpoint's content unusable: the check that failed, with the member, field or
//! count it names and what was expected.

use std::fmt;

use sepval_common::evaluation::{MAX_REASON_BYTES, Outcome};
use sepval_core::factors::Factor;
use sepval_solve::ga::GaError;
use sepval_solve::rng::{RngState, RngStateError};

use super::{CHECKPOINT_FORMAT, digest};

/// A checkpoint whose format, keys or content this sepval does not use.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ContentError {
    /// The format of the checkpoints written before the digest.
    #[error(
        "format `{format}` was written by an earlier sepval, without a digest of its content, so an edit to it cannot be detected: this sepval reads only `{CHECKPOINT_FORMAT}`; run the fit again"
    )]
    EarlierFormat {
        /// The format read.
        format: String,
    },
    /// Another format.
    #[error("format `{format}`, this sepval reads `{CHECKPOINT_FORMAT}`")]
    OtherFormat {
        /// The format read.
        format: String,
    },
    /// A key this sepval does not write.
    #[error("`{key}` is not part of a sepval checkpoint (edited by hand?)")]
    UnknownKey {
        /// The key (a JSON path).
        key: String,
    },
    /// No digest.
    #[error("no digest of its content (`digest`): edited by hand, or not written by sepval")]
    NoDigest,
    /// A method that writes no checkpoint.
    #[error("method `{method}`: a checkpoint is written by ga, both or ga+lm")]
    Method {
        /// The method read.
        method: String,
    },
    /// GA settings refused.
    #[error("{0}")]
    Settings(GaError),
    /// Noise levels that are not positive.
    #[error("noise levels sigma_pos {pos_m} m, sigma_att {att_deg} deg: expected positive numbers")]
    Noise {
        /// sigma_pos \[m\].
        pos_m: f64,
        /// sigma_att \[deg\].
        att_deg: f64,
    },
    /// A hill-climber setting that is not positive.
    #[error("hill-climber setting {name} = {value}: expected a positive number")]
    Hill {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A hash that is not a SHA-256.
    #[error("{name} `{hash}` is not a SHA-256 (64 lower-case hex digits)")]
    Hash {
        /// The field.
        name: &'static str,
        /// Its value.
        hash: String,
    },
    /// A generation outside the settings'.
    #[error("generation {generation}: expected 1 to the settings' {generations} generations")]
    Generation {
        /// The state's generation.
        generation: usize,
        /// The settings' generations.
        generations: usize,
    },
    /// A population of another size than the settings'.
    #[error("population of {members} members, settings say {population}")]
    Population {
        /// Its members.
        members: usize,
        /// The settings' population.
        population: usize,
    },
    /// A count of simulations that the generations do not make.
    #[error(
        "{evaluations} simulations recorded, but {generation} generations of {population} make {expected}"
    )]
    Evaluations {
        /// The count recorded.
        evaluations: u64,
        /// The generations done.
        generation: usize,
        /// The population.
        population: usize,
        /// What they make.
        expected: u128,
    },
    /// A generator state that does not restore.
    #[error("generator state (state.rng): {0}")]
    Rng(RngStateError),
    /// A generator state not written as sepval writes it.
    #[error("generator state (state.rng) is not written as sepval writes it: {rng:?}")]
    RngForm {
        /// The state read.
        rng: RngState,
    },
    /// A generator of another key or stream than the settings' seed.
    #[error(
        "generator state (state.rng): its key and stream are not those of the settings' seed {seed}"
    )]
    RngSeed {
        /// The settings' seed.
        seed: u64,
    },
    /// An archive member that did not finish.
    #[error("archive member {index} did not finish: the archive holds finished runs only")]
    ArchiveUnfinished {
        /// The member.
        index: usize,
    },
    /// Two archive members with one chromosome.
    #[error("archive members {first} and {second} have the same chromosome")]
    ArchiveTwice {
        /// The first.
        first: usize,
        /// The second.
        second: usize,
    },
    /// Archive members out of order.
    #[error("archive members {first} and {second} are not in order of J_pos, then J_att")]
    ArchiveOrder {
        /// The one before.
        first: usize,
        /// The one after.
        second: usize,
    },
    /// A dominated archive member.
    #[error(
        "archive member {index} is dominated by archive member {by}: the archive holds non-dominated runs only"
    )]
    ArchiveDominated {
        /// The member.
        index: usize,
        /// The member that dominates it.
        by: usize,
    },
    /// A population member and an archive member with one chromosome and two outcomes.
    #[error(
        "population member {member} and archive member {archived} have the same chromosome but different outcomes ({outcome:?}, {archived_outcome:?})"
    )]
    TwoOutcomes {
        /// The population member.
        member: usize,
        /// The archive member.
        archived: usize,
        /// The population member's outcome.
        outcome: Outcome,
        /// The archive member's.
        archived_outcome: Outcome,
    },
    /// A finished population member neither in the archive nor dominated by it.
    #[error(
        "population member {member} ({outcome:?}) is neither in the archive nor dominated by an archive member"
    )]
    OutsideArchive {
        /// The member.
        member: usize,
        /// Its outcome.
        outcome: Outcome,
    },
    /// A history of other length than the generations done.
    #[error(
        "history of {entries} generations (state.history), the state is at generation {generation}"
    )]
    HistoryLength {
        /// Its entries.
        entries: usize,
        /// The state's generation.
        generation: usize,
    },
    /// A history entry with other counts than its place makes.
    #[error(
        "history entry {index} (state.history): generation {generation} after {evaluations} simulations, expected generation {expected_generation} after {expected_evaluations}"
    )]
    HistoryEntry {
        /// The entry.
        index: usize,
        /// Its generation.
        generation: usize,
        /// Its simulations.
        evaluations: u64,
        /// The generation its place makes.
        expected_generation: usize,
        /// The simulations its place makes.
        expected_evaluations: u64,
    },
    /// A history value that is NaN or negative.
    #[error(
        "history of generation {generation} (state.history): {name} = {value}: expected a non-negative number or \"inf\""
    )]
    HistoryValue {
        /// The generation.
        generation: usize,
        /// The field.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A last history entry that is not what the population gives.
    #[error(
        "history of generation {generation} (state.history): {name} = {recorded}, but the population's is {population}"
    )]
    HistoryBest {
        /// The generation.
        generation: usize,
        /// The field.
        name: &'static str,
        /// Its value.
        recorded: f64,
        /// The population's.
        population: f64,
    },
    /// Probes of a method that makes none.
    #[error("{probes} refinement attempt(s) (probes), but method `{method}` makes none")]
    ProbesMethod {
        /// The probes.
        probes: usize,
        /// The method.
        method: String,
    },
    /// A probe after a generation out of order.
    #[error("probe {index} after generation {generation}: expected generation {from} to {to}")]
    ProbeGeneration {
        /// The probe.
        index: usize,
        /// Its generation.
        generation: usize,
        /// The earliest allowed (the previous probe's).
        from: usize,
        /// The latest (the state's).
        to: usize,
    },
    /// A probe's count of simulations before it that the generations and probes do not make.
    #[error(
        "probe {index}: {recorded} simulations before it recorded, the generations and earlier probes make {expected}"
    )]
    ProbeBefore {
        /// The probe.
        index: usize,
        /// The count recorded.
        recorded: u64,
        /// What they make.
        expected: u128,
    },
    /// A probe's goals that are not finite and non-negative.
    #[error("probe {index}: goals {goals:?}: expected finite non-negative numbers")]
    ProbeGoals {
        /// The probe.
        index: usize,
        /// Its goals.
        goals: [f64; 2],
    },
    /// A member of the population or the archive.
    #[error("{set} member {index}: {reason}")]
    Member {
        /// "population" or "archive".
        set: &'static str,
        /// The member.
        index: usize,
        /// What is wrong with it.
        reason: MemberError,
    },
}

/// What is wrong with one member of a checkpoint.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MemberError {
    /// Goals that are not finite and non-negative.
    #[error("goals J_pos {j_pos_m} m, J_att {j_att_deg} deg: expected finite non-negative numbers")]
    Goals {
        /// J_pos \[m\].
        j_pos_m: f64,
        /// J_att \[deg\].
        j_att_deg: f64,
    },
    /// A divergence time that is not finite and non-negative.
    #[error("diverged at t = {t_s} s: expected a finite non-negative time")]
    DivergedAt {
        /// The time \[s\].
        t_s: f64,
    },
    /// A failure reason longer than a failure carries.
    #[error(
        "failure reason of {bytes} bytes, longer than the {MAX_REASON_BYTES} a failure carries"
    )]
    Reason {
        /// Its bytes.
        bytes: usize,
    },
    /// A chromosome of another length than the genes make.
    #[error("chromosome of {bits} bits, the factor table's genes make {expected}")]
    Bits {
        /// Its bits.
        bits: usize,
        /// The genes' bits.
        expected: usize,
    },
    /// Values of another count than the factors.
    #[error("{values} values recorded, the factor table has {factors} factors")]
    Values {
        /// The values recorded.
        values: usize,
        /// The factors.
        factors: usize,
    },
    /// A chromosome that does not decode to the recorded values.
    #[error(
        "its chromosome decodes to {} = {decoded:?}, its recorded value is {recorded:?}",
        gene_name(*gene)
    )]
    Decodes {
        /// The gene (the factor's index).
        gene: usize,
        /// What the chromosome decodes to.
        decoded: f64,
        /// The value recorded.
        recorded: f64,
    },
    /// A divergence in an event the job does not have.
    #[error("diverged in event {event}, the job has {events}")]
    Event {
        /// The event.
        event: usize,
        /// The job's events.
        events: usize,
    },
}

/// `factor cmoff`, or `gene 20` past the factors.
fn gene_name(k: usize) -> String {
    Factor::ALL
        .get(k)
        .map_or_else(|| format!("gene {k}"), |f| format!("factor {}", f.name()))
}

/// How a checkpoint's content differs from its digest (`changed: state.population[4]`).
#[derive(Debug, Clone, PartialEq)]
pub struct DigestMismatch {
    /// The parts whose hash changed.
    pub changed: Vec<String>,
    /// The parts digested that are gone.
    pub gone: Vec<String>,
    /// The content is the one digested: only the record of its parts was edited.
    pub parts_only: bool,
}

impl fmt::Display for DigestMismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.parts_only {
            return f.write_str("changed: digest.parts");
        }
        let mut what = Vec::new();
        if !self.changed.is_empty() {
            what.push(format!("changed: {}", digest::listed(&self.changed)));
        }
        if !self.gone.is_empty() {
            what.push(format!("gone: {}", digest::listed(&self.gone)));
        }
        if what.is_empty() {
            what.push("changed: digest.sha256".into());
        }
        f.write_str(&what.join("; "))
    }
}
