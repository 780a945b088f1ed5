//! Telemetry files: measured or simulated trajectories as CSV.
//!
//! Source: `docs/model.md` section 6. One header row naming the columns `t_s, x_m, y_m,
//! z_m, roll_deg, pitch_deg, yaw_deg` (any order; positions may be `x_ft, y_ft, z_ft`), then one
//! row per sample, time strictly increasing. Lines starting with `#` are comments; a comment of
//! the form `# key = value` or `# key: value` is also kept as metadata (for example the event
//! name or its flight condition). A key given twice must have the same value both times: `#
//! mach = 1.2` then `# mach = 0.6` is refused, naming both lines (which one was meant cannot be
//! told); the same value given again is accepted.
//!
//! Choices made here:
//! - Columns for other quantities (a header whose quantity is not t, x, y, z, roll, pitch or
//!   yaw) are ignored, so that files with extra channels can be read; a known quantity with an
//!   unknown unit (`x_km`, `roll_rad`) is refused.
//! - Blank lines are skipped. Fields may be surrounded by spaces, and enclosed in double quotes
//!   as spreadsheets write them (`"t_s","x_m",...`); a quote that does not enclose a whole field
//!   is refused. A UTF-8 byte-order mark at the start of the file is skipped.
//! - The limits of [`sepval_core::limits`]: at most [`MAX_SAMPLES`] samples, sample times within
//!   +-[`MAX_SPAN_S`](sepval_core::limits::MAX_SPAN_S), positions within +-[`MAX_POSITION_M`](sepval_core::limits::MAX_POSITION_M) and angles within
//!   +-[`MAX_ANGLE_DEG`](sepval_core::limits::MAX_ANGLE_DEG); a value beyond them is refused with its line and column (it is a
//!   unit or export mistake, and it would overflow the goals).
//! - Files are read line by line: the text is never held whole in memory. Only a regular file
//!   is read, of at most [`MAX_TELEMETRY_BYTES`] ([`sepval_core::input_file`]), each line of at most
//!   [`MAX_TELEMETRY_LINE_BYTES`] (refused once that many bytes of it were read).
//! - Files sepval writes print every number in the shortest form that reads back as the same
//!   double, so writing and reading is exact.

use std::fmt::Write as _;
use std::path::Path;

use sepval_core::atomic_file::{WriteError, write_atomically};
use sepval_core::input_file::{InputFile, InputFileError};
use sepval_core::limits::{MAX_SAMPLES, MAX_TELEMETRY_BYTES, MAX_TELEMETRY_LINE_BYTES};
use sepval_core::units::M_PER_FT;

mod error;
pub(crate) mod lines;
pub mod outliers;
pub use error::{Bound, TelemetryError};
use lines::{BoundedLines, too_long as line_too_long};

/// A trajectory: samples of position and attitude against time.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Trajectory {
    /// Sample times \[s\], strictly increasing.
    pub times_s: Vec<f64>,
    /// Launch-frame positions (x, y, z; z down) \[m\].
    pub pos_m: Vec<[f64; 3]>,
    /// Euler angles (roll, pitch, yaw) \[deg\].
    pub att_deg: Vec<[f64; 3]>,
    /// `# key = value` comments, in file order.
    pub metadata: Vec<(String, String)>,
    /// All comment lines (text after `#`, trimmed), in file order.
    pub comments: Vec<String>,
}

/// A trajectory read from a file or text, with the line of each sample (so that a message
/// about a sample can name its line).
#[derive(Debug, Clone, PartialEq)]
pub struct Numbered {
    /// The trajectory.
    pub trajectory: Trajectory,
    /// The 1-based line of each sample in the file.
    pub lines: Vec<usize>,
}

/// One quantity of a telemetry row: its name, accepted headers with their scale to SI, and how
/// an error message lists them.
struct Quantity {
    name: &'static str,
    headers: &'static [(&'static str, f64)],
    expected: &'static str,
}

const fn quantity(
    name: &'static str,
    headers: &'static [(&'static str, f64)],
    expected: &'static str,
) -> Quantity {
    Quantity {
        name,
        headers,
        expected,
    }
}

/// The seven quantities of a telemetry row, in the order of [`Trajectory`]'s fields.
const QUANTITIES: [Quantity; 7] = [
    quantity("t", &[("t_s", 1.0)], "`t_s`"),
    quantity("x", &[("x_m", 1.0), ("x_ft", M_PER_FT)], "`x_m` or `x_ft`"),
    quantity("y", &[("y_m", 1.0), ("y_ft", M_PER_FT)], "`y_m` or `y_ft`"),
    quantity("z", &[("z_m", 1.0), ("z_ft", M_PER_FT)], "`z_m` or `z_ft`"),
    quantity("roll", &[("roll_deg", 1.0)], "`roll_deg`"),
    quantity("pitch", &[("pitch_deg", 1.0)], "`pitch_deg`"),
    quantity("yaw", &[("yaw_deg", 1.0)], "`yaw_deg`"),
];

