//! Extension files (`sepval-extension/1`, docs/discovery.md section 11.3): a term as files write
//! it, the reader that refuses a bad field with its file, line and name, and the writer whose
//! output reads back to the same terms bit for bit.

use serde::{Deserialize, Serialize};

use super::wind::DEFAULT_RISE_S;
use super::{Axis, Family, MAX_TERMS, Regressor, Term, TermError};
use sepval_core::limits::MAX_EXTENSION_BYTES;

/// A term as files write it: `axis`, `family`, `regressor`, the family's locator by name (a
/// wind's two: `t_on_s` and `rise_s`, the latter [`DEFAULT_RISE_S`] when not written), and
/// `coefficient` (with `std_error` and `reading` kept as the diagnosis wrote them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TermRecord {
    /// `CA`, `CY`, `CZ`, `Cl`, `Cm`, `Cn`, `ejector`, `wind_y` or `wind_z`.
    pub axis: String,
    /// A family of the library.
    pub family: String,
    /// The family's regressor.
    pub regressor: String,
    /// Decay length (`interference`, `interference_flow_angle`) \[m\].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lambda_m: Option<f64>,
    /// Reference Mach number (`mach`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mach0: Option<f64>,
    /// Step or gust time (`step`, `wind`) \[s\].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t_on_s: Option<f64>,
    /// Onset or pulse length (`wind`) \[s\].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rise_s: Option<f64>,
    /// Frequency (`oscillation`) \[Hz\].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub f_hz: Option<f64>,
    /// The coefficient.
    pub coefficient: f64,
    /// Its standard error, as estimated (informational).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_error: Option<f64>,
    /// What it means physically (informational).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reading: Option<String>,
}

impl TermRecord {
    /// The record of a term.
    pub fn of(term: &Term) -> TermRecord {
        let family = term.regressor.family();
        let loc = term.locator[0];
        let pick = |name: &str| (family.locator() == Some(name)).then_some(loc);
        TermRecord {
            axis: term.axis.name().to_string(),
            family: family.name().to_string(),
            regressor: term.regressor.name().to_string(),
            lambda_m: pick("lambda_m"),
            mach0: pick("mach0"),
            t_on_s: pick("t_on_s"),
            rise_s: (family == Family::Wind).then_some(term.locator[1]),
            f_hz: pick("f_hz"),
            coefficient: term.coefficient,
            std_error: None,
            reading: None,
        }
    }

    /// The term of a record: `Err((field, message))` names what is wrong.
    pub fn term(&self) -> Result<Term, (&'static str, String)> {
        let axis = Axis::from_name(&self.axis).ok_or_else(|| {
            (
                "axis",
                format!(
                    "`{}` is not an axis (expected CA, CY, CZ, Cl, Cm, Cn, ejector, wind_y or wind_z)",
                    self.axis
                ),
            )
        })?;
        let family = Family::from_name(&self.family).ok_or_else(|| {
            (
                "family",
                format!(
                    "`{}` is not a family of the library (expected {})",
                    self.family,
                    Family::LIBRARY.map(Family::name).join(", ")
                ),
            )
        })?;
        let regressor = Regressor::from_names(family, &self.regressor).ok_or_else(|| {
            let names: Vec<&str> = Regressor::ALL
                .iter()
                .filter(|(_, f, _)| *f == family)
                .map(|(_, _, n)| *n)
                .collect();
            (
                "regressor",
                format!(
                    "`{}` is not a regressor of {} (expected {})",
                    self.regressor,
                    family.name(),
                    names.join(", ")
                ),
            )
        })?;
        let given = [
            ("lambda_m", self.lambda_m),
            ("mach0", self.mach0),
            ("t_on_s", self.t_on_s),
            ("f_hz", self.f_hz),
        ];
        let mut locator = 0.0;
        for (name, value) in given {
            match (family.locator() == Some(name), value) {
                (true, Some(v)) => locator = v,
                (true, None) => {
                    return Err((name, format!("is missing: {} needs it", family.name())));
                }
                (false, Some(_)) => {
                    return Err((name, format!("is not a locator of {}", family.name())));
                }
                (false, None) => {}
            }
        }
        let rise_s = match (family, self.rise_s) {
            (Family::Wind, v) => v.unwrap_or(DEFAULT_RISE_S),
            (_, None) => 0.0,
            (_, Some(_)) => {
                return Err(("rise_s", format!("is not a locator of {}", family.name())));
            }
        };
        let term = Term {
            axis,
            regressor,
            locator: [locator, rise_s],
            coefficient: self.coefficient,
        };
        term.check().map_err(|e| {
            let field = match &e {
                TermError::Axis { .. } => "axis",
                TermError::Value { what, .. } => what,
                TermError::TooMany => "term",
            };
            (field, e.to_string())
        })?;
        Ok(term)
    }
}

