//! Output directories of runs (`fit --out`, `diagnose --out`), protected: a run holds a lock in
//! its directory for its whole life, so a second run into it is refused (naming the holder's
//! process id); a directory that already holds something is refused unless it is the run being
//! resumed, or the user asked to clear it; and a directory is only ever cleared when it is a
//! sepval output directory (it carries the marker file, or a sepval result).
//!
//! A claim has two steps, so that a refusal never deletes or rewrites anything: [`RunDir::claim`]
//! takes the lock and checks the directory without changing what is in it, before anything
//! runs (no worker is started for a refused `--out`); [`RunDir::prepare`], called once every
//! input is checked (a resumed checkpoint re-evaluated and replayed included), clears the
//! directory or removes the abandoned continuation of a resumed run, and writes the marker.
//!
//! Files: `DIR/.sepval-lock` (the holder's process id; removed when the run ends, left behind
//! only by a killed process, and then taken over once that process is gone) and
//! `DIR/.sepval-run` (the marker: which command made the directory).

use std::fs::OpenOptions;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The lock file of a run directory.
pub const LOCK_FILE: &str = ".sepval-lock";
/// The marker of a sepval output directory.
pub const MARKER_FILE: &str = ".sepval-run";

/// Files whose presence makes a directory (made before the marker existed) a sepval output.
const SEPVAL_OUTPUTS: [&str; 4] = ["result.json", "generations", "diagnosis.json", "baseline"];

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

/// A directory a run cannot use.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OutDirError {
    /// Another process holds the directory.
    #[error(
        "{path} is in use by sepval process {pid} (lock {lock}); wait for it to finish, or remove the lock if that process is gone"
    )]
    Locked {
        /// The directory.
        path: PathBuf,
        /// The holder.
        pid: u32,
        /// The lock file.
        lock: PathBuf,
    },
    /// A non-empty directory for a fresh run.
    #[error(
        "{path} is not empty (it holds {first}); give another directory, resume from one of its checkpoints, or clear it"
    )]
    NotEmpty {
        /// The directory.
        path: PathBuf,
        /// One of its entries.
        first: String,
    },
    /// A directory to resume into that is not the checkpoint's.
    #[error(
        "{path} is not the run directory of checkpoint {checkpoint} (that is {expected}); resume into it, or give an empty directory"
    )]
    OtherRun {
        /// The directory.
        path: PathBuf,
        /// The checkpoint.
        checkpoint: PathBuf,
        /// Its run directory.
        expected: PathBuf,
    },
    /// A directory to clear that sepval did not make.
    #[error(
        "not clearing {path}: it is not a sepval output directory (no {MARKER_FILE}, no result)"
    )]
    NotOurs {
        /// The directory.
        path: PathBuf,
    },
    /// A path that is not a directory.
    #[error("{path} exists and is not a directory")]
    NotADirectory {
        /// The path.
        path: PathBuf,
    },
    /// The file system refused.
    #[error("{what} {path}")]
    Io {
        /// What was attempted.
        what: &'static str,
        /// The path.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
}

