//! A directory that an `--overwrite` run was killed in outright (SIGKILL, a power cut), which
//! neither committed nor put the earlier run back: the earlier run sits in
//! `DIR/.sepval-replaced` (whole once it was moved aside: its marker moves last), and `DIR`
//! holds what the killed run wrote, its marker without a manifest.
//!
//! The choice made: the killed run is the partial one, the earlier run the one to keep until a
//! new run replaces it. So a second `--overwrite` discards what the killed run wrote (what its
//! own put-back would have removed, had it been stopped rather than killed) and takes the
//! earlier run, checked against its manifest, as the run it replaces: removed when the new run
//! commits, put back when it fails. A fresh run or a resume is refused, each message saying
//! where the earlier run is and how to put it back by hand; so is an `--overwrite` when the
//! earlier run is not whole there (killed while moving it aside), is not what its manifest
//! lists, or when a run has ended in `DIR` since (which of the two to keep cannot be told).

use std::path::Path;

use super::error::{OutDirError, io};
use super::marker::{self, MARKER_FILE};
use super::{Claim, REPLACED, entries};

/// What an `--overwrite` killed in a directory left.
#[derive(Debug)]
pub(super) struct Killed {
    /// The killed run's command (from its marker, else the command claiming the directory).
    command: String,
    /// Whether the earlier run was moved aside whole (its marker is in [`REPLACED`]).
    whole: bool,
    /// Whether a run has ended in the directory since (its marker has a manifest).
    ended_since: bool,
}

/// What a killed `--overwrite` left in `dir`, if anything (`command` claims the directory).
pub(super) fn killed(dir: &Path, command: &str) -> Option<Killed> {
    let aside = dir.join(REPLACED);
    std::fs::symlink_metadata(&aside).ok()?;
    let (marked, ended_since) = marker::command_of(dir).unwrap_or((command.to_string(), false));
    Some(Killed {
        command: marked,
        whole: aside.is_dir()
            && !aside.is_symlink()
            && std::fs::symlink_metadata(aside.join(MARKER_FILE)).is_ok(),
        ended_since,
    })
}

/// Whether `claim` may use `dir` in the state `killed` describes: only an `--overwrite`, with
/// the earlier run whole in [`REPLACED`] and unchanged, and no run ended in `dir` since.
pub(super) fn check(dir: &Path, claim: &Claim, killed: &Killed) -> Result<(), OutDirError> {
    let aside = dir.join(REPLACED);
    let refuse = |doing: &str, hint: String| interrupted(dir, killed, doing, hint);
    match claim {
        Claim::Fresh => Err(refuse(
            "is not empty",
            "give --overwrite to discard the killed run and replace the earlier one (kept until \
             the new run succeeds, put back if it fails), or give another directory"
                .into(),
        )),
        Claim::Resume { .. } => Err(refuse(
            "not resuming in",
            format!(
                "to resume the killed run, remove the earlier one first (rm -r {})",
                aside.display()
            ),
        )),
        Claim::Overwrite if killed.ended_since => Err(refuse(
            "not clearing",
            format!(
                "a run has ended in it since (its {MARKER_FILE} lists its files), so which of the \
                 two to keep cannot be told: remove the one not wanted (rm -r {} keeps the later)",
                aside.display()
            ),
        )),
        Claim::Overwrite if !killed.whole => Err(refuse(
            "not clearing",
            "so it cannot be replaced as it is".into(),
        )),
        Claim::Overwrite => marker::check_clearable(&aside, &entries(&aside)?).map_err(|e| {
            refuse(
                "not clearing",
                format!("but what it holds cannot be taken for that run: {e}"),
            )
        }),
    }
}

/// Removes what the killed run wrote in `dir` (everything but the lock and [`REPLACED`]), its
/// marker included.
pub(super) fn discard_killed(dir: &Path) -> Result<(), OutDirError> {
    for name in entries(dir)?
        .iter()
        .map(String::as_str)
        .chain([MARKER_FILE])
    {
        let p = dir.join(name);
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.is_dir() => std::fs::remove_dir_all(&p),
            Ok(_) => std::fs::remove_file(&p),
            Err(_) => continue,
        }
        .map_err(io("cannot remove", &p))?;
    }
    Ok(())
}

/// The refusal of `dir` (`doing` it, with `hint`), saying where the earlier run is and how to
/// put it back.
fn interrupted(dir: &Path, killed: &Killed, doing: &str, hint: String) -> OutDirError {
    let (path, aside) = (dir.display(), dir.join(REPLACED));
    let aside = aside.display();
    let lead = if doing == "is not empty" {
        format!("{path} is not empty")
    } else {
        format!("{doing} {path}")
    };
    let command = &killed.command;
    let (state, put_back) = if killed.whole {
        (
            format!("the earlier run it was replacing is whole in {aside}"),
            format!(
                "to put it back, remove everything in {path} but {REPLACED}, then move what \
                 {aside} holds (its {MARKER_FILE} too) into {path} and remove it"
            ),
        )
    } else {
        (
            format!(
                "the earlier run it was replacing is partly in {aside} (the run was killed while \
                 moving it aside) and partly still in {path}"
            ),
            format!("to put it back, move what {aside} holds into {path} and remove it"),
        )
    };
    OutDirError::Interrupted {
        path: dir.to_path_buf(),
        message: format!(
            "{lead}: an --overwrite run of `{command}` into it was killed before it ended, and \
             {state}; {hint}; {put_back}"
        ),
    }
}
