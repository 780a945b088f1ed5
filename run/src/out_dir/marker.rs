//! The marker of a run directory, `DIR/.sepval-run`: the command that made the directory and,
//! once its run has ended, the manifest of what the directory holds: every file with its
//! SHA-256 and every directory. `--overwrite` clears a directory only when everything in it is
//! in the manifest, each file unchanged; anything else (a file of another tool, a file edited
//! since, a marker of an older sepval or of a run killed before it ended, which list no files)
//! is refused, naming what is not sepval's.
//!
//! The manifest is written when the run ends, successful or not (a run refused or stopped by
//! Ctrl-C included; a run killed with SIGKILL leaves its marker without one): it lists the
//! directory as it is then. While the run holds the directory's lock no other sepval run
//! writes into it, and it started empty (or cleared, or resumed), so what it holds is what the
//! run wrote, a resumed fit's earlier generations included.

use std::collections::{BTreeMap, BTreeSet};
use std::io::Read;
use std::path::Path;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use super::REPLACED;
use super::error::{OutDirError, io};
use super::lock::LOCK_FILE;

/// The marker of a sepval output directory.
pub const MARKER_FILE: &str = ".sepval-run";

/// The format of the marker this sepval writes (an older one has no `format`).
const FORMAT: &str = "sepval-run/2";

/// At most this many entries are named in a refusal.
const NAMED: usize = 8;

/// The marker file's content.
#[derive(Debug, Serialize, Deserialize)]
struct Marker {
    /// [`FORMAT`]; absent in an older sepval's marker.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    format: Option<String>,
    /// The command that made the directory.
    command: String,
    /// Every file (path relative to the directory, `/`-separated) and its SHA-256 (hex), once
    /// the run has ended.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    files: Option<BTreeMap<String, String>>,
    /// Every directory, once the run has ended.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    directories: Option<BTreeSet<String>>,
}

/// Writes the marker of a run of `command` that has started: no manifest yet.
pub(super) fn write_started(dir: &Path, command: &str) -> Result<(), OutDirError> {
    write(
        dir,
        &Marker {
            format: Some(FORMAT.into()),
            command: command.into(),
            files: None,
            directories: None,
        },
    )
}

/// Writes the marker of a run of `command` that has ended: the manifest of `dir` as it is.
pub(super) fn write_ended(dir: &Path, command: &str) -> Result<(), OutDirError> {
    let mut files = BTreeMap::new();
    let mut directories = BTreeSet::new();
    for (name, kind) in walk(dir, &|_| true)? {
        match kind {
            Kind::File => {
                let path = dir.join(&name);
                files.insert(name, sha256(&path).map_err(io("cannot read", &path))?);
            }
            Kind::Directory => {
                directories.insert(name);
            }
            // Never written by a run: left out, so refused by a later --overwrite.
            Kind::Other(_) => {}
        }
    }
    write(
        dir,
        &Marker {
            format: Some(FORMAT.into()),
            command: command.into(),
            files: Some(files),
            directories: Some(directories),
        },
    )
}

fn write(dir: &Path, marker: &Marker) -> Result<(), OutDirError> {
    let path = dir.join(MARKER_FILE);
    let mut text = serde_json::to_string_pretty(marker).expect("a marker serialises");
    text.push('\n');
    sepval_core::atomic_file::write_atomically(&path, text.as_bytes()).map_err(|e| {
        OutDirError::Io {
            what: "cannot write",
            path: path.clone(),
            source: e.source,
        }
    })
}

/// The command of `dir`'s marker and whether it has a manifest (its run ended), when it is a
/// marker this sepval reads.
pub(super) fn command_of(dir: &Path) -> Option<(String, bool)> {
    let text = sepval_core::input_file::read_string(
        &dir.join(MARKER_FILE),
        "run marker",
        sepval_core::limits::MAX_JSON_BYTES,
    )
    .ok()?;
    let m: Marker = serde_json::from_str(&text).ok()?;
    let ended = m.files.is_some() && m.directories.is_some();
    Some((m.command, ended))
}

/// Whether `dir`, which holds `entries` besides its lock and marker, may be cleared: only when
/// its marker's manifest lists every one of them, each file unchanged.
pub(super) fn check_clearable(dir: &Path, entries: &[String]) -> Result<(), OutDirError> {
    check_ours(dir, entries, Use::Clear)
}

