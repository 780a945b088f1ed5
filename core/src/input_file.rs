//! One way to read an input file: only a regular file is opened, and it is read with a byte
//! limit checked against its size before anything is allocated and again while reading.
//!
//! Why (issue 21, items 1 and 2): a path given by a user may name `/dev/zero` (read until the
//! machine runs out of memory), a FIFO with no writer (a blocking `open` waits for good and
//! ignores SIGINT), a directory or a socket. Each reader of outside input in this crate
//! (telemetry, table CSV, scenario and extension TOML) and the binaries' readers call
//! [`read_bytes`], [`read_string`] or, to stream, [`InputFile::open`].
//!
//! How:
//! - The path's metadata (following symbolic links) must be a regular file; the file is then
//!   opened with `O_NONBLOCK` (open(2): a FIFO opened for reading that way returns at once
//!   instead of waiting for a writer; it has no effect on a regular file) and its handle's
//!   metadata (fstat(2)) checked again, so a path swapped between the two checks is refused too.
//! - The size from that fstat is compared with the limit before a buffer is reserved, and the
//!   read itself stops one byte past the limit, so a file that grows while it is read is
//!   refused as well.
//!
//! The limits, one per kind of file, are in [`crate::limits`].

use std::fs::{File, FileType};
use std::io::Read;
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

/// An input file that cannot be used. Every variant names the file and what it was read as
/// (`label`, e.g. "table" or "telemetry file").
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum InputFileError {
    /// The path cannot be opened (it does not exist, no permission, ...).
    #[error("{path}: cannot read {label}")]
    Open {
        /// The file.
        path: PathBuf,
        /// What it was read as.
        label: &'static str,
        /// Why.
        source: std::io::Error,
    },
    /// The path is not a regular file.
    #[error(
        "{path}: the {label} is {kind}, not a regular file: sepval reads a {label} from a regular file only (copy the content to a file and give its path)"
    )]
    NotRegular {
        /// The file.
        path: PathBuf,
        /// What it was read as.
        label: &'static str,
        /// What it is instead ("a directory", "a FIFO (named pipe)", ...).
        kind: &'static str,
    },
    /// The file is larger than the limit for its kind (or grew beyond it while read).
    #[error(
        "{path}: the {label} is {size_bytes} bytes{growing}, more than the limit of {limit_bytes} bytes for a {label} (sepval_core::limits): check that it is the intended file, or split it",
        growing = if *.grew { " or more (it grew while read)" } else { "" }
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// What it was read as.
        label: &'static str,
        /// Its size (or the bytes read when it grew) \[bytes\].
        size_bytes: u64,
        /// The limit \[bytes\].
        limit_bytes: u64,
        /// Whether it grew past the limit while read (its size was within it when opened).
        grew: bool,
    },
    /// Reading failed after the file was opened.
    #[error("{path}: cannot read {label}")]
    Read {
        /// The file.
        path: PathBuf,
        /// What it was read as.
        label: &'static str,
        /// Why.
        source: std::io::Error,
    },
    /// The file is not UTF-8 text ([`read_string`] only).
    #[error("{path}: the {label} is not UTF-8 text (byte {offset})")]
    NotText {
        /// The file.
        path: PathBuf,
        /// What it was read as.
        label: &'static str,
        /// The offset of the first byte that is not UTF-8.
        offset: usize,
    },
}

/// Two errors are equal when they are of one kind and say the same (an I/O error has no
/// equality of its own), so that the readers' errors that carry one keep theirs.
impl PartialEq for InputFileError {
    fn eq(&self, other: &Self) -> bool {
        std::mem::discriminant(self) == std::mem::discriminant(other)
            && chain_text(self) == chain_text(other)
    }
}

/// The error and its causes' text.
fn chain_text(e: &dyn std::error::Error) -> Vec<String> {
    std::iter::successors(Some(e), |e| e.source())
        .map(|e| e.to_string())
        .collect()
}

