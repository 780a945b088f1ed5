//! What a command is about to create in the campaign directory outside its staging directory
//! (a release's copy `releases/NN.csv`, a round `rounds/NN`), recorded in
//! `CAMP/.staging/created` before it is created, so that the next command removes what an
//! interrupted one left there, and only that: a file the user put in the campaign directory
//! is never one of them (before 2026-11-29 every entry of `releases/` and `rounds/` that
//! campaign.json does not name was removed, a user's file and an `add --data` given from there
//! included).
//!
//! A command never creates over an entry that is there already: [`claim`] refuses it, naming
//! it, before any work.

use std::io::Write;
use std::path::Path;

use crate::CampaignError;
use crate::record::record_error;

/// The directory of staged changes.
pub(crate) const STAGING: &str = ".staging";

/// The journal in the staging directory.
const JOURNAL: &str = "created";

/// Whether `rel` is a path a command creates (`releases/NN.csv`, `rounds/NN`): a journal line
/// that is not one is ignored.
fn is_created_name(rel: &str) -> bool {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    match rel.split_once('/') {
        Some(("releases", f)) => f.strip_suffix(".csv").is_some_and(digits),
        Some(("rounds", d)) => digits(d),
        _ => false,
    }
}

/// Refuses `rel` (in `dir`) when something is there already: campaign.json does not name it
/// (the caller numbers past what it names), so it is not the campaign's.
pub(crate) fn claim(dir: &Path, rel: &str) -> Result<(), CampaignError> {
    let path = dir.join(rel);
    if std::fs::symlink_metadata(&path).is_ok() {
        return Err(crate::Refusal::Occupied {
            round: rel.starts_with("rounds/"),
            path,
        }
        .into());
    }
    Ok(())
}

/// Records that `rel` (in `dir`) is about to be created; call it just before creating it.
pub(crate) fn record(dir: &Path, rel: &str) -> Result<(), CampaignError> {
    debug_assert!(is_created_name(rel), "{rel}");
    claim(dir, rel)?;
    let staging = dir.join(STAGING);
    std::fs::create_dir_all(&staging).map_err(|e| record_error(&staging, e))?;
    let path = staging.join(JOURNAL);
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .map_err(|e| record_error(&path, e))?;
    writeln!(f, "{rel}")
        .and_then(|()| f.sync_data())
        .map_err(|e| record_error(&path, e))
}

/// Removes what an interrupted command left: each entry its journal records that campaign.json
/// does not name (`named`), then the staging directory.
pub(crate) fn undo(dir: &Path, named: &dyn Fn(&str) -> bool) -> Result<(), CampaignError> {
    let staging = dir.join(STAGING);
    if !staging.exists() {
        return Ok(());
    }
    let journal = std::fs::read_to_string(staging.join(JOURNAL)).unwrap_or_default();
    for rel in journal.lines().filter(|r| is_created_name(r) && !named(r)) {
        let p = dir.join(rel);
        let removed = match std::fs::symlink_metadata(&p) {
            Ok(m) if m.is_dir() => std::fs::remove_dir_all(&p),
            Ok(_) => std::fs::remove_file(&p),
            Err(_) => Ok(()),
        };
        removed.map_err(|e| record_error(&p, e))?;
    }
    std::fs::remove_dir_all(&staging).map_err(|e| record_error(&staging, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_what_a_command_recorded_is_removed_and_nothing_is_created_over() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        std::fs::create_dir_all(d.join("releases")).unwrap();
        std::fs::write(d.join("releases/01.csv"), "named").unwrap();
        std::fs::write(d.join("releases/mine.csv"), "the user's").unwrap();
        std::fs::write(d.join("releases/03.csv"), "the user's too").unwrap();
        let e = record(d, "releases/03.csv").unwrap_err().to_string();
        assert!(e.contains("releases/03.csv is there already"), "{e}");
        record(d, "releases/02.csv").unwrap();
        std::fs::write(d.join("releases/02.csv"), "left by an interrupted add").unwrap();
        record(d, "rounds/01").unwrap();
        std::fs::create_dir_all(d.join("rounds/01")).unwrap();
        undo(d, &|r| r == "releases/01.csv").unwrap();
        assert!(!d.join("releases/02.csv").exists() && !d.join("rounds/01").exists());
        assert!(!d.join(STAGING).exists());
        for kept in ["releases/01.csv", "releases/mine.csv", "releases/03.csv"] {
            assert!(d.join(kept).exists(), "{kept}");
        }
        assert!(!is_created_name("releases/../campaign.json") && !is_created_name("rounds/"));
    }
}