/// Whether a run may be resumed in `dir`, which holds `entries` besides its lock and marker:
/// only when it is a sepval run directory whose manifest lists every one of them, each file
/// unchanged, so that the resumed run neither removes nor writes over, nor lists as its own, a
/// file it did not write. A run killed before it ended (SIGKILL) left no manifest: its
/// directory is taken as it is, the one case a resumed run cannot check.
pub(super) fn check_resumable(dir: &Path, entries: &[String]) -> Result<(), OutDirError> {
    check_ours(dir, entries, Use::Resume)
}

/// What is done to a directory that must hold only what a sepval run wrote.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Use {
    Clear,
    Resume,
}

fn check_ours(dir: &Path, entries: &[String], to: Use) -> Result<(), OutDirError> {
    if entries.is_empty() {
        return Ok(());
    }
    let not_ours = |why: String| OutDirError::NotOurs {
        doing: match to {
            Use::Clear => "clearing",
            Use::Resume => "resuming in",
        },
        path: dir.to_path_buf(),
        why,
        hint: match to {
            Use::Clear => "",
            Use::Resume => {
                "; move what its run did not write out of it, or resume into another (empty) --out"
            }
        },
    };
    let path = dir.join(MARKER_FILE);
    if std::fs::symlink_metadata(&path).is_err() {
        return Err(not_ours(format!(
            "it is not a sepval output directory (it has no {MARKER_FILE}; it holds {})",
            named(entries.iter().cloned())
        )));
    }
    let marker: Marker = sepval_core::input_file::read_string(
        &path,
        "run marker",
        sepval_core::limits::MAX_JSON_BYTES,
    )
    .map_err(|e| e.to_string())
    .and_then(|t| serde_json::from_str(&t).map_err(|e| e.to_string()))
    .map_err(|e| not_ours(format!("its {MARKER_FILE} is not one sepval writes ({e})")))?;
    let unlisted = |why: String| OutDirError::Unlisted {
        path: dir.to_path_buf(),
        why,
    };
    let (files, directories) = match (&marker.format, marker.files, marker.directories) {
        // No manifest to check against (an older sepval's marker, a killed run's): a resumed
        // run takes the directory as it is.
        (None, _, _) | (Some(_), None, _) | (Some(_), _, None)
            if to == Use::Resume && marker.format.as_deref().is_none_or(|f| f == FORMAT) =>
        {
            return Ok(());
        }
        (None, _, _) => {
            return Err(unlisted(format!(
                "its {MARKER_FILE} (of a run of `{}`) was written by an older sepval, which listed no files",
                marker.command
            )));
        }
        (Some(f), _, _) if f != FORMAT => {
            return Err(not_ours(format!(
                "its {MARKER_FILE} has format `{f}`, not {FORMAT}"
            )));
        }
        (Some(_), Some(files), Some(directories)) => (files, directories),
        (Some(_), _, _) => {
            return Err(unlisted(format!(
                "its run of `{}` never ended (it was killed), so its {MARKER_FILE} lists no files",
                marker.command
            )));
        }
    };
    let mut foreign = Vec::new();
    for (name, kind) in walk(dir, &|d| directories.contains(d))? {
        let why = match (kind, files.get(&name)) {
            (Kind::Directory, _) if directories.contains(&name) => continue,
            (Kind::File, Some(sum)) => match sha256(&dir.join(&name)) {
                Ok(s) if &s == sum => continue,
                Ok(_) => "changed since",
                Err(_) => "unreadable",
            },
            (Kind::Other(what), _) => what,
            _ => "not written by it",
        };
        foreign.push(format!("{name} ({why})"));
    }
    if foreign.is_empty() {
        return Ok(());
    }
    Err(not_ours(format!(
        "it holds what its run of `{}` did not write: {}",
        marker.command,
        named(foreign.into_iter())
    )))
}

/// At most [`NAMED`] of `items`, then how many more.
fn named(items: impl ExactSizeIterator<Item = String>) -> String {
    let n = items.len();
    let mut shown: Vec<String> = items.take(NAMED).collect();
    if n > NAMED {
        shown.push(format!("and {} more", n - NAMED));
    }
    shown.join(", ")
}

/// What an entry of a run directory is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    File,
    Directory,
    /// Something a run never writes (a symbolic link, a FIFO, a socket, a device), in words.
    Other(&'static str),
}