impl InputFileError {
    /// The I/O error of an [`InputFileError::Open`] or [`InputFileError::Read`] (so that a
    /// reader can keep its own message for a file that is missing or unreadable), or the error
    /// itself otherwise.
    pub fn into_io(self) -> Result<std::io::Error, InputFileError> {
        match self {
            InputFileError::Open { source, .. } | InputFileError::Read { source, .. } => Ok(source),
            other => Err(other),
        }
    }

    /// The input-file error carried by an I/O error of [`InputFile`]'s `Read` (a file that grew
    /// past its limit while streamed), if it is one.
    pub fn from_io(e: &std::io::Error) -> Option<&InputFileError> {
        e.get_ref()?.downcast_ref::<InputFileError>()
    }
}

/// What a file type is, for [`InputFileError::NotRegular`]; `None` for a regular file.
fn irregular(t: FileType) -> Option<&'static str> {
    if t.is_file() {
        None
    } else if t.is_dir() {
        Some("a directory")
    } else if t.is_fifo() {
        Some("a FIFO (named pipe)")
    } else if t.is_socket() {
        Some("a socket")
    } else if t.is_char_device() {
        Some("a character device")
    } else if t.is_block_device() {
        Some("a block device")
    } else {
        Some("not a file")
    }
}

/// An open regular input file whose reads stop at a byte limit (a read beyond it is an error
/// carrying [`InputFileError::TooLarge`]).
#[derive(Debug)]
pub struct InputFile {
    file: File,
    path: PathBuf,
    label: &'static str,
    limit_bytes: u64,
    size_bytes: u64,
    read_bytes: u64,
}

impl InputFile {
    /// Opens `path` as a `label` of at most `limit_bytes` bytes: refused unless it is a regular
    /// file within the limit. Never blocks (a FIFO with no writer is refused at once).
    pub fn open(
        path: &Path,
        label: &'static str,
        limit_bytes: u64,
    ) -> Result<Self, InputFileError> {
        let open_error = |source| InputFileError::Open {
            path: path.to_path_buf(),
            label,
            source,
        };
        let not_regular = |kind| InputFileError::NotRegular {
            path: path.to_path_buf(),
            label,
            kind,
        };
        // A socket cannot be opened at all (ENXIO): its metadata says what it is.
        let before = std::fs::metadata(path).map_err(open_error)?;
        if let Some(kind) = irregular(before.file_type()) {
            return Err(not_regular(kind));
        }
        let file = std::fs::OpenOptions::new()
            .read(true)
            .custom_flags(libc::O_NONBLOCK)
            .open(path)
            .map_err(open_error)?;
        let meta = file.metadata().map_err(open_error)?;
        if let Some(kind) = irregular(meta.file_type()) {
            return Err(not_regular(kind));
        }
        if meta.len() > limit_bytes {
            return Err(InputFileError::TooLarge {
                path: path.to_path_buf(),
                label,
                size_bytes: meta.len(),
                limit_bytes,
                grew: false,
            });
        }
        Ok(InputFile {
            file,
            path: path.to_path_buf(),
            label,
            limit_bytes,
            size_bytes: meta.len(),
            read_bytes: 0,
        })
    }

    /// Its size when it was opened \[bytes\] (within the limit).
    pub fn size_bytes(&self) -> u64 {
        self.size_bytes
    }

    /// The whole content: a buffer of the size found at opening, and an error if the file grew
    /// past the limit.
    pub fn read_all(mut self) -> Result<Vec<u8>, InputFileError> {
        // The size is within the limit (checked when opened), so this reservation is bounded.
        let mut bytes = Vec::with_capacity(usize::try_from(self.size_bytes).unwrap_or(0));
        self.read_to_end(&mut bytes)
            .map_err(|e| self.read_error(e))?;
        Ok(bytes)
    }

