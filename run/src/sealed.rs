//! The records one command writes and another reads (DIR/result.json of `sepval fit`,
//! DIR/diagnosis.json of `sepval diagnose`): one writer that seals a record with a digest of
//! its content, and one reader that every such record goes through, which refuses, naming what
//! is wrong and where:
//!
//! - a file that is not JSON (empty, truncated, `NaN`, not text): the parse error with its line
//!   and column;
//! - a `format` other than the one this sepval writes (or none);
//! - content that does not match its digest (an edit, by hand or by accident);
//! - a field that does not fit the type read (the field and its line and column);
//! - a value outside its stated range ([`Record::check`]: the field, its value and the range).
//!
//! # Digest
//!
//! As a fit's checkpoints carry one (`sepval_fit::checkpoint`), a record carries `digest`: the SHA-256
//! (lower-case hex) of its *canonical form*, the compact JSON (`serde_json::to_vec`) of the
//! record's JSON value with the top-level `digest` key left out. The value's object keys are in
//! serde_json's map order (sorted), and numbers are spelled in serde_json's shortest form that
//! reads back exactly, so what does not change a value does not matter (whitespace, key order,
//! `0.5` against `5e-1`), and every change of a value is refused, as is a key added or
//! removed. The digest detects edits; it is not a signature: who knows this rule can write a
//! matching digest for edited content, which must still meet the ranges of [`Record::check`].
//!
//! A record without `digest` (one written before sepval recorded it, or one whose digest was
//! deleted) is refused as well, saying so: accepting it would let any edit pass by removing
//! the digest. Such a record is made again by running its command again with this sepval.

use std::path::{Path, PathBuf};

use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::Value;

use sepval_common::scenario::hex_sha256;
use sepval_core::atomic_file::{WriteError, write_atomically};
use sepval_core::input_file::{InputFileError, read_string};
use sepval_core::limits::MAX_JSON_BYTES;

/// The key of the digest in a record.
pub const DIGEST_KEY: &str = "digest";

/// A record that cannot be read or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RecordError {
    /// Missing, not a regular file, over the size limit, not UTF-8.
    #[error(transparent)]
    Read(#[from] InputFileError),
    /// Not JSON.
    #[error("{}: line {line}, column {column}: not JSON: {message}", path.display())]
    NotJson {
        /// The file.
        path: PathBuf,
        /// Where (1-based).
        line: usize,
        /// Where (1-based).
        column: usize,
        /// The parser's words.
        message: String,
    },
    /// JSON of another format (or of none).
    #[error(
        "{}: format {found}, expected {expected}: not a record this sepval writes (run `sepval {command}` again with this sepval)",
        path.display()
    )]
    Format {
        /// The file.
        path: PathBuf,
        /// The format found (`none` when it has none).
        found: String,
        /// The format this sepval writes.
        expected: &'static str,
        /// The command that writes it.
        command: &'static str,
    },
    /// No digest.
    #[error(
        "{}: records no digest of its content (`digest`): written by an earlier sepval or edited by hand; a record without one is not used (run `sepval {command}` again with this sepval)",
        path.display()
    )]
    NoDigest {
        /// The file.
        path: PathBuf,
        /// The command that writes it.
        command: &'static str,
    },
    /// Content that does not match its digest.
    #[error(
        "{}: its content does not match its digest: edited after `sepval {command}` wrote it? an edited record is not used (run `sepval {command}` again)",
        path.display()
    )]
    Edited {
        /// The file.
        path: PathBuf,
        /// The command that writes it.
        command: &'static str,
    },
    /// JSON that does not fit the record (a field missing or of another type).
    #[error("{}: line {line}, column {column}: {message}", path.display())]
    Shape {
        /// The file.
        path: PathBuf,
        /// Where (1-based).
        line: usize,
        /// Where (1-based).
        column: usize,
        /// The parser's words.
        message: String,
    },
    /// A value outside its range.
    #[error("{}: {field}", path.display())]
    Field {
        /// The file.
        path: PathBuf,
        /// The field, its value and its range.
        field: FieldError,
    },
    /// The record cannot be written.
    #[error(transparent)]
    Write(#[from] WriteError),
}

/// A field of a record outside its range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("`{field}` = {value}: expected {expected}")]
pub struct FieldError {
    /// Its path in the record (`rivals[2].delta_bic`).
    pub field: String,
    /// Its value, as read.
    pub value: String,
    /// Its range in words.
    pub expected: String,
}

/// A record one command writes and others read.
pub trait Record: Serialize + DeserializeOwned {
    /// Its `format`.
    const FORMAT: &'static str;
    /// The command that writes it (`diagnose`, `fit`).
    const COMMAND: &'static str;
    /// Checks every value read from it against its stated range (docs/model.md).
    fn check(&self) -> Result<(), FieldError>;
}

/// The canonical form of a record's JSON value: compact, without the top-level digest.
fn canonical(mut value: Value) -> Vec<u8> {
    if let Value::Object(map) = &mut value {
        map.remove(DIGEST_KEY);
    }
    serde_json::to_vec(&value).expect("a JSON value serialises")
}

/// The digest of `record` (any digest it holds left out).
pub fn digest_of<T: Serialize>(record: &T) -> String {
    let value = serde_json::to_value(record).expect("a record serialises");
    hex_sha256(&canonical(value))
}

/// `record` as pretty JSON with its digest as the last key.
pub fn sealed<T: Serialize>(record: &T) -> Vec<u8> {
    #[derive(Serialize)]
    struct Sealed<'a, T> {
        #[serde(flatten)]
        record: &'a T,
        digest: String,
    }
    let digest = digest_of(record);
    serde_json::to_vec_pretty(&Sealed { record, digest }).expect("a record serialises")
}