/// (column index, scale to SI) of each quantity.
type ColumnMap = [(usize, f64); 7];

/// The header row: its line, its field names and where each quantity is.
struct Header {
    line: usize,
    names: Vec<String>,
    columns: ColumnMap,
}

impl Trajectory {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.times_s.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.times_s.is_empty()
    }

    /// The value of metadata `key`, if present (a key read from a file has one value, however
    /// often it is given; of entries pushed with different values, the last one wins).
    pub fn meta(&self, key: &str) -> Option<&str> {
        self.metadata
            .iter()
            .rev()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// Reads a telemetry file, line by line.
    pub fn read(path: &Path) -> Result<Trajectory, TelemetryError> {
        Trajectory::read_numbered(path).map(|n| n.trajectory)
    }

    /// Reads a telemetry file, line by line, with the line of each sample.
    pub fn read_numbered(path: &Path) -> Result<Numbered, TelemetryError> {
        let name = path.display().to_string();
        let file =
            InputFile::open(path, "telemetry file", MAX_TELEMETRY_BYTES).map_err(|e| {
                match e.into_io() {
                    Ok(io) => TelemetryError::Io {
                        file: name.clone(),
                        message: io.to_string(),
                    },
                    Err(refused) => TelemetryError::Input(Box::new(refused)),
                }
            })?;
        let lines = BoundedLines::new(std::io::BufReader::new(file), MAX_TELEMETRY_LINE_BYTES);
        Trajectory::parse_lines(lines, &name, MAX_SAMPLES)
    }

    /// Parses telemetry text; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Trajectory, TelemetryError> {
        Trajectory::parse_numbered(text, file).map(|n| n.trajectory)
    }

    /// Parses telemetry text, with the line of each sample; `file` names it in errors.
    pub fn parse_numbered(text: &str, file: &str) -> Result<Numbered, TelemetryError> {
        let lines = text.split('\n').map(|l| Ok(l.as_bytes().to_vec()));
        Trajectory::parse_lines(lines, file, MAX_SAMPLES)
    }

    /// Parses telemetry lines (without their `\n`), at most `max_samples` samples; `file`
    /// names the source in errors.
    #[doc(hidden)]
    pub fn parse_lines(
        lines: impl Iterator<Item = std::io::Result<Vec<u8>>>,
        file: &str,
        max_samples: usize,
    ) -> Result<Numbered, TelemetryError> {
        let file = file.to_string();
        let mut out = Trajectory::default();
        let mut sample_lines = Vec::new();
        let mut metadata_lines = Vec::new();
        let mut header: Option<Header> = None;
        for (i, raw) in lines.enumerate() {
            let line = i + 1;
            let raw = line_bytes(raw, &file, line)?;
            let text = std::str::from_utf8(&raw).map_err(|_| TelemetryError::NotText {
                file: file.clone(),
                line,
            })?;
            let text = if line == 1 {
                text.strip_prefix('\u{feff}').unwrap_or(text)
            } else {
                text
            };
            let trimmed = text.trim();
            if trimmed.is_empty() {
                continue;
            }
            if let Some(comment) = trimmed.strip_prefix('#') {
                let comment = comment.trim();
                out.comments.push(comment.to_string());
                if let Some((k, v)) = split_metadata(comment) {
                    check_repeated(&out.metadata, &metadata_lines, (&k, &v), line, &file)?;
                    out.metadata.push((k, v));
                    metadata_lines.push(line);
                }
                continue;
            }
            let fields = split_fields(trimmed, line, &file)?;
            let Some(Header { names, columns, .. }) = &header else {
                header = Some(Header {
                    line,
                    names: fields.iter().map(|s| s.to_string()).collect(),
                    columns: parse_header(&fields, line, &file)?,
                });
                continue;
            };
            if fields.len() != names.len() {
                return Err(TelemetryError::FieldCount {
                    file,
                    line,
                    expected: names.len(),
                    found: fields.len(),
                });
            }
            if out.times_s.len() >= max_samples {
                return Err(TelemetryError::TooManySamples {
                    file,
                    line,
                    limit: max_samples,
                });
            }
            let values = parse_row(&fields, names, columns, line, &file)?;
            if let Some(&previous_s) = out.times_s.last() {
                if values[0] <= previous_s {
                    return Err(TelemetryError::TimeNotIncreasing {
                        file,
                        line,
                        column: columns[0].0 + 1,
                        t_s: values[0],
                        previous_s,
                    });
                }
            }
            out.times_s.push(values[0]);
            out.pos_m.push([values[1], values[2], values[3]]);
            out.att_deg.push([values[4], values[5], values[6]]);
            sample_lines.push(line);
        }
        match header {
            None => Err(TelemetryError::Empty { file }),
            Some(Header { line, .. }) if out.times_s.is_empty() => {
                Err(TelemetryError::NoSamples { file, line })
            }
            Some(_) => Ok(Numbered {
                trajectory: out,
                lines: sample_lines,
            }),
        }
    }

    /// The trajectory as CSV text (comments first, then header and rows; SI units).
    pub fn to_csv_string(&self) -> String {
        let mut s = String::with_capacity(64 * (self.len() + 8));
        for c in &self.comments {
            let _ = writeln!(s, "# {c}");
        }
        self.write_csv_rows(&mut s);
        s
    }

    /// Writes the header and the rows (no comments) as CSV into `w`, every number in the
    /// shortest form that reads back as the same double.
    pub fn write_csv_rows(&self, w: &mut impl std::fmt::Write) {
        let _ = w.write_str("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n");
        for k in 0..self.len() {
            let p = self.pos_m[k];
            let a = self.att_deg[k];
            let _ = writeln!(
                w,
                "{},{},{},{},{},{},{}",
                self.times_s[k], p[0], p[1], p[2], a[0], a[1], a[2]
            );
        }
    }

    /// Writes the trajectory atomically (no partial file is ever left at `path`).
    pub fn write(&self, path: &Path) -> Result<(), WriteError> {
        write_atomically(path, self.to_csv_string().as_bytes())
    }

    /// Writes the trajectory atomically with `extra` columns after the seven (each a header
    /// whose quantity readers ignore, such as `clearance_m`, and one value per sample).
    pub fn write_with_columns(
        &self,
        path: &Path,
        extra: &[(&str, &[f64])],
    ) -> Result<(), WriteError> {
        let mut s = String::with_capacity(64 * (self.len() + 8));
        for c in &self.comments {
            let _ = writeln!(s, "# {c}");
        }
        s.push_str("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg");
        for (h, _) in extra {
            let _ = write!(s, ",{h}");
        }
        s.push('\n');
        for k in 0..self.len() {
            let (p, a) = (self.pos_m[k], self.att_deg[k]);
            let _ = write!(
                s,
                "{},{},{},{},{},{},{}",
                self.times_s[k], p[0], p[1], p[2], a[0], a[1], a[2]
            );
            for (_, v) in extra {
                let _ = write!(s, ",{}", v.get(k).copied().unwrap_or(f64::NAN));
            }
            s.push('\n');
        }
        write_atomically(path, s.as_bytes())
    }

    /// Adds a `# key = value` comment (and metadata entry).
    pub fn push_metadata(&mut self, key: &str, value: &str) {
        self.comments.push(format!("{key} = {value}"));
        self.metadata.push((key.to_string(), value.to_string()));
    }
}

