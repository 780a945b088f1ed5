//! An interrupted sweep's record, so that `sepval envelope --resume` goes on from it:
//! DIR/sweep/progress.json holds the rows done, rewritten atomically after each condition, and
//! the SHA-256 of the sweep's inputs (the source's records, the geometry files, the axes and
//! the settings: [`inputs_digest`]), so that a resume with other inputs is refused rather than
//! mixing two envelopes; each input's own digest (a file) or value (a setting) is kept beside
//! it ([`Progress::inputs`]), so that the refusal names the inputs that differ. A resumed sweep predicts only the conditions not done; each row is a
//! pure function of the inputs and its condition, so the envelope is the same bits as an
//! uninterrupted one. The file is removed once the outputs are written.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use sepval_common::scenario::hex_sha256;
use sepval_core::atomic_file::{WriteError, write_atomically};
use sepval_core::input_file::{InputFileError, read_string};
use sepval_core::limits::MAX_JSON_BYTES;

use sepval_run::out_dir::Claim;

use crate::row::Row;

/// The format of the progress file.
pub const PROGRESS_FORMAT: &str = "sepval-envelope-progress/1";

/// The progress file of the sweep in `out`.
pub fn progress_path(out: &Path) -> PathBuf {
    out.join("sweep").join("progress.json")
}

/// Removes the progress of the sweep in `out` (its file and its directory when empty) once
/// the envelope is written: a finished sweep has nothing to resume. What cannot be removed is
/// left as it is (the envelope is written already).
pub fn remove_progress(out: &Path) {
    let file = progress_path(out);
    let _ = std::fs::remove_file(&file);
    if let Some(dir) = file.parent() {
        let _ = std::fs::remove_dir(dir);
    }
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
        "{}: it records a sweep of other inputs ({differs}): give the same inputs to --resume, or run without --resume into a new --out",
        path.display()
    )]
    OtherInputs {
        /// The file.
        path: PathBuf,
        /// What differs, in words.
        differs: String,
    },
    /// Cannot be written.
    #[error("cannot write {}", .0.path.display())]
    Write(#[from] WriteError),
    /// `--resume` into a directory that holds no interrupted sweep.
    #[error(
        "--resume: {} {}",
        out.display(),
        if *finished {
            "holds a finished sweep (envelope.json is written and no sweep/progress.json is left): there is nothing to resume; run without --resume into a new --out, or with --overwrite to sweep it again"
        } else {
            "holds no interrupted sweep (no sweep/progress.json): run without --resume"
        }
    )]
    NothingToResume {
        /// The output directory.
        out: PathBuf,
        /// Whether it holds a finished sweep.
        finished: bool,
    },
    /// `--resume` with a progress file that cannot be gone on with.
    #[error("--resume: the sweep in {} (run without --resume to start anew)", out.display())]
    Resume {
        /// The output directory.
        out: PathBuf,
        /// Why.
        #[source]
        source: Box<ProgressError>,
    },
}

/// How a sweep into `out` claims it and what it starts from: with `resume`, the interrupted
/// sweep's progress, which must record the same inputs as `fresh` (the claim names the
/// progress file as what it resumes); else `fresh`, the directory cleared with `overwrite`
/// or new. The third value is the hint a refused claim gives when `out` holds an interrupted
/// sweep.
pub fn claim_sweep(
    out: &Path,
    resume: bool,
    overwrite: bool,
    fresh: Progress,
) -> Result<(Claim, Progress, Option<String>), ProgressError> {
    let file = progress_path(out);
    let hint = file
        .is_file()
        .then(|| "go on with its interrupted sweep (--resume)".to_string());
    if !resume {
        let claim = if overwrite {
            Claim::Overwrite
        } else {
            Claim::Fresh
        };
        return Ok((claim, fresh, hint));
    }
    if !file.exists() {
        return Err(ProgressError::NothingToResume {
            out: out.to_path_buf(),
            finished: out.join("envelope.json").is_file(),
        });
    }
    let progress = Progress::read(&file, &fresh).map_err(|e| ProgressError::Resume {
        out: out.to_path_buf(),
        source: Box::new(e),
    })?;
    let claim = Claim::Resume {
        checkpoint: file,
        generation: 0,
    };
    Ok((claim, progress, hint))
}