/// Writes `record` to `path` atomically, sealed with its digest.
pub fn write_record<T: Serialize>(path: &Path, record: &T) -> Result<(), WriteError> {
    write_atomically(path, &sealed(record))
}

/// Reads the record at `path`, labelled `label` in messages, and checks it (see the module
/// documentation).
pub fn read_record<T: Record>(path: &Path, label: &'static str) -> Result<T, RecordError> {
    let text = read_string(path, label, MAX_JSON_BYTES)?;
    let value: Value = serde_json::from_str(&text).map_err(|e| RecordError::NotJson {
        path: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message: words(&e),
    })?;
    let found = value.get("format").map(|f| match f {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    });
    if found.as_deref() != Some(T::FORMAT) {
        return Err(RecordError::Format {
            path: path.to_path_buf(),
            found: found.unwrap_or_else(|| "none".into()),
            expected: T::FORMAT,
            command: T::COMMAND,
        });
    }
    let Some(stored) = value
        .get(DIGEST_KEY)
        .and_then(Value::as_str)
        .map(str::to_string)
    else {
        return Err(RecordError::NoDigest {
            path: path.to_path_buf(),
            command: T::COMMAND,
        });
    };
    if hex_sha256(&canonical(value)) != stored {
        return Err(RecordError::Edited {
            path: path.to_path_buf(),
            command: T::COMMAND,
        });
    }
    let record: T = serde_json::from_str(&text).map_err(|e| RecordError::Shape {
        path: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message: words(&e),
    })?;
    record.check().map_err(|field| RecordError::Field {
        path: path.to_path_buf(),
        field,
    })?;
    Ok(record)
}

/// serde_json's message without its own " at line L column C" (the error says it once).
fn words(e: &serde_json::Error) -> String {
    let text = e.to_string();
    match text.rfind(" at line ") {
        Some(i) => text[..i].to_string(),
        None => text,
    }
}

/// A check of one field: `value` must satisfy `ok`, else a [`FieldError`] naming `field` and
/// `expected`.
pub fn field(
    field: impl Into<String>,
    value: f64,
    ok: bool,
    expected: &str,
) -> Result<(), FieldError> {
    if ok {
        Ok(())
    } else {
        Err(FieldError {
            field: field.into(),
            value: number(value),
            expected: expected.into(),
        })
    }
}

/// `value` as a message shows it: in exponent form when very large or small (1e300, not 301
/// digits).
fn number(value: f64) -> String {
    let a = value.abs();
    if a > 0.0 && a.is_finite() && !(1e-4..1e16).contains(&a) {
        format!("{value:e}")
    } else {
        format!("{value}")
    }
}

/// The largest position noise a record may hold \[m\]: the largest position telemetry may
/// hold (`sepval_core::limits`), beyond which no noise can have been estimated.
pub const MAX_SIGMA_POS_M: f64 = 1e5;
/// The largest attitude noise a record may hold \[deg\] (the largest telemetry angle).
pub const MAX_SIGMA_ATT_DEG: f64 = 3600.0;

/// Checks a record's noise: sigma_pos_m in (0, [`MAX_SIGMA_POS_M`]] m, sigma_att_deg in
/// (0, [`MAX_SIGMA_ATT_DEG`]] deg.
pub fn check_noise(pos_m: f64, att_deg: f64) -> Result<(), FieldError> {
    field(
        "sigma_pos_m",
        pos_m,
        pos_m > 0.0 && pos_m <= MAX_SIGMA_POS_M,
        "a position noise in (0, 1e5] m",
    )?;
    field(
        "sigma_att_deg",
        att_deg,
        att_deg > 0.0 && att_deg <= MAX_SIGMA_ATT_DEG,
        "an attitude noise in (0, 3600] deg",
    )
}

/// Checks the identifiability of a record's answer at `at`: every value finite, every
/// standard error finite and >= 0, every correlation in [-1, 1], the correlation matrix
/// square over the parameters.
pub fn check_identifiability(
    at: &str,
    i: &sepval_solve::identifiability::Identifiability,
) -> Result<(), FieldError> {
    let n = i.parameters.len();
    for (k, p) in i.parameters.iter().enumerate() {
        let here = format!("{at}.parameters[{k}]");
        field(
            format!("{here}.value"),
            p.value,
            p.value.is_finite(),
            "a finite number",
        )?;
        for (name, se) in [
            ("std_error", p.std_error),
            ("std_error_white", p.std_error_white),
        ] {
            if let Some(se) = se {
                field(
                    format!("{here}.{name}"),
                    se,
                    se.is_finite() && se >= 0.0,
                    "a finite standard error >= 0",
                )?;
            }
        }
    }
    if i.correlation.len() != n || i.correlation.iter().any(|row| row.len() != n) {
        return Err(FieldError {
            field: format!("{at}.correlation"),
            value: format!("{} rows", i.correlation.len()),
            expected: format!("a {n} x {n} matrix (one row and column per parameter)"),
        });
    }
    for (r, row) in i.correlation.iter().enumerate() {
        for (c, &rho) in row.iter().enumerate() {
            field(
                format!("{at}.correlation[{r}][{c}]"),
                rho,
                (-1.0..=1.0).contains(&rho),
                "a correlation in [-1, 1]",
            )?;
        }
    }
    Ok(())
}

/// Checks the factors of a model at `at`: finite.
pub fn check_factors(at: &str, f: &sepval_core::factors::Factors) -> Result<(), FieldError> {
    for (name, v) in sepval_core::factors::Factor::ALL.iter().zip(f.0.iter()) {
        field(
            format!("{at}.{}", name.name()),
            *v,
            v.is_finite(),
            "a finite factor",
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests;