/// DIR/extension.toml: `format` and the terms.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ExtensionFile {
    format: String,
    #[serde(default)]
    term: Vec<toml::Spanned<TermRecord>>,
}

/// Format tag of extension files.
pub const EXTENSION_FORMAT: &str = "sepval-extension/1";

/// An extension file that cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExtensionError {
    /// The file cannot be read.
    #[error("cannot read extension {path}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The path is not a regular file, or the file is over its byte limit.
    #[error(transparent)]
    Input(Box<sepval_core::input_file::InputFileError>),
    /// Not TOML, or not the expected fields (the parser names line and column).
    #[error("extension {path}: {message}")]
    Parse {
        /// The file.
        path: String,
        /// The parser's message.
        message: String,
    },
    /// A term that cannot be run.
    #[error("extension {path}: line {line}, term {index}, `{field}` {message}")]
    Term {
        /// The file.
        path: String,
        /// The line of the field (of the term's table when the field is missing).
        line: usize,
        /// The term's number (1-based).
        index: usize,
        /// The field.
        field: &'static str,
        /// What is wrong.
        message: String,
    },
}

/// The line of `field` within the term spanning `span` of `text` (its `[[term]]` line when the
/// field is not written, e.g. a missing coefficient).
fn field_line(text: &str, span: std::ops::Range<usize>, field: &str) -> usize {
    // The term's lines: from its span to the next table header.
    let start = span.start.min(text.len());
    let first = text[..start].matches('\n').count() + 1;
    text.get(start..)
        .unwrap_or_default()
        .lines()
        .enumerate()
        .take_while(|(k, l)| *k == 0 || !l.trim_start().starts_with('['))
        .map(|(_, l)| l)
        .position(|l| {
            l.trim_start()
                .strip_prefix(field)
                .is_some_and(|rest| rest.trim_start().starts_with('='))
        })
        .map_or(first, |k| first + k)
}

/// Reads extension TOML; `path` names it in errors.
pub fn parse_extension(text: &str, path: &str) -> Result<Vec<Term>, ExtensionError> {
    let file: ExtensionFile = toml::from_str(text).map_err(|e| ExtensionError::Parse {
        path: path.to_string(),
        message: sepval_core::toml_error::one_line(text, &e),
    })?;
    if file.format != EXTENSION_FORMAT {
        return Err(ExtensionError::Parse {
            path: path.to_string(),
            message: format!(
                "format `{}`, this sepval reads `{EXTENSION_FORMAT}`",
                file.format
            ),
        });
    }
    if file.term.len() > MAX_TERMS {
        return Err(ExtensionError::Parse {
            path: path.to_string(),
            message: format!("{} terms, at most {MAX_TERMS}", file.term.len()),
        });
    }
    file.term
        .iter()
        .enumerate()
        .map(|(k, t)| {
            t.get_ref()
                .term()
                .map_err(|(field, message)| ExtensionError::Term {
                    path: path.to_string(),
                    line: field_line(text, t.span(), field),
                    index: k + 1,
                    field,
                    message,
                })
        })
        .collect()
}

/// Reads an extension file.
pub fn load_extension(path: &std::path::Path) -> Result<Vec<Term>, ExtensionError> {
    let name = path.display().to_string();
    let text = sepval_core::input_file::read_string(path, "extension", MAX_EXTENSION_BYTES)
        .map_err(|e| match e.into_io() {
            Ok(source) => ExtensionError::Io {
                path: name.clone(),
                source,
            },
            Err(refused) => ExtensionError::Input(Box::new(refused)),
        })?;
    parse_extension(&text, &name)
}

/// The extension file of `records` (a comment line first).
pub fn extension_toml(records: &[TermRecord]) -> String {
    #[derive(Serialize)]
    struct Out<'a> {
        format: &'a str,
        term: &'a [TermRecord],
    }
    format!(
        "# sepval model extension (docs/model.md section 11): give it to simulate, fit or\n\
         # diagnose with --extension FILE.\n{}",
        toml::to_string(&Out {
            format: EXTENSION_FORMAT,
            term: records,
        })
        .expect("records serialise")
    )
}
