//! An interrupted sweep's record, so that `sepval envelope --resume` goes on from it:
//! DIR/sweep/progress.json holds the rows done, rewritten atomically after each condition, and
//! the SHA-256 of the sweep's inputs (the source's records, the geometry files, the axes and
//! the settings: [`inputs_digest`]), so that a resume with other inputs is refused rather than
//! mixing two envelopes. A resumed sweep predicts only the conditions not done; each row is a
//! pure function of the inputs and its condition, so the envelope is the same bits as an
//! uninterrupted one. The file is removed once the outputs are written.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use sepval_common::atomic_file::{WriteError, write_atomically};
use sepval_common::input_file::{InputFileError, read_string};
use sepval_common::limits::MAX_JSON_BYTES;

use crate::row::Row;

/// The format of the progress file.
pub const PROGRESS_FORMAT: &str = "sepval-envelope-progress/1";

/// The progress file of the sweep in `out`.
pub fn progress_path(out: &Path) -> PathBuf {
    out.join("sweep").join("progress.json")
}

/// A progress file that cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ProgressError {
    /// Unreadable.
    #[error(transparent)]
    Read(#[from] InputFileError),
    /// Not a progress file.
    #[error("{}: not a sepval envelope progress file ({message})", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Of another sweep.
    #[error(
        "{}: it records a sweep of other inputs (the source, the geometry, the axes or the settings differ): run without --resume into a new --out",
        path.display()
    )]
    OtherInputs {
        /// The file.
        path: PathBuf,
    },
    /// Cannot be written.
    #[error("cannot write {}", .0.path.display())]
    Write(#[from] WriteError),
}

/// The rows done so far.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    /// [`PROGRESS_FORMAT`].
    pub format: String,
    /// The inputs' digest.
    pub inputs_sha256: String,
    /// Conditions of the grid.
    pub conditions: usize,
    /// Rows done, in the order they were done.
    pub rows: Vec<Row>,
}

impl Progress {
    /// A sweep not started.
    pub fn new(inputs_sha256: String, conditions: usize) -> Progress {
        Progress {
            format: PROGRESS_FORMAT.into(),
            inputs_sha256,
            conditions,
            rows: Vec::new(),
        }
    }

    /// Reads `path`, which must record a sweep of `inputs_sha256` over `conditions`.
    pub fn read(
        path: &Path,
        inputs_sha256: &str,
        conditions: usize,
    ) -> Result<Progress, ProgressError> {
        let text = read_string(path, "envelope progress file", MAX_JSON_BYTES)?;
        let format = |message: String| ProgressError::Format {
            path: path.to_path_buf(),
            message,
        };
        let p: Progress = serde_json::from_str(&text).map_err(|e| format(e.to_string()))?;
        if p.format != PROGRESS_FORMAT {
            return Err(format(format!(
                "format `{}`, expected `{PROGRESS_FORMAT}`",
                p.format
            )));
        }
        if p.inputs_sha256 != inputs_sha256 || p.conditions != conditions {
            return Err(ProgressError::OtherInputs {
                path: path.to_path_buf(),
            });
        }
        if let Some(r) = p.rows.iter().find(|r| r.index >= conditions) {
            return Err(format(format!(
                "a row of condition {} of a grid of {conditions}",
                r.index
            )));
        }
        Ok(p)
    }

    /// Whether condition `k` is done.
    pub fn done(&self, k: usize) -> bool {
        self.rows.iter().any(|r| r.index == k)
    }

    /// Writes it to `path` atomically (its directory created).
    pub fn write(&self, path: &Path) -> Result<(), ProgressError> {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|source| WriteError {
                path: dir.to_path_buf(),
                source,
            })?;
        }
        let json = serde_json::to_string(self).expect("a progress record serialises") + "\n";
        write_atomically(path, json.as_bytes())?;
        Ok(())
    }
}

/// The SHA-256 (hex) of the sweep's inputs: `parts` in order, each a label and its bytes
/// (length-prefixed, so no two lists of parts give the same stream).
pub fn inputs_digest(parts: &[(&str, &[u8])]) -> String {
    let mut h = Sha256::new();
    for (label, bytes) in parts {
        for b in [label.as_bytes(), *bytes] {
            h.update((b.len() as u64).to_le_bytes());
            h.update(b);
        }
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use sepval_predict::record::ConditionRecord;

    fn row(index: usize) -> Row {
        let c = ConditionRecord {
            mach: 0.8,
            altitude_m: 1000.0,
            alpha_deg: 0.0,
            beta_deg: 0.0,
            gamma_deg: 0.0,
        };
        Row::all_diverged(index, c)
    }

    #[test]
    fn a_progress_file_reads_back_and_refuses_other_inputs() {
        let dir = tempfile::tempdir().unwrap();
        let path = progress_path(dir.path());
        let mut p = Progress::new(inputs_digest(&[("axes", b"0.6:0.9:4")]), 4);
        p.rows.push(row(2));
        p.write(&path).unwrap();
        let back = Progress::read(&path, &p.inputs_sha256, 4).unwrap();
        assert!(back.done(2) && !back.done(0));
        assert_eq!(back.rows[0].p_fail.to_bits(), 1.0f64.to_bits());
        assert!(back.rows[0].clearance_p5_mm.is_nan(), "NaN reads back");
        let other = inputs_digest(&[("axes", b"0.6:0.9:5")]);
        let e = Progress::read(&path, &other, 4).unwrap_err().to_string();
        assert!(e.contains("other inputs"), "{e}");
        std::fs::write(&path, "{\"format\": 3}").unwrap();
        let e = Progress::read(&path, &p.inputs_sha256, 4)
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a sepval envelope progress file"), "{e}");
    }

    #[test]
    fn the_digest_depends_on_every_part_and_its_boundaries() {
        let a = inputs_digest(&[("a", b"xy"), ("b", b"z")]);
        assert_ne!(a, inputs_digest(&[("a", b"x"), ("b", b"yz")]));
        assert_eq!(a, inputs_digest(&[("a", b"xy"), ("b", b"z")]));
    }
}