/// Every entry under `dir` (its lock and marker aside), as paths relative to it
/// (`/`-separated) in order, descending into the directories `descend` accepts; symbolic links
/// are never followed.
fn walk(dir: &Path, descend: &dyn Fn(&str) -> bool) -> Result<Vec<(String, Kind)>, OutDirError> {
    let mut out = Vec::new();
    let mut stack = vec![String::new()];
    while let Some(rel) = stack.pop() {
        let here = if rel.is_empty() {
            dir.to_path_buf()
        } else {
            dir.join(&rel)
        };
        let mut names: Vec<(String, std::fs::FileType)> = std::fs::read_dir(&here)
            .map_err(io("cannot read", &here))?
            .filter_map(Result::ok)
            .filter_map(|e| {
                Some((
                    e.file_name().to_string_lossy().into_owned(),
                    e.file_type().ok()?,
                ))
            })
            .collect();
        names.sort_by(|a, b| a.0.cmp(&b.0));
        for (name, ty) in names {
            if rel.is_empty() && (name == LOCK_FILE || name == MARKER_FILE || name == REPLACED) {
                continue;
            }
            let path = if rel.is_empty() {
                name
            } else {
                format!("{rel}/{name}")
            };
            let kind = if ty.is_symlink() {
                Kind::Other("a symbolic link")
            } else if ty.is_dir() {
                Kind::Directory
            } else if ty.is_file() {
                Kind::File
            } else {
                Kind::Other("not a regular file")
            };
            if kind == Kind::Directory && descend(&path) {
                stack.push(path.clone());
            }
            out.push((path, kind));
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(out)
}

/// The SHA-256 (hex) of the regular file `path`, read without blocking.
fn sha256(path: &Path) -> std::io::Result<String> {
    // No limit on what a run wrote (the reader's limit plus one must not overflow).
    const UNLIMITED: u64 = i64::MAX as u64;
    let mut file = sepval_core::input_file::InputFile::open(path, "run output", UNLIMITED)
        .map_err(std::io::Error::other)?;
    let mut h = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = file.read(&mut buf)?;
        if n == 0 {
            break;
        }
        h.update(&buf[..n]);
    }
    Ok(h.finalize().iter().map(|b| format!("{b:02x}")).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(dir: &Path) -> Vec<String> {
        walk(dir, &|_| false)
            .unwrap()
            .into_iter()
            .map(|(n, _)| n)
            .collect()
    }

    #[test]
    fn only_what_the_manifest_lists_unchanged_is_clearable() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        std::fs::create_dir_all(d.join("figures")).unwrap();
        std::fs::create_dir_all(d.join("empty")).unwrap();
        std::fs::write(d.join("result.json"), "{}").unwrap();
        std::fs::write(d.join("figures/a.png"), "png").unwrap();
        let clearable = |d: &Path| check_clearable(d, &entries(d)).map_err(|e| e.to_string());
        let e = clearable(d).unwrap_err();
        assert!(e.contains("it is not a sepval output directory (it has no .sepval-run; it holds empty, figures, result.json)"), "{e}");
        write_started(d, "fit").unwrap();
        let e = clearable(d).unwrap_err();
        assert!(
            e.contains("its run of `fit` never ended (it was killed)"),
            "{e}"
        );
        write_ended(d, "fit").unwrap();
        clearable(d).unwrap();
        let marker = std::fs::read_to_string(d.join(MARKER_FILE)).unwrap();
        // SHA-256 of `{}`.
        let sum = "44136fa355b3678a1146ad16f7e8649e94fb4fc21fe77e8310c060f61caaff8a";
        assert!(
            marker.contains(&format!("\"result.json\": \"{sum}\"")),
            "{marker}"
        );
        // A file added, a file edited, a link: each named.
        std::fs::write(d.join("figures/mine.png"), "x").unwrap();
        std::fs::write(d.join("result.json"), "{\"x\": 1}").unwrap();
        std::os::unix::fs::symlink(d.join("result.json"), d.join("empty/link")).unwrap();
        let e = clearable(d).unwrap_err();
        assert!(
            e.ends_with(
                "it holds what its run of `fit` did not write: empty/link (a symbolic link), figures/mine.png (not written by it), result.json (changed since)"
            ),
            "{e}"
        );
        // An older sepval's marker lists no files.
        std::fs::write(d.join(MARKER_FILE), "{\"command\": \"plan\"}\n").unwrap();
        let e = clearable(d).unwrap_err();
        assert!(
            e.contains("written by an older sepval, which listed no files"),
            "{e}"
        );
        assert!(e.contains("remove it by hand (rm -r "), "{e}");
        std::fs::write(d.join(MARKER_FILE), "not json").unwrap();
        let e = clearable(d).unwrap_err();
        assert!(e.contains("is not one sepval writes"), "{e}");
    }
}
