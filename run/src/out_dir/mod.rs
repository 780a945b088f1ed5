//! Output directories of runs (`--out` of fit, diagnose, plan, predict, envelope, update),
//! protected: a run holds a lock in its directory for its whole life, so a second run into it
//! is refused (naming the holder's process id); the directory is never one of the run's inputs,
//! nor holds one, nor lies inside an input directory ([`Input`]); a directory that already
//! holds something is refused unless it is the run being resumed, or the user asked to clear
//! it; and a directory is only ever cleared when everything in it is what a sepval run wrote,
//! as the manifest of its marker lists it (`marker`).
//!
//! A claim has two steps, so that a refusal never deletes or rewrites anything: [`RunDir::claim`]
//! takes the lock and checks the directory without changing what is in it, before anything
//! runs (no worker is started for a refused `--out`); [`RunDir::prepare`], called once every
//! input is checked (a resumed checkpoint re-evaluated and replayed included) and as late as
//! the run allows, clears the directory (checking it again) or removes the abandoned
//! continuation of a resumed run, and writes the marker. When the run ends (the [`RunDir`]
//! dropped, on success or error), the marker gets the manifest of what the directory holds.
//!
//! An `--overwrite` moves the earlier run into `DIR/.sepval-replaced` ([`REPLACED`]), removed
//! when the new run commits and put back when it fails. A run killed outright leaves it there:
//! a second `--overwrite` discards the killed run's files and replaces the earlier run, and
//! every other use of the directory is refused saying where the earlier run is and how to put
//! it back (`replaced`).
//!
//! An `--out` that is a dangling symbolic link or a link loop is refused as such: nothing is
//! written through it.
//!
//! Files: `DIR/.sepval-lock` (the holder's process id; removed when the run ends, left behind
//! only by a killed process, and then taken over once that process is gone) and
//! `DIR/.sepval-run` (the marker: which command made the directory, and its manifest).

mod error;
mod inputs;
mod lock;
mod marker;
mod replaced;

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

pub use error::OutDirError;
pub use inputs::{Input, check_file, recorded_inputs};
pub use lock::{DirLock, LOCK_FILE};
pub use marker::MARKER_FILE;

use error::io;

/// Where a search's checkpoint of generation `generation` lies in its run directory `dir`
/// (`DIR/generations/gen-NNNN.json`, `sepval_fit::checkpoint`): a directory's own checkpoints
/// are what a resumed run keeps and `--overwrite` refuses to remove.
pub fn generation_path(dir: &Path, generation: usize) -> PathBuf {
    dir.join("generations")
        .join(format!("gen-{generation:04}.json"))
}

/// How a run uses its directory.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Claim {
    /// A new run: the directory must be absent or empty.
    Fresh,
    /// A new run into a directory whose contents may be cleared first.
    Overwrite,
    /// Resuming the run of the checkpoint whose run directory this is: its contents stay but
    /// for the checkpoints of generations after the one resumed from.
    Resume {
        /// The checkpoint resumed from.
        checkpoint: PathBuf,
        /// Its generation.
        generation: usize,
    },
}

/// A run's request for its output directory.
#[derive(Debug)]
pub struct Request<'a> {
    /// The command (recorded in the marker).
    pub command: &'a str,
    /// How the run uses the directory.
    pub claim: Claim,
    /// What the run reads: the directory may be none of them, hold none and lie inside none
    /// (the run directory a resumed run goes on in, and its checkpoint, aside).
    pub inputs: &'a [Input],
    /// How the command goes on with an interrupted run in a directory (the refusal of a
    /// non-empty one suggests it), e.g. "resume from one of its checkpoints (--resume ...)";
    /// `None` for a command that cannot.
    pub resume: Option<String>,
}