fn io(what: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> OutDirError {
    let path = path.to_path_buf();
    move |source| OutDirError::Io { what, path, source }
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
}

impl RunDir {
    /// Claims `path` for a run of `command` (created if absent): takes the lock and checks
    /// that the directory may be used as `claim` says. Nothing in it is changed yet:
    /// [`RunDir::prepare`] does that once the run's inputs are checked.
    pub fn claim(path: &Path, claim: Claim, command: &str) -> Result<RunDir, OutDirError> {
        let mut created = false;
        match std::fs::metadata(path) {
            Ok(m) if !m.is_dir() => {
                return Err(OutDirError::NotADirectory {
                    path: path.to_path_buf(),
                });
            }
            Ok(_) => {}
            Err(_) => {
                std::fs::create_dir_all(path).map_err(io("cannot create", path))?;
                created = true;
            }
        }
        let lock = path.join(LOCK_FILE);
        if let Err(e) = take_lock(path, &lock) {
            if created {
                let _ = std::fs::remove_dir(path);
            }
            return Err(e);
        }
        let dir = RunDir {
            path: path.to_path_buf(),
            lock,
            created,
            claim: claim.clone(),
            command: command.to_string(),
        };
        // From here on the lock is ours (released when `dir` drops, on error too).
        let others = entries(path)?;
        match claim {
            Claim::Fresh => {
                if let Some(first) = others.first() {
                    return Err(OutDirError::NotEmpty {
                        path: path.to_path_buf(),
                        first: first.clone(),
                    });
                }
            }
            Claim::Overwrite => {
                // `entries` leaves the marker out: it is looked for on its own.
                let ours = path.join(MARKER_FILE).is_file()
                    || others.iter().any(|e| SEPVAL_OUTPUTS.contains(&e.as_str()));
                if !others.is_empty() && !ours {
                    return Err(OutDirError::NotOurs {
                        path: path.to_path_buf(),
                    });
                }
            }
            Claim::Resume { checkpoint, .. } => {
                // DIR/generations/gen-NNNN.json belongs to DIR.
                let expected = checkpoint
                    .parent()
                    .and_then(Path::parent)
                    .map(Path::to_path_buf)
                    .unwrap_or_default();
                let same = |a: &Path, b: &Path| {
                    let canon = |p: &Path| std::fs::canonicalize(p).unwrap_or(p.to_path_buf());
                    canon(a) == canon(b)
                };
                if !others.is_empty() && !same(path, &expected) {
                    return Err(OutDirError::OtherRun {
                        path: path.to_path_buf(),
                        checkpoint: checkpoint.clone(),
                        expected,
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

    /// Makes the directory ready for the run, the first change to what is in it: clears it
    /// ([`Claim::Overwrite`]), or removes the checkpoints of generations after the one resumed
    /// from ([`Claim::Resume`]: those of the continuation being replaced), then writes the
    /// marker. Returns the checkpoints removed when resuming.
    pub fn prepare(&self) -> Result<Vec<PathBuf>, OutDirError> {
        let removed = match &self.claim {
            Claim::Fresh => Vec::new(),
            Claim::Overwrite => {
                for e in entries(&self.path)? {
                    let p = self.path.join(e);
                    if p.is_dir() {
                        std::fs::remove_dir_all(&p).map_err(io("cannot clear", &p))?;
                    } else {
                        std::fs::remove_file(&p).map_err(io("cannot clear", &p))?;
                    }
                }
                Vec::new()
            }
            Claim::Resume { generation, .. } => self.discard_generations_after(*generation)?,
        };
        let marker = format!("{{\"command\": {}}}\n", serde_json::json!(self.command));
        let path = self.path.join(MARKER_FILE);
        sepval_common::atomic_file::write_atomically(&path, marker.as_bytes()).map_err(|e| {
            OutDirError::Io {
                what: "cannot write",
                path: path.clone(),
                source: e.source,
            }
        })?;
        Ok(removed)
    }

    /// Removes the checkpoints of generations after `generation` (those of an abandoned
    /// continuation, when a run is resumed from an earlier generation) and returns them.
    fn discard_generations_after(&self, generation: usize) -> Result<Vec<PathBuf>, OutDirError> {
        let dir = self.path.join("generations");
        let Ok(entries) = std::fs::read_dir(&dir) else {
            return Ok(Vec::new());
        };
        let mut removed = Vec::new();
        for e in entries.filter_map(Result::ok) {
            let name = e.file_name().to_string_lossy().into_owned();
            let later = name
                .strip_prefix("gen-")
                .and_then(|n| n.strip_suffix(".json"))
                .and_then(|n| n.parse::<usize>().ok())
                .is_some_and(|g| g > generation);
            if later {
                std::fs::remove_file(e.path()).map_err(io("cannot remove", &e.path()))?;
                removed.push(e.path());
            }
        }
        removed.sort();
        Ok(removed)
    }
}

impl Drop for RunDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.lock);
        let untouched = entries(&self.path).is_ok_and(|e| e.is_empty());
        if self.created && untouched {
            let _ = std::fs::remove_file(self.path.join(MARKER_FILE));
            let _ = std::fs::remove_dir(&self.path);
        }
    }
}

/// The directory's entries other than the lock and the marker, sorted.
fn entries(path: &Path) -> Result<Vec<String>, OutDirError> {
    let mut out: Vec<String> = std::fs::read_dir(path)
        .map_err(io("cannot read", path))?
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != LOCK_FILE && n != MARKER_FILE)
        .collect();
    out.sort();
    Ok(out)
}

/// Whether process `pid` is alive.
fn alive(pid: u32) -> bool {
    // SAFETY: kill(2) with signal 0 only checks that the process exists.
    let r = unsafe { libc::kill(pid as libc::pid_t, 0) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
}

/// Creates the lock file holding our process id; takes over the lock of a process that is
/// gone.
fn take_lock(dir: &Path, lock: &Path) -> Result<(), OutDirError> {
    for _ in 0..2 {
        match OpenOptions::new().write(true).create_new(true).open(lock) {
            Ok(mut f) => {
                writeln!(f, "{}", std::process::id()).map_err(io("cannot write", lock))?;
                return Ok(());
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                // Read as any input (a FIFO or a huge file planted as the lock must not hang or
                // exhaust the run): a lock that cannot be read is a killed run's.
                let holder = sepval_common::input_file::read_string(lock, "lock file", 4096)
                    .ok()
                    .and_then(|t| t.trim().parse::<u32>().ok());
                match holder {
                    Some(pid) if alive(pid) => {
                        return Err(OutDirError::Locked {
                            path: dir.to_path_buf(),
                            pid,
                            lock: lock.to_path_buf(),
                        });
                    }
                    // A killed run's lock (or one being written): take it over.
                    _ => {
                        let _ = std::fs::remove_file(lock);
                    }
                }
            }
            Err(e) => return Err(io("cannot lock", lock)(e)),
        }
    }
    Err(OutDirError::Locked {
        path: dir.to_path_buf(),
        pid: 0,
        lock: lock.to_path_buf(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_directory_is_claimed_once_and_only_cleared_when_it_is_ours() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path().join("run");
        let first = RunDir::claim(&d, Claim::Fresh, "fit").unwrap();
        let e = RunDir::claim(&d, Claim::Overwrite, "fit").unwrap_err();
        assert!(
            e.to_string()
                .contains(&format!("in use by sepval process {}", std::process::id())),
            "{e}"
        );
        std::fs::write(d.join("result.json"), "{}").unwrap();
        drop(first);
        assert!(!d.join(LOCK_FILE).exists());
        let e = RunDir::claim(&d, Claim::Fresh, "fit").unwrap_err();
        assert!(
            e.to_string()
                .contains("is not empty (it holds result.json)"),
            "{e}"
        );
        // A claim refused later (an input, a worker) has cleared nothing: only prepare does.
        drop(RunDir::claim(&d, Claim::Overwrite, "fit").unwrap());
        assert!(d.join("result.json").exists() && !d.join(LOCK_FILE).exists());
        let again = RunDir::claim(&d, Claim::Overwrite, "fit").unwrap();
        assert!(d.join("result.json").exists() && !d.join(MARKER_FILE).exists());
        assert_eq!(again.prepare().unwrap(), Vec::<PathBuf>::new());
        assert!(!d.join("result.json").exists() && d.join(MARKER_FILE).exists());
        drop(again);
        // The marker alone makes a directory ours (a plan's holds no result.json).
        std::fs::write(d.join("plan.json"), "{}").unwrap();
        let marked = RunDir::claim(&d, Claim::Overwrite, "plan").unwrap();
        marked.prepare().unwrap();
        assert!(!d.join("plan.json").exists());
        drop(marked);
        // A directory sepval did not make is never cleared.
        let other = tmp.path().join("mine");
        std::fs::create_dir(&other).unwrap();
        std::fs::write(other.join("thesis.tex"), "x").unwrap();
        let e = RunDir::claim(&other, Claim::Overwrite, "fit").unwrap_err();
        assert!(e.to_string().starts_with("not clearing"), "{e}");
        assert!(other.join("thesis.tex").exists() && !other.join(LOCK_FILE).exists());
        // A killed run's lock is taken over.
        std::fs::write(d.join(LOCK_FILE), "999999999\n").unwrap();
        RunDir::claim(&d, Claim::Fresh, "fit").unwrap();
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
        drop(RunDir::claim(&d, claim(), "fit").unwrap());
        assert!(generations.join("gen-0004.json").exists() && !d.join(MARKER_FILE).exists());
        let resumed = RunDir::claim(&d, claim(), "fit").unwrap();
        assert_eq!(
            resumed.prepare().unwrap(),
            vec![
                generations.join("gen-0003.json"),
                generations.join("gen-0004.json")
            ]
        );
        assert!(generations.join("gen-0002.json").exists());
        assert!(!generations.join("gen-0003.json").exists() && d.join(MARKER_FILE).exists());
    }
}