/// The bytes of line `line` as read: an I/O error, a file that grew past its limit or a line
/// longer than [`MAX_TELEMETRY_LINE_BYTES`] become the error that says so.
fn line_bytes(
    raw: std::io::Result<Vec<u8>>,
    file: &str,
    line: usize,
) -> Result<Vec<u8>, TelemetryError> {
    let raw = raw.map_err(|e| match InputFileError::from_io(&e) {
        // A file that grew past its limit while read.
        Some(_) => TelemetryError::Input(Box::new(
            *e.into_inner()
                .and_then(|inner| inner.downcast::<InputFileError>().ok())
                .expect("checked: it carries an InputFileError"),
        )),
        None => match line_too_long(&e) {
            Some(limit) => TelemetryError::LineTooLong {
                file: file.to_string(),
                line,
                limit,
            },
            None => TelemetryError::Io {
                file: file.to_string(),
                message: format!("line {line}: {e}"),
            },
        },
    })?;
    if raw.len() > MAX_TELEMETRY_LINE_BYTES {
        // Text given whole (not read from a file) is held to the same bound.
        return Err(TelemetryError::LineTooLong {
            file: file.to_string(),
            line,
            limit: MAX_TELEMETRY_LINE_BYTES,
        });
    }
    Ok(raw)
}