/// A claimed run directory: locked until dropped. A directory this claim created is removed
/// again when the run ends before writing anything into it (a refused input, workers that
/// would not start), so a failed run leaves nothing behind.
#[derive(Debug)]
pub struct RunDir {
    path: PathBuf,
    lock: PathBuf,
    created: bool,
    claim: Claim,
    command: String,
    /// Whether [`RunDir::prepare`] ran (the marker is then written again, with the manifest,
    /// when the run ends).
    prepared: AtomicBool,
    /// Whether [`RunDir::prepare`] moved an earlier run aside ([`REPLACED`]), to be put back
    /// if this run does not end by [`RunDir::commit`].
    replaced: AtomicBool,
    /// Whether the run ended by [`RunDir::commit`].
    committed: bool,
    /// The notice of an ill-formed lock taken over.
    notice: Option<String>,
}

impl RunDir {
    /// Claims `path` for a run as `request` says (created if absent): checks that it is none of
    /// the run's inputs, takes the lock and checks that the directory may be used as the claim
    /// says. Nothing in it is changed yet: [`RunDir::prepare`] does that once the run's inputs
    /// are checked.
    pub fn claim(path: &Path, request: Request<'_>) -> Result<RunDir, OutDirError> {
        let Request {
            command,
            claim,
            inputs,
            resume,
        } = request;
        let expected = match &claim {
            Claim::Resume { checkpoint, .. } => Some(run_of(checkpoint)),
            _ => None,
        };
        let allowed: Vec<PathBuf> = match (&claim, &expected) {
            // The run directory a resumed run goes on in, and the checkpoint in it.
            (Claim::Resume { checkpoint, .. }, Some(e))
                if inputs::resolved(path) == inputs::resolved(e) =>
            {
                vec![inputs::resolved(e), inputs::resolved(checkpoint)]
            }
            _ => Vec::new(),
        };
        inputs::check(path, inputs, &allowed)?;
        let created = make_dir(path)?;
        let lock = path.join(LOCK_FILE);
        let notice = match lock::take_lock(path, &lock) {
            Ok(notice) => notice,
            Err(e) => {
                if created {
                    let _ = std::fs::remove_dir(path);
                }
                return Err(e);
            }
        };
        let dir = RunDir {
            path: path.to_path_buf(),
            lock,
            created,
            claim: claim.clone(),
            command: command.to_string(),
            prepared: AtomicBool::new(false),
            replaced: AtomicBool::new(false),
            committed: false,
            notice,
        };
        // From here on the lock is ours (released when `dir` drops, on error too).
        let others = entries(path)?;
        if let Some(killed) = replaced::killed(path, command) {
            replaced::check(path, &claim, &killed)?;
            return Ok(dir);
        }
        match claim {
            Claim::Fresh => {
                if let Some(first) = others.first() {
                    return Err(OutDirError::NotEmpty {
                        path: path.to_path_buf(),
                        first: first.clone(),
                        resume: resume.map(|r| format!(", {r}")).unwrap_or_default(),
                    });
                }
            }
            Claim::Overwrite => marker::check_clearable(path, &others)?,
            Claim::Resume {
                checkpoint,
                generation,
            } => {
                let expected = expected.unwrap_or_default();
                if others.is_empty() {
                    return Ok(dir);
                }
                if inputs::resolved(path) != inputs::resolved(&expected) {
                    return Err(OutDirError::OtherRun {
                        path: path.to_path_buf(),
                        checkpoint: checkpoint.clone(),
                        expected,
                    });
                }
                marker::check_resumable(path, &others)?;
                let checkpoint_id = inputs::resolved(&checkpoint);
                if later_generations(path, generation)?
                    .iter()
                    .any(|p| inputs::resolved(p) == checkpoint_id)
                {
                    return Err(OutDirError::WouldRemoveCheckpoint {
                        path: path.to_path_buf(),
                        checkpoint,
                        generation,
                    });
                }
            }
        }
        Ok(dir)
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The notice of a lock taken over that named no process (`0`, a negative number, text),
    /// for the command to tell.
    pub fn notice(&self) -> Option<&str> {
        self.notice.as_deref()
    }

    /// Makes the directory ready for the run, the first change to what is in it: clears it
    /// ([`Claim::Overwrite`], after checking again that everything in it is an earlier run's),
    /// or removes the checkpoints of generations after the one resumed from ([`Claim::Resume`]:
    /// those of the continuation being replaced), then writes the marker. Returns the
    /// checkpoints removed when resuming. Call it once every input is read and checked, as
    /// late as the run allows (just before the first file is written).
    pub fn prepare(&self) -> Result<Vec<PathBuf>, OutDirError> {
        let removed = match &self.claim {
            Claim::Fresh => Vec::new(),
            Claim::Overwrite => {
                if let Some(killed) = replaced::killed(&self.path, &self.command) {
                    // Checked again, as late as possible; the earlier run, already aside, is
                    // the one this run replaces (put back if it fails).
                    replaced::check(&self.path, &self.claim, &killed)?;
                    self.replaced.store(true, Ordering::Relaxed);
                    replaced::discard_killed(&self.path)?;
                } else {
                    let others = entries(&self.path)?;
                    marker::check_clearable(&self.path, &others)?;
                    if !others.is_empty() {
                        self.move_aside(&others)?;
                    }
                }
                Vec::new()
            }
            Claim::Resume { generation, .. } => {
                // Checked again, as late as possible: nothing not its run's is removed.
                marker::check_resumable(&self.path, &entries(&self.path)?)?;
                let removed = later_generations(&self.path, *generation)?;
                for p in &removed {
                    std::fs::remove_file(p).map_err(io("cannot remove", p))?;
                }
                removed
            }
        };
        marker::write_started(&self.path, &self.command)?;
        self.prepared.store(true, Ordering::Relaxed);
        Ok(removed)
    }

    /// Moves the earlier run's `others` (and its marker) into [`REPLACED`], where they stay
    /// until this run commits (then removed) or fails (then put back).
    fn move_aside(&self, others: &[String]) -> Result<(), OutDirError> {
        let aside = self.path.join(REPLACED);
        std::fs::create_dir(&aside).map_err(io("cannot create", &aside))?;
        self.replaced.store(true, Ordering::Relaxed);
        for name in others.iter().map(String::as_str).chain([MARKER_FILE]) {
            let p = self.path.join(name);
            if std::fs::symlink_metadata(&p).is_ok() {
                std::fs::rename(&p, aside.join(name)).map_err(io("cannot move aside", &p))?;
            }
        }
        Ok(())
    }

    /// Ends the run as a success: the earlier run an `--overwrite` moved aside is removed, and
    /// the directory keeps what this run wrote. A run dropped without it (an error, Ctrl-C)
    /// puts the earlier run back as it was.
    pub fn commit(mut self) {
        self.committed = true;
        if self.replaced.load(Ordering::Relaxed) {
            let _ = std::fs::remove_dir_all(self.path.join(REPLACED));
        }
    }

    /// Puts back the earlier run an `--overwrite` moved aside: what this run wrote goes, then
    /// the earlier run's entries and marker return (best effort: what cannot return stays in
    /// [`REPLACED`], never removed).
    fn put_back(&self) {
        let aside = self.path.join(REPLACED);
        let Ok(names) = std::fs::read_dir(&aside).map(|d| {
            d.filter_map(Result::ok)
                .map(|e| e.file_name())
                .collect::<Vec<_>>()
        }) else {
            return;
        };
        for name in entries(&self.path).unwrap_or_default() {
            let p = self.path.join(name);
            let _ = match std::fs::symlink_metadata(&p) {
                Ok(m) if m.is_dir() => std::fs::remove_dir_all(&p),
                _ => std::fs::remove_file(&p),
            };
        }
        let _ = std::fs::remove_file(self.path.join(MARKER_FILE));
        for name in names {
            let _ = std::fs::rename(aside.join(&name), self.path.join(&name));
        }
        let _ = std::fs::remove_dir(&aside);
    }
}

impl Drop for RunDir {
    fn drop(&mut self) {
        if self.replaced.load(Ordering::Relaxed) && !self.committed {
            self.put_back();
            let _ = std::fs::remove_file(&self.lock);
            return;
        }
        // A directory this run made and wrote no file into (an empty `generations/` of a fit
        // that failed at its start is no file) goes, with what the run made in it.
        if self.created && holds_no_file(&self.path) && remove_empty(&self.path) {
            let _ = std::fs::remove_file(self.path.join(MARKER_FILE));
            let _ = std::fs::remove_file(&self.lock);
            let _ = std::fs::remove_dir(&self.path);
            return;
        }
        if self.prepared.load(Ordering::Relaxed) {
            // The manifest of what the run wrote, before the lock goes (best effort: a marker
            // without one only makes a later --overwrite refuse the directory).
            let _ = marker::write_ended(&self.path, &self.command);
        }
        let _ = std::fs::remove_file(&self.lock);
    }
}

/// Makes the directory `path` unless it is one; whether it was made. A path that is not a
/// directory, or a link that does not resolve, is refused.
fn make_dir(path: &Path) -> Result<bool, OutDirError> {
    check_link(path)?;
    match std::fs::metadata(path) {
        Ok(m) if !m.is_dir() => Err(OutDirError::NotADirectory {
            path: path.to_path_buf(),
        }),
        Ok(_) => Ok(false),
        Err(_) => {
            std::fs::create_dir_all(path).map_err(io("cannot create", path))?;
            Ok(true)
        }
    }
}

/// Refuses an `--out` that is a symbolic link which does not resolve (to nothing, or in a
/// loop): creating the directory would fail or write where the link points.
fn check_link(path: &Path) -> Result<(), OutDirError> {
    let is_link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    if !is_link {
        return Ok(());
    }
    match std::fs::metadata(path) {
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(OutDirError::DanglingLink {
            path: path.to_path_buf(),
            target: std::fs::read_link(path).unwrap_or_default(),
        }),
        // ELOOP: too many levels of symbolic links.
        Err(e) if e.raw_os_error() == Some(40) => Err(OutDirError::LinkLoop {
            path: path.to_path_buf(),
        }),
        Err(e) => Err(io("cannot resolve the link", path)(e)),
    }
}

/// The checkpoints in `dir` of generations after `generation` (those of an abandoned
/// continuation, which a run resumed from an earlier generation replaces), sorted: files named
/// exactly as a fit names them (`generations/gen-NNNN.json`), nothing else.
fn later_generations(dir: &Path, generation: usize) -> Result<Vec<PathBuf>, OutDirError> {
    let generations = dir.join("generations");
    let Ok(entries) = std::fs::read_dir(&generations) else {
        return Ok(Vec::new());
    };
    let mut later = Vec::new();
    for e in entries.filter_map(Result::ok) {
        let name = e.file_name().to_string_lossy().into_owned();
        let named = name
            .strip_prefix("gen-")
            .and_then(|n| n.strip_suffix(".json"))
            .and_then(|n| n.parse::<usize>().ok())
            .filter(|&g| e.path() == generation_path(dir, g));
        let is_file = e.file_type().is_ok_and(|t| t.is_file());
        if is_file && named.is_some_and(|g| g > generation) {
            later.push(e.path());
        }
    }
    later.sort();
    Ok(later)
}

/// The run directory of `checkpoint`: DIR/generations/gen-NNNN.json belongs to DIR.
fn run_of(checkpoint: &Path) -> PathBuf {
    checkpoint
        .parent()
        .and_then(Path::parent)
        .map(Path::to_path_buf)
        .unwrap_or_default()
}

/// Whether `path` holds nothing but directories without a file (and a run's lock and marker).
fn holds_no_file(path: &Path) -> bool {
    entries(path).is_ok_and(|names| {
        names.iter().all(|n| {
            let p = path.join(n);
            std::fs::symlink_metadata(&p).is_ok_and(|m| m.is_dir()) && holds_no_file(&p)
        })
    })
}

/// Removes the directories under `path` that [`holds_no_file`] found, deepest first
/// (`remove_dir`: never a file); whether all went.
fn remove_empty(path: &Path) -> bool {
    entries(path).is_ok_and(|names| {
        names.iter().all(|n| {
            let p = path.join(n);
            remove_empty(&p) && std::fs::remove_dir(&p).is_ok()
        })
    })
}

/// Where an `--overwrite` keeps the earlier run until it commits (`DIR/.sepval-replaced`).
pub const REPLACED: &str = ".sepval-replaced";

/// The directory's entries other than the lock, the marker and an earlier run moved aside,
/// sorted.
fn entries(path: &Path) -> Result<Vec<String>, OutDirError> {
    let mut out: Vec<String> = std::fs::read_dir(path)
        .map_err(io("cannot read", path))?
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != LOCK_FILE && n != MARKER_FILE && n != REPLACED)
        .collect();
    out.sort();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(command: &str, claim: Claim) -> Request<'_> {
        Request {
            command,
            claim,
            inputs: &[],
            resume: None,
        }
    }

    #[test]
    fn a_directory_is_claimed_once_and_only_cleared_when_it_is_ours() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path().join("run");
        let claim = |c: Claim| RunDir::claim(&d, request("fit", c));
        let first = claim(Claim::Fresh).unwrap();
        let e = claim(Claim::Overwrite).unwrap_err();
        assert!(
            e.to_string()
                .contains(&format!("in use by sepval process {}", std::process::id())),
            "{e}"
        );
        first.prepare().unwrap();
        std::fs::write(d.join("result.json"), "{}").unwrap();
        drop(first);
        assert!(!d.join(LOCK_FILE).exists());
        let e = claim(Claim::Fresh).unwrap_err();
        assert!(
            e.to_string().contains(
                "is not empty (it holds result.json); give another directory, or clear it (--overwrite)"
            ),
            "{e}"
        );
        // A claim refused later (an input, a worker) has cleared nothing: only prepare does.
        drop(claim(Claim::Overwrite).unwrap());
        assert!(d.join("result.json").exists() && !d.join(LOCK_FILE).exists());
        let again = claim(Claim::Overwrite).unwrap();
        assert!(d.join("result.json").exists());
        assert_eq!(again.prepare().unwrap(), Vec::<PathBuf>::new());
        assert!(!d.join("result.json").exists() && d.join(MARKER_FILE).exists());
        std::fs::write(d.join("plan.json"), "{}").unwrap();
        again.commit();
        assert!(!d.join(REPLACED).exists() && !d.join("result.json").exists());
        // The manifest of the ended run makes a directory ours, whatever it holds.
        let marked = RunDir::claim(&d, request("plan", Claim::Overwrite)).unwrap();
        marked.prepare().unwrap();
        assert!(!d.join("plan.json").exists());
        marked.commit();
        // A directory sepval did not make is never cleared, nor one with a file of another
        // tool beside a sepval result.
        let other = tmp.path().join("mine");
        std::fs::create_dir(&other).unwrap();
        std::fs::write(other.join("thesis.tex"), "x").unwrap();
        std::fs::write(other.join("result.json"), "{\"x\": 1}").unwrap();
        let e = RunDir::claim(&other, request("fit", Claim::Overwrite)).unwrap_err();
        assert!(
            e.to_string().starts_with(&format!(
                "not clearing {}: it is not a sepval output directory (it has no .sepval-run; it holds result.json, thesis.tex)",
                other.display()
            )),
            "{e}"
        );
        assert!(other.join("thesis.tex").exists() && !other.join(LOCK_FILE).exists());
        // A killed run's lock is taken over.
        std::fs::write(d.join(LOCK_FILE), "999999999\n").unwrap();
        claim(Claim::Fresh).unwrap();
    }

    #[test]
    fn a_run_refused_before_it_prepared_leaves_its_directory_as_it_was() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path().join("run");
        drop(RunDir::claim(&d, request("predict", Claim::Fresh)).unwrap());
        assert!(!d.exists());
        // A run that made directories but wrote no file in them (a fit that failed at its
        // start, its `generations/` empty) leaves nothing either; one that wrote a file keeps
        // it, and the directories that lead to it.
        let run = RunDir::claim(&d, request("fit", Claim::Fresh)).unwrap();
        run.prepare().unwrap();
        std::fs::create_dir_all(d.join("generations/deeper")).unwrap();
        drop(run);
        assert!(!d.exists());
        let run = RunDir::claim(&d, request("fit", Claim::Fresh)).unwrap();
        run.prepare().unwrap();
        std::fs::create_dir_all(d.join("generations/deeper")).unwrap();
        std::fs::write(d.join("generations/gen-0000.json"), "{}").unwrap();
        drop(run);
        assert!(d.join("generations/gen-0000.json").exists());
        assert!(d.join("generations/deeper").is_dir());
        std::fs::remove_dir_all(&d).unwrap();
        let run = RunDir::claim(&d, request("predict", Claim::Fresh)).unwrap();
        run.prepare().unwrap();
        std::fs::write(d.join("prediction.json"), "{}").unwrap();
        drop(run);
        let marker = std::fs::read_to_string(d.join(MARKER_FILE)).unwrap();
        assert!(marker.contains("\"prediction.json\": \""), "{marker}");
        // An overwrite that ends before prepare (a refused input, Ctrl-C while it computes)
        // leaves the earlier run and its manifest whole.
        drop(RunDir::claim(&d, request("predict", Claim::Overwrite)).unwrap());
        assert_eq!(
            std::fs::read_to_string(d.join(MARKER_FILE)).unwrap(),
            marker
        );
        assert!(d.join("prediction.json").exists());
    }

    #[test]
    fn an_overwrite_that_fails_puts_the_earlier_run_back_as_it_was() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path().join("run");
        let first = RunDir::claim(&d, request("fit", Claim::Fresh)).unwrap();
        first.prepare().unwrap();
        std::fs::create_dir_all(d.join("generations")).unwrap();
        std::fs::write(d.join("generations/gen-0001.json"), "old checkpoint").unwrap();
        std::fs::write(d.join("result.json"), "old result").unwrap();
        first.commit();
        let marker = std::fs::read_to_string(d.join(MARKER_FILE)).unwrap();
        // Cleared, then a failure (an error, Ctrl-C) after it wrote: the earlier run returns.
        let again = RunDir::claim(&d, request("fit", Claim::Overwrite)).unwrap();
        again.prepare().unwrap();
        assert!(!d.join("result.json").exists() && d.join(REPLACED).is_dir());
        std::fs::create_dir_all(d.join("generations")).unwrap();
        std::fs::write(d.join("generations/gen-0001.json"), "new checkpoint").unwrap();
        std::fs::write(d.join("partial.json"), "new").unwrap();
        drop(again);
        assert_eq!(
            std::fs::read_to_string(d.join("result.json")).unwrap(),
            "old result"
        );
        assert_eq!(
            std::fs::read_to_string(d.join("generations/gen-0001.json")).unwrap(),
            "old checkpoint"
        );
        assert_eq!(
            std::fs::read_to_string(d.join(MARKER_FILE)).unwrap(),
            marker
        );
        assert!(!d.join("partial.json").exists() && !d.join(REPLACED).exists());
        assert!(!d.join(LOCK_FILE).exists());
        // So it may be cleared again, and a run that commits replaces it.
        let last = RunDir::claim(&d, request("fit", Claim::Overwrite)).unwrap();
        last.prepare().unwrap();
        std::fs::write(d.join("result.json"), "new result").unwrap();
        last.commit();
        assert!(!d.join(REPLACED).exists() && !d.join("generations").exists());
        assert_eq!(
            std::fs::read_to_string(d.join("result.json")).unwrap(),
            "new result"
        );
    }

    /// A run that holds `d` killed outright (SIGKILL) after writing `partial.json`: nothing of
    /// its drop runs, and its lock names a process that is gone.
    fn killed(d: &Path, run: RunDir) {
        std::fs::write(d.join("partial.json"), "killed").unwrap();
        std::mem::forget(run);
        std::fs::write(d.join(LOCK_FILE), "999999999\n").unwrap();
    }

    #[test]
    fn after_an_overwrite_killed_outright_a_second_one_replaces_the_earlier_run() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path().join("run");
        let claim = |c: Claim| RunDir::claim(&d, request("fit", c));
        let first = claim(Claim::Fresh).unwrap();
        first.prepare().unwrap();
        std::fs::write(d.join("result.json"), "old result").unwrap();
        first.commit();
        let marker = std::fs::read_to_string(d.join(MARKER_FILE)).unwrap();
        let run = claim(Claim::Overwrite).unwrap();
        run.prepare().unwrap();
        killed(&d, run);
        // A fresh run and a resume are refused, saying where the earlier run is.
        let resume = Claim::Resume {
            checkpoint: d.join("generations/gen-0001.json"),
            generation: 1,
        };
        for c in [Claim::Fresh, resume] {
            let e = claim(c).unwrap_err().to_string();
            assert!(
                e.contains(&format!(
                    "the earlier run it was replacing is whole in {}",
                    d.join(REPLACED).display()
                )) && e.contains("; to put it back, remove everything in"),
                "{e}"
            );
            assert!(d.join("partial.json").exists());
        }
        // A second overwrite that fails: the earlier run returns as it was, the killed run's
        // file gone.
        let again = claim(Claim::Overwrite).unwrap();
        again.prepare().unwrap();
        assert!(!d.join("partial.json").exists() && d.join(REPLACED).is_dir());
        std::fs::write(d.join("mine.json"), "new").unwrap();
        drop(again);
        assert_eq!(
            std::fs::read_to_string(d.join("result.json")).unwrap(),
            "old result"
        );
        assert_eq!(
            std::fs::read_to_string(d.join(MARKER_FILE)).unwrap(),
            marker
        );
        assert!(!d.join("mine.json").exists() && !d.join(REPLACED).exists());
        // Killed again, then one that commits: the new run alone.
        let run = claim(Claim::Overwrite).unwrap();
        run.prepare().unwrap();
        killed(&d, run);
        let last = claim(Claim::Overwrite).unwrap();
        last.prepare().unwrap();
        std::fs::write(d.join("result.json"), "new result").unwrap();
        last.commit();
        assert!(!d.join(REPLACED).exists() && !d.join("partial.json").exists());
        assert_eq!(
            std::fs::read_to_string(d.join("result.json")).unwrap(),
            "new result"
        );
        // Killed while moving the earlier run aside (its marker not yet moved): refused,
        // nothing removed.
        std::fs::create_dir(d.join(REPLACED)).unwrap();
        std::fs::rename(d.join("result.json"), d.join(REPLACED).join("result.json")).unwrap();
        let e = claim(Claim::Overwrite).unwrap_err().to_string();
        assert!(e.contains("partly in") && e.contains("move what"), "{e}");
        assert!(d.join(REPLACED).join("result.json").exists());
    }

    #[test]
    fn a_dangling_or_looping_link_is_refused_as_such() {
        let tmp = tempfile::tempdir().unwrap();
        let dangling = tmp.path().join("dangling");
        std::os::unix::fs::symlink(tmp.path().join("nowhere"), &dangling).unwrap();
        let e = RunDir::claim(&dangling, request("fit", Claim::Fresh)).unwrap_err();
        assert!(
            matches!(e, OutDirError::DanglingLink { .. })
                && e.to_string().contains("sepval will not write through it"),
            "{e}"
        );
        let looping = tmp.path().join("loop");
        std::os::unix::fs::symlink(&looping, &looping).unwrap();
        let e = RunDir::claim(&looping, request("fit", Claim::Overwrite)).unwrap_err();
        assert!(matches!(e, OutDirError::LinkLoop { .. }), "{e}");
        assert!(!tmp.path().join("nowhere").exists());
    }

    #[test]
    fn an_output_that_is_an_input_is_refused_before_anything_is_made() {
        let tmp = tempfile::tempdir().unwrap();
        let run = tmp.path().join("run");
        let generations = run.join("generations");
        std::fs::create_dir_all(&generations).unwrap();
        let checkpoint = generations.join("gen-0005.json");
        std::fs::write(&checkpoint, "{}").unwrap();
        marker::write_ended(&run, "fit").unwrap();
        let inputs = [
            Input::resumed_run(&checkpoint, &run),
            Input::file("--resume", &checkpoint),
        ];
        let resume = Claim::Resume {
            checkpoint: checkpoint.clone(),
            generation: 5,
        };
        let with = |claim: Claim| Request {
            command: "fit",
            claim,
            inputs: &inputs,
            resume: None,
        };
        // Resuming into its own run directory is what --resume is for.
        RunDir::claim(&run, with(resume.clone())).unwrap();
        let e = RunDir::claim(&run, with(Claim::Overwrite)).unwrap_err();
        assert!(
            e.to_string().starts_with(&format!(
                "{} is the run directory {} of --resume {}, an input of this run",
                run.display(),
                run.display(),
                checkpoint.display()
            )),
            "{e}"
        );
        let inside = run.join("again");
        let e = RunDir::claim(&inside, with(resume)).unwrap_err();
        assert!(
            e.to_string()
                .contains("again lies inside the run directory"),
            "{e}"
        );
        assert!(!inside.exists() && checkpoint.exists());
    }

    #[test]
    fn a_resumed_run_removes_its_later_generations_only_when_prepared() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path().join("run");
        let generations = d.join("generations");
        std::fs::create_dir_all(&generations).unwrap();
        for g in 1..=4 {
            std::fs::write(generations.join(format!("gen-{g:04}.json")), "{}").unwrap();
        }
        let claim = || Claim::Resume {
            checkpoint: generations.join("gen-0002.json"),
            generation: 2,
        };
        // Not a sepval run directory (no marker): nothing in it is taken for the run's.
        let e = RunDir::claim(&d, request("fit", claim())).unwrap_err();
        assert!(
            e.to_string().starts_with(&format!(
                "not resuming in {}: it is not a sepval output directory (it has no .sepval-run",
                d.display()
            )),
            "{e}"
        );
        // A run killed before it ended (a marker without a manifest) is taken as it is; names
        // a fit does not write are never removed.
        marker::write_started(&d, "fit").unwrap();
        std::fs::write(generations.join("gen-9.json"), "mine").unwrap();
        drop(RunDir::claim(&d, request("fit", claim())).unwrap());
        assert!(generations.join("gen-0004.json").exists());
        let resumed = RunDir::claim(&d, request("fit", claim())).unwrap();
        assert_eq!(
            resumed.prepare().unwrap(),
            vec![
                generations.join("gen-0003.json"),
                generations.join("gen-0004.json")
            ]
        );
        assert!(generations.join("gen-0002.json").exists());
        assert!(!generations.join("gen-0003.json").exists() && d.join(MARKER_FILE).exists());
        assert!(generations.join("gen-9.json").exists());
        drop(resumed);
        // Its run has ended: its manifest lists gen-9.json (it was there, unchanged). A file
        // added since, or a checkpoint changed, is not the run's: the resume is refused and
        // nothing is removed.
        std::fs::write(generations.join("gen-0007.json"), "mine").unwrap();
        std::fs::write(d.join("notes.txt"), "mine").unwrap();
        let e = RunDir::claim(&d, request("fit", claim())).unwrap_err();
        assert!(
            e.to_string().ends_with(
                "it holds what its run of `fit` did not write: generations/gen-0007.json (not written by it), notes.txt (not written by it); move what its run did not write out of it, or resume into another (empty) --out"
            ),
            "{e}"
        );
        assert!(generations.join("gen-0007.json").exists());
        std::fs::remove_file(generations.join("gen-0007.json")).unwrap();
        std::fs::remove_file(d.join("notes.txt")).unwrap();
        // The checkpoint resumed from, under a later generation's name, is never removed.
        std::fs::rename(
            generations.join("gen-0002.json"),
            generations.join("gen-0005.json"),
        )
        .unwrap();
        marker::write_ended(&d, "fit").unwrap();
        let e = RunDir::claim(
            &d,
            request(
                "fit",
                Claim::Resume {
                    checkpoint: generations.join("gen-0005.json"),
                    generation: 2,
                },
            ),
        )
        .unwrap_err();
        assert!(
            e.to_string().contains(
                "gen-0005.json holds generation 2 but lies where the run keeps a later generation"
            ),
            "{e}"
        );
        assert!(generations.join("gen-0005.json").exists());
    }
}