/// The rows done so far.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    /// [`PROGRESS_FORMAT`].
    pub format: String,
    /// The inputs' digest.
    pub inputs_sha256: String,
    /// Each input by name: a file's SHA-256 (`the --aircraft file`), a setting's value
    /// (`--samples`), so that a resume with other inputs names them (empty in files written
    /// before it was recorded).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub inputs: BTreeMap<String, String>,
    /// Conditions of the grid.
    pub conditions: usize,
    /// Rows done, in the order they were done.
    pub rows: Vec<Row>,
}

impl Progress {
    /// A sweep not started, of the inputs `inputs` (each by name) whose digest is
    /// `inputs_sha256`.
    pub fn new(
        inputs_sha256: String,
        inputs: BTreeMap<String, String>,
        conditions: usize,
    ) -> Progress {
        Progress {
            format: PROGRESS_FORMAT.into(),
            inputs_sha256,
            inputs,
            conditions,
            rows: Vec::new(),
        }
    }

    /// Reads `path`, which must record a sweep of the same inputs as `given` (a sweep not
    /// started: its digest, its inputs by name and its conditions).
    pub fn read(path: &Path, given: &Progress) -> Result<Progress, ProgressError> {
        let (inputs_sha256, conditions) = (&given.inputs_sha256, given.conditions);
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
        if &p.inputs_sha256 != inputs_sha256 || p.conditions != conditions {
            return Err(ProgressError::OtherInputs {
                path: path.to_path_buf(),
                differs: differs(&p.inputs, &given.inputs),
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

/// The inputs that differ between a sweep's record `then` and those given `now`, in words.
fn differs(then: &BTreeMap<String, String>, now: &BTreeMap<String, String>) -> String {
    if then.is_empty() {
        return "the source, the geometry, the axes or the settings differ; the file is of an earlier sepval, which did not record which".into();
    }
    let names: std::collections::BTreeSet<&String> = then.keys().chain(now.keys()).collect();
    let words: Vec<String> = names
        .into_iter()
        .filter(|n| then.get(*n) != now.get(*n))
        .map(|n| {
            let (a, b) = (then.get(n), now.get(n));
            if n.starts_with("--") {
                let v = |x: Option<&String>| x.map_or("not given".to_string(), |s| s.clone());
                format!("{n} was {}, now {}", v(a), v(b))
            } else {
                match (a, b) {
                    (Some(_), Some(_)) => format!("{n}: its content differs"),
                    (Some(_), None) => format!("{n}: not given now"),
                    _ => format!("{n}: not given then"),
                }
            }
        })
        .collect();
    if words.is_empty() {
        "the grid differs".into()
    } else {
        words.join("; ")
    }
}

/// What decides an envelope, as its progress file records it: the source's records, the
/// geometry files, the extension, the held-out files named, the axes and the settings.
#[derive(Debug, Clone)]
pub struct SweepInputs<'a> {
    /// The source directory (`--from`): its result.json or diagnosis.json.
    pub from: &'a Path,
    /// The aircraft's geometry file.
    pub aircraft: &'a Path,
    /// The store's shape file, when one is given.
    pub store_shape: Option<&'a Path>,
    /// The extension file, when one is given.
    pub extension: Option<&'a Path>,
    /// The releases held out, as named.
    pub validate: &'a [PathBuf],
    /// The axes swept: each one's flag and its `LO:HI:N` as typed.
    pub axes: Vec<(&'static str, String)>,
    /// Samples per condition.
    pub samples: usize,
    /// The seed of every draw.
    pub seed: u64,
    /// The clearance criterion \[mm\].
    pub clearance_mm: f64,
    /// Whether rows holding outliers are dropped.
    pub outliers_drop: bool,
}

/// An input of the sweep that cannot be read for its digest.
#[derive(Debug, thiserror::Error)]
#[error("cannot read {}", path.display())]
pub struct DigestError {
    /// The file.
    pub path: PathBuf,
    /// Why.
    #[source]
    pub source: std::io::Error,
}

impl SweepInputs<'_> {
    /// The digest of the inputs ([`inputs_digest`]) and each of them by name: a file's
    /// SHA-256, a setting's value ([`Progress::inputs`]).
    pub fn digest(&self) -> Result<(String, BTreeMap<String, String>), DigestError> {
        let read = |p: &Path| {
            std::fs::read(p).map_err(|source| DigestError {
                path: p.to_path_buf(),
                source,
            })
        };
        let mut parts: Vec<(String, Vec<u8>)> = Vec::new();
        let mut named = BTreeMap::new();
        let mut file = |label: &str, name: String, bytes: Vec<u8>| {
            named.insert(name, hex_sha256(&bytes));
            parts.push((label.into(), bytes));
        };
        for name in ["result.json", "diagnosis.json"] {
            let p = self.from.join(name);
            if p.is_file() {
                file(name, format!("the source's {name}"), read(&p)?);
            }
        }
        file(
            "aircraft",
            "the --aircraft file".into(),
            read(self.aircraft)?,
        );
        if let Some(p) = self.store_shape {
            file("store", "the --store-shape file".into(), read(p)?);
        }
        if let Some(p) = self.extension {
            file("extension", "the --extension file".into(), read(p)?);
        }
        let validate: Vec<String> = self
            .validate
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        let axes: Vec<String> = self
            .axes
            .iter()
            .map(|(flag, text)| format!("{flag}={text}"))
            .collect();
        let mut settings = format!(
            "samples={} seed={} clearance_mm={} validate={} axes={}",
            self.samples,
            self.seed,
            self.clearance_mm,
            validate.join(";"),
            axes.join(";")
        );
        if self.outliers_drop {
            // Only when given, so that the digest of an envelope without it stays as it was.
            settings.push_str(" outliers=drop");
        }
        parts.push(("settings".into(), settings.into_bytes()));
        named.insert("--samples".into(), self.samples.to_string());
        named.insert("--seed".into(), self.seed.to_string());
        named.insert("--clearance-mm".into(), self.clearance_mm.to_string());
        if !validate.is_empty() {
            named.insert("--validate".into(), validate.join(" "));
        }
        for (flag, text) in &self.axes {
            named.insert((*flag).into(), text.clone());
        }
        let refs: Vec<(&str, &[u8])> = parts
            .iter()
            .map(|(l, b)| (l.as_str(), b.as_slice()))
            .collect();
        Ok((inputs_digest(&refs), named))
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
        let named = |axes: &str| BTreeMap::from([("--mach".to_string(), axes.to_string())]);
        let given =
            |axes: &str| Progress::new(inputs_digest(&[("axes", axes.as_bytes())]), named(axes), 4);
        let mut p = given("0.6:0.9:4");
        p.rows.push(row(2));
        p.write(&path).unwrap();
        let back = Progress::read(&path, &given("0.6:0.9:4")).unwrap();
        assert!(back.done(2) && !back.done(0));
        assert_eq!(back.rows[0].p_fail.to_bits(), 1.0f64.to_bits());
        assert!(back.rows[0].clearance_p5_mm.is_nan(), "NaN reads back");
        let e = Progress::read(&path, &given("0.6:0.9:5"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("other inputs (--mach was 0.6:0.9:4, now 0.6:0.9:5)"),
            "{e}"
        );
        std::fs::write(&path, "{\"format\": 3}").unwrap();
        let e = Progress::read(&path, &given("0.6:0.9:4"))
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
