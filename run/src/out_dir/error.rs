//! Why a run cannot use a directory.

use std::path::{Path, PathBuf};

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
        "{path} is not empty (it holds {first}); give another directory{resume}, or clear it (--overwrite)"
    )]
    NotEmpty {
        /// The directory.
        path: PathBuf,
        /// One of its entries.
        first: String,
        /// How the command goes on with the run in it (", resume ..."), empty for a command
        /// that cannot.
        resume: String,
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
    /// The directory is, holds or lies inside one of the run's inputs.
    #[error(
        "{path} {relation} {input}, an input of this run; the output directory must lie outside every input (a run that cleared or wrote it would destroy what it reads): give another --out"
    )]
    IsInput {
        /// The directory.
        path: PathBuf,
        /// "is", "holds" or "lies inside".
        relation: &'static str,
        /// The input, as the flag that gives it and its path.
        input: String,
    },
    /// An output file that is one of the run's inputs.
    #[error(
        "{path} is {input}, an input of this run (writing it would destroy what the run reads): give another --out"
    )]
    FileIsInput {
        /// The output file.
        path: PathBuf,
        /// The input, as the flag that gives it and its path.
        input: String,
    },
    /// A directory to clear, or to resume a run in, holding entries sepval did not write.
    #[error("not {doing} {path}: {why}{hint}")]
    NotOurs {
        /// "clearing" or "resuming in".
        doing: &'static str,
        /// The directory.
        path: PathBuf,
        /// What in it is not sepval's.
        why: String,
        /// What to do (empty when clearing: the message says enough).
        hint: &'static str,
    },
    /// A resumed run that would remove the checkpoint it resumes from: a checkpoint of an
    /// earlier generation under a later generation's name in the run directory.
    #[error(
        "not resuming in {path}: --resume {checkpoint} holds generation {generation} but lies where the run keeps a later generation, which a resumed run removes (its continuation is replaced) or writes over; copy it to its own name (gen-{generation:04}.json) or resume into another --out"
    )]
    WouldRemoveCheckpoint {
        /// The directory.
        path: PathBuf,
        /// The checkpoint.
        checkpoint: PathBuf,
        /// Its generation.
        generation: usize,
    },
    /// A directory to clear whose marker lists no files (an older sepval's, or a killed run's).
    #[error(
        "not clearing {path}: {why}, so what the run wrote cannot be told from what was added since; look at what it holds and remove it by hand (rm -r {path}), or give another --out"
    )]
    Unlisted {
        /// The directory.
        path: PathBuf,
        /// Why its marker lists no files.
        why: String,
    },
    /// A directory an `--overwrite` run was killed in (`replaced`): where the earlier run is,
    /// and how to go on or put it back.
    #[error("{message}")]
    Interrupted {
        /// The directory.
        path: PathBuf,
        /// What happened, what to do, and how to put the earlier run back.
        message: String,
    },
    /// An `--out` that is a symbolic link to nothing.
    #[error(
        "{path} is a symbolic link to {target}, which does not exist (a dangling link): sepval will not write through it; remove the link, or give another --out"
    )]
    DanglingLink {
        /// The link.
        path: PathBuf,
        /// What it points to.
        target: PathBuf,
    },
    /// An `--out` that is a symbolic link that never resolves.
    #[error(
        "{path} is a symbolic link that never resolves (a link loop): sepval will not write through it; remove the link, or give another --out"
    )]
    LinkLoop {
        /// The link.
        path: PathBuf,
    },
    /// An output file that is a directory.
    #[error("{path} is a directory: give the name of the file to write (in it, or anywhere)")]
    FileIsDirectory {
        /// The output.
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

/// The file system's refusal to do `what` to `path`.
pub(super) fn io(what: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> OutDirError {
    let path = path.to_path_buf();
    move |source| OutDirError::Io { what, path, source }
}