    /// A read error as an [`InputFileError`] (the limit's own error unwrapped).
    fn read_error(&self, e: std::io::Error) -> InputFileError {
        if InputFileError::from_io(&e).is_some() {
            let inner = e.into_inner().expect("checked: it carries an error");
            return *inner
                .downcast::<InputFileError>()
                .expect("checked: it is an InputFileError");
        }
        InputFileError::Read {
            path: self.path.clone(),
            label: self.label,
            source: e,
        }
    }
}

impl Read for InputFile {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        // At most one byte past the limit, which is the evidence that the file grew.
        let room = (self.limit_bytes + 1).saturating_sub(self.read_bytes);
        let take = buf.len().min(usize::try_from(room).unwrap_or(usize::MAX));
        let n = self.file.read(&mut buf[..take])?;
        self.read_bytes += n as u64;
        if self.read_bytes > self.limit_bytes {
            return Err(std::io::Error::new(
                std::io::ErrorKind::FileTooLarge,
                InputFileError::TooLarge {
                    path: self.path.clone(),
                    label: self.label,
                    size_bytes: self.read_bytes,
                    limit_bytes: self.limit_bytes,
                    grew: true,
                },
            ));
        }
        Ok(n)
    }
}

/// The bytes of the regular file `path`, read as a `label` of at most `limit_bytes` bytes
/// (one of the limits of [`crate::limits`]).
pub fn read_bytes(
    path: &Path,
    label: &'static str,
    limit_bytes: u64,
) -> Result<Vec<u8>, InputFileError> {
    InputFile::open(path, label, limit_bytes)?.read_all()
}

/// The text of the regular file `path` (UTF-8), read as a `label` of at most `limit_bytes`
/// bytes (one of the limits of [`crate::limits`]).
pub fn read_string(
    path: &Path,
    label: &'static str,
    limit_bytes: u64,
) -> Result<String, InputFileError> {
    String::from_utf8(read_bytes(path, label, limit_bytes)?).map_err(|e| InputFileError::NotText {
        path: path.to_path_buf(),
        label,
        offset: e.utf8_error().valid_up_to(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_regular_file_within_its_limit_reads_whole() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        std::fs::write(&p, "hello").unwrap();
        assert_eq!(read_string(&p, "test file", 5).unwrap(), "hello");
        let e = read_string(&p, "test file", 4).unwrap_err().to_string();
        assert_eq!(
            e,
            format!(
                "{}: the test file is 5 bytes, more than the limit of 4 bytes for a test file (sepval_core::limits): check that it is the intended file, or split it",
                p.display()
            )
        );
    }

    #[test]
    fn a_directory_and_a_device_are_refused_by_kind() {
        let dir = tempfile::tempdir().unwrap();
        let e = read_bytes(dir.path(), "table", 10).unwrap_err().to_string();
        assert!(e.ends_with(": the table is a directory, not a regular file: sepval reads a table from a regular file only (copy the content to a file and give its path)"), "{e}");
        let e = read_bytes(Path::new("/dev/zero"), "table", 10)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("/dev/zero: the table is a character device,"),
            "{e}"
        );
    }

    #[test]
    fn text_that_is_not_utf8_names_its_first_bad_byte() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("b.txt");
        std::fs::write(&p, b"ab\xffcd").unwrap();
        let e = read_string(&p, "scenario", 100).unwrap_err().to_string();
        assert_eq!(
            e,
            format!("{}: the scenario is not UTF-8 text (byte 2)", p.display())
        );
    }

    #[test]
    fn a_stream_stops_one_byte_past_its_limit() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("c.txt");
        std::fs::write(&p, "0123456789").unwrap();
        let mut f = InputFile::open(&p, "telemetry file", 10).unwrap();
        // The limit as if the file had grown after it was opened.
        f.limit_bytes = 6;
        let mut out = Vec::new();
        let e = f.read_to_end(&mut out).unwrap_err();
        let inner = InputFileError::from_io(&e).unwrap().to_string();
        assert!(
            inner.contains(
                "is 7 bytes or more (it grew while read), more than the limit of 6 bytes"
            ),
            "{inner}"
        );
        assert_eq!(f.read_bytes, 7);
    }
}