/// The seven values of a data row in SI (time, position, attitude): each field a finite number
/// within the bounds of plausible telemetry.
fn parse_row(
    fields: &[&str],
    names: &[String],
    columns: &ColumnMap,
    line: usize,
    file: &str,
) -> Result<[f64; 7], TelemetryError> {
    let mut values = [0.0; 7];
    for (q, &(col, scale)) in columns.iter().enumerate() {
        let text = fields[col];
        let field_error = |value: &str| {
            (
                file.to_string(),
                col + 1,
                names[col].clone(),
                value.to_string(),
            )
        };
        let v: f64 = text.parse().map_err(|_| {
            let (file, column, header, value) = field_error(text);
            TelemetryError::NotNumeric {
                file,
                line,
                column,
                header,
                value,
            }
        })?;
        if !v.is_finite() {
            let (file, column, header, value) = field_error(text);
            return Err(TelemetryError::NotFinite {
                file,
                line,
                column,
                header,
                value,
            });
        }
        let si = v * scale;
        let kind = match q {
            0 => Bound::Time,
            1..=3 => Bound::Position,
            _ => Bound::Angle,
        };
        if si.abs() > kind.bound() {
            let (file, column, header, value) = field_error(text);
            return Err(TelemetryError::Implausible {
                file,
                line,
                column,
                header,
                value,
                kind,
            });
        }
        values[q] = si;
    }
    Ok(values)
}

/// The comma-separated fields of a line, trimmed, each with one pair of enclosing double
/// quotes removed.
fn split_fields<'a>(
    line_text: &'a str,
    line: usize,
    file: &str,
) -> Result<Vec<&'a str>, TelemetryError> {
    line_text
        .split(',')
        .enumerate()
        .map(|(k, f)| {
            let f = f.trim();
            let inner = f
                .strip_prefix('"')
                .and_then(|g| g.strip_suffix('"'))
                .unwrap_or(f);
            if inner.contains('"') || (f.len() == 1 && f == "\"") {
                return Err(TelemetryError::Quote {
                    file: file.to_string(),
                    line,
                    column: k + 1,
                    value: f.to_string(),
                });
            }
            Ok(inner.trim())
        })
        .collect()
}

/// Refuses metadata `key = value` on `line` when an earlier entry (`metadata`, read on
/// `lines`) gives the key another value.
fn check_repeated(
    metadata: &[(String, String)],
    lines: &[usize],
    (key, value): (&str, &str),
    line: usize,
    file: &str,
) -> Result<(), TelemetryError> {
    let earlier = metadata.iter().zip(lines).find(|((k, _), _)| k == key);
    match earlier {
        Some(((_, first_value), &first_line)) if first_value != value => {
            Err(TelemetryError::MetadataTwice {
                file: file.to_string(),
                line,
                key: key.to_string(),
                value: value.to_string(),
                first_line,
                first_value: first_value.clone(),
            })
        }
        _ => Ok(()),
    }
}

fn split_metadata(comment: &str) -> Option<(String, String)> {
    let pos = comment.find(['=', ':'])?;
    let (k, v) = (comment[..pos].trim(), comment[pos + 1..].trim());
    let is_key = !k.is_empty()
        && k.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.');
    is_key.then(|| (k.to_string(), v.to_string()))
}

fn parse_header(fields: &[&str], line: usize, file: &str) -> Result<ColumnMap, TelemetryError> {
    let mut found: [Option<(usize, f64)>; 7] = [None; 7];
    for (col, name) in fields.iter().enumerate() {
        let quantity = name.split_once('_').map_or(*name, |(q, _)| q);
        let Some(q) = QUANTITIES.iter().position(|k| k.name == quantity) else {
            continue; // another channel: ignored
        };
        let Quantity {
            name: qname,
            headers,
            expected,
        } = &QUANTITIES[q];
        let Some(&(_, scale)) = headers.iter().find(|(h, _)| *h == *name) else {
            return Err(TelemetryError::UnknownUnit {
                file: file.to_string(),
                line,
                column: col + 1,
                header: name.to_string(),
                expected,
            });
        };
        if found[q].is_some() {
            return Err(TelemetryError::DuplicateColumn {
                file: file.to_string(),
                line,
                column: col + 1,
                header: name.to_string(),
                quantity: qname,
            });
        }
        found[q] = Some((col, scale));
    }
    let mut out = [(0, 0.0); 7];
    for (q, f) in found.iter().enumerate() {
        out[q] = f.ok_or(TelemetryError::MissingColumn {
            file: file.to_string(),
            line,
            quantity: QUANTITIES[q].name,
            expected: QUANTITIES[q].expected,
        })?;
    }
    Ok(out)
}
