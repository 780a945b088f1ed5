//! The claim "settled" checked (docs/campaign.md, "Rehearsal"): a campaign says it is settled
//! with conditions undecided when no release safe to fly is expected to settle or narrow any
//! of them (crate::next, rule 3). A rehearsal that ends so, asked to check the claim
//! (`--check-settled`), flies every condition then safe to fly (P(fail) at most the fly risk)
//! in turn, each on its own copy of the campaign, as the next release would be flown (the next
//! noise seed), and counts the conditions each settles. The claim holds when none settles any.
//!
//! The copies live in CAMP/settled-check/ while they are flown and are removed after each,
//! also when the check is interrupted or fails; only their counts stay, in rehearsal.json.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use sepval_core::cancel;
use sepval_predict::record::ConditionRecord;
use sepval_run::out_dir::LOCK_FILE;
use sepval_solve::run::ProgressObserver;

use super::fly::{Candidate, Flew, Release, fly};
use super::{Truth, TruthCondition};
use crate::CampaignError;
use crate::assess::StartEvaluator;
use crate::program::Campaign;
use crate::record::record_error;
use crate::state::State;

/// Where the copies are flown, under the campaign's directory.
pub const CHECK_DIR: &str = "settled-check";

/// One safe candidate flown after the campaign said it was settled.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateFlown {
    /// Its condition.
    pub condition: ConditionRecord,
    /// Its probability of failing to clear, as the settled round assessed it.
    pub p_fail: f64,
    /// Whether the truth clears there.
    pub truly_safe: bool,
    /// The undecided conditions it settled.
    pub settled: usize,
    /// The decided conditions it made undecided.
    pub unsettled: usize,
}

/// Removes CAMP/settled-check/ when dropped: the check leaves no copy behind, however it ends.
struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Flies every condition of `c`'s current round that is safe to fly, each on a copy of `c`,
/// as release `number` of the truth; `truth_at` is the truth at every condition.
pub(super) fn check_settled(
    c: &Campaign,
    truth: &Truth,
    truth_at: &[TruthCondition],
    number: usize,
    start: &mut StartEvaluator<'_>,
    observer: &mut dyn ProgressObserver,
) -> Result<Vec<CandidateFlown>, CampaignError> {
    let current = c.current()?;
    if current.iter().all(|a| a.state != State::Undecided) {
        return Ok(Vec::new());
    }
    let fly_risk = c.file.settings.fly_risk;
    let scratch = Scratch(c.dir.join(CHECK_DIR));
    if scratch.0.exists() {
        std::fs::remove_dir_all(&scratch.0).map_err(|e| record_error(&scratch.0, e))?;
    }
    let mut out = Vec::new();
    for (index, a) in current.iter().enumerate() {
        if a.row.p_fail > fly_risk {
            continue;
        }
        cancel::check()?;
        let dir = scratch.0.join(format!("{:02}", index + 1));
        copy_campaign(&c.dir, &dir)?;
        let flown_dir = dir.join("rehearsal");
        std::fs::create_dir_all(&flown_dir).map_err(|e| record_error(&flown_dir, e))?;
        let mut copy = Campaign::open(&dir, c.threads)?;
        let release = Release {
            truth,
            at: Candidate {
                index,
                p_fail: a.row.p_fail,
                expected_settled: 0.0,
            },
            number,
            dir: &flown_dir,
        };
        let f = match fly(&mut copy, &release, truth_at[index].fails, start, observer)? {
            Flew::Added(f) | Flew::Tumbled(f, _) => f,
        };
        drop(copy);
        std::fs::remove_dir_all(&dir).map_err(|e| record_error(&dir, e))?;
        out.push(CandidateFlown {
            condition: f.condition,
            p_fail: a.row.p_fail,
            truly_safe: f.truly_safe,
            settled: f.settled,
            unsettled: f.unsettled,
        });
    }
    Ok(out)
}

/// Copies the campaign in `from` to `to`, without its lock, its rehearsal's files or an
/// earlier check: what `Campaign::open` reads (the record names its rounds and releases by
/// paths relative to the campaign, its inputs by absolute paths).
fn copy_campaign(from: &Path, to: &Path) -> Result<(), CampaignError> {
    let skip = [LOCK_FILE, CHECK_DIR, "rehearsal", "rehearsal.json"];
    copy_tree(from, to, &skip)
}

/// Copies the directory `from` to `to`, leaving out the entries of `from` named in `skip`.
fn copy_tree(from: &Path, to: &Path, skip: &[&str]) -> Result<(), CampaignError> {
    std::fs::create_dir_all(to).map_err(|e| record_error(to, e))?;
    for entry in std::fs::read_dir(from).map_err(|e| record_error(from, e))? {
        let entry = entry.map_err(|e| record_error(from, e))?;
        let name = entry.file_name();
        if skip.iter().any(|s| name == *s) {
            continue;
        }
        let (src, dst) = (entry.path(), to.join(&name));
        let kind = entry.file_type().map_err(|e| record_error(&src, e))?;
        if kind.is_dir() {
            copy_tree(&src, &dst, &[])?;
        } else if kind.is_file() {
            std::fs::copy(&src, &dst).map_err(|e| record_error(&src, e))?;
        }
    }
    Ok(())
}
