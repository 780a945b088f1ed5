//! Telemetry files: measured or simulated trajectories as CSV.
//!
//! Source: `docs/model.md` section 6. One header row naming the columns `t_s, x_m, y_m,
//! z_m, roll_deg, pitch_deg, yaw_deg` (any order; positions may be `x_ft, y_ft, z_ft`), then one
//! row per sample, time strictly increasing. Lines starting with `#` are comments; a comment of
//! the form `# key = value` or `# key: value` is also kept as metadata (for example the event
//! name or its flight condition).
//!
//! Choices made here:
//! - Columns for other quantities (a header whose quantity is not t, x, y, z, roll, pitch or
//!   yaw) are ignored, so that files with extra channels can be read; a known quantity with an
//!   unknown unit (`x_km`, `roll_rad`) is refused.
//! - Blank lines are skipped. Fields may be surrounded by spaces, and enclosed in double quotes
//!   as spreadsheets write them (`"t_s","x_m",...`); a quote that does not enclose a whole field
//!   is refused. A UTF-8 byte-order mark at the start of the file is skipped.
//! - The limits of [`crate::limits`]: at most [`MAX_SAMPLES`] samples, sample times within
//!   +-[`MAX_SPAN_S`], positions within +-[`MAX_POSITION_M`] and angles within
//!   +-[`MAX_ANGLE_DEG`]; a value beyond them is refused with its line and column (it is a
//!   unit or export mistake, and it would overflow the goals).
//! - Files are read line by line: the text is never held whole in memory.
//! - Files sepval writes print every number in the shortest form that reads back as the same
//!   double, so writing and reading is exact.

use std::fmt::Write as _;
use std::io::BufRead;
use std::path::Path;

use crate::atomic_file::{WriteError, write_atomically};
use crate::limits::{MAX_ANGLE_DEG, MAX_POSITION_M, MAX_SAMPLES, MAX_SPAN_S};
use crate::units::M_PER_FT;

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

/// Errors reading a telemetry file. Every variant names the file; those about content name the
/// line and column.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum TelemetryError {
    /// The file could not be read.
    #[error("{file}: cannot read: {message}")]
    Io {
        /// The file.
        file: String,
        /// The cause.
        message: String,
    },
    /// No header row.
    #[error(
        "{file}: empty file: expected a header row `t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg`"
    )]
    Empty {
        /// The file.
        file: String,
    },
    /// A header without data rows.
    #[error("{file}: no samples after the header (line {line})")]
    NoSamples {
        /// The file.
        file: String,
        /// Header line.
        line: usize,
    },
    /// A required quantity has no column.
    #[error("{file}: line {line}: missing column for {quantity}: expected {expected}")]
    MissingColumn {
        /// The file.
        file: String,
        /// Header line.
        line: usize,
        /// The quantity.
        quantity: &'static str,
        /// Accepted headers.
        expected: &'static str,
    },
    /// A known quantity with an unknown unit.
    #[error(
        "{file}: line {line}, column {column}: unknown unit in `{header}`: expected {expected}"
    )]
    UnknownUnit {
        /// The file.
        file: String,
        /// Header line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The header given.
        header: String,
        /// Accepted headers.
        expected: &'static str,
    },
    /// Two columns for one quantity.
    #[error("{file}: line {line}, column {column}: `{header}` repeats the {quantity} column")]
    DuplicateColumn {
        /// The file.
        file: String,
        /// Header line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The header given.
        header: String,
        /// The quantity.
        quantity: &'static str,
    },
    /// A row with the wrong number of fields.
    #[error("{file}: line {line}: expected {expected} fields as in the header, found {found}")]
    FieldCount {
        /// The file.
        file: String,
        /// The line.
        line: usize,
        /// Fields in the header.
        expected: usize,
        /// Fields found.
        found: usize,
    },
    /// A field that is not a number.
    #[error(
        "{file}: line {line}, column {column} (`{header}`): expected a number, found `{value}`"
    )]
    NotNumeric {
        /// The file.
        file: String,
        /// The line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// Its header.
        header: String,
        /// The text found.
        value: String,
    },
    /// A field that is NaN or infinite.
    #[error(
        "{file}: line {line}, column {column} (`{header}`): expected a finite number, found `{value}`"
    )]
    NotFinite {
        /// The file.
        file: String,
        /// The line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// Its header.
        header: String,
        /// The text found.
        value: String,
    },
    /// A line that is not UTF-8 text.
    #[error("{file}: line {line}: not valid UTF-8 text")]
    NotText {
        /// The file.
        file: String,
        /// The line.
        line: usize,
    },
    /// A double quote that does not enclose a whole field.
    #[error(
        "{file}: line {line}, column {column}: unbalanced double quote in `{value}` (a quoted field must start and end with a quote)"
    )]
    Quote {
        /// The file.
        file: String,
        /// The line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The field.
        value: String,
    },
    /// More samples than an event may have.
    #[error("{file}: line {line}: more than {limit} samples, the limit per event")]
    TooManySamples {
        /// The file.
        file: String,
        /// The line of the first sample beyond the limit.
        line: usize,
        /// The limit.
        limit: usize,
    },
    /// A value beyond the bounds of plausible telemetry.
    #[error(
        "{file}: line {line}, column {column} (`{header}`): {value} is beyond the plausible bound of +-{} {} for {}",
        kind.bound(),
        kind.unit(),
        kind.what()
    )]
    Implausible {
        /// The file.
        file: String,
        /// The line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// Its header.
        header: String,
        /// The value (in the file's unit).
        value: String,
        /// Which bound.
        kind: Bound,
    },
    /// Time not strictly increasing.
    #[error(
        "{file}: line {line}, column {column} (`t_s`): time {t_s} s is not after the previous sample's {previous_s} s (times must increase strictly)"
    )]
    TimeNotIncreasing {
        /// The file.
        file: String,
        /// The line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The time found.
        t_s: f64,
        /// The previous time.
        previous_s: f64,
    },
}

/// The bounds of plausible telemetry ([`crate::limits`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bound {
    /// A sample time: +-[`MAX_SPAN_S`].
    Time,
    /// A position coordinate: +-[`MAX_POSITION_M`].
    Position,
    /// An Euler angle: +-[`MAX_ANGLE_DEG`].
    Angle,
}

impl Bound {
    /// The bound, SI.
    pub fn bound(self) -> f64 {
        match self {
            Bound::Time => MAX_SPAN_S,
            Bound::Position => MAX_POSITION_M,
            Bound::Angle => MAX_ANGLE_DEG,
        }
    }

    /// Its unit.
    pub fn unit(self) -> &'static str {
        match self {
            Bound::Time => "s",
            Bound::Position => "m",
            Bound::Angle => "deg",
        }
    }

    /// What it bounds.
    pub fn what(self) -> &'static str {
        match self {
            Bound::Time => "a sample time",
            Bound::Position => "a position",
            Bound::Angle => "an angle",
        }
    }
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

    /// The value of metadata `key`, if present (the last one wins).
    pub fn meta(&self, key: &str) -> Option<&str> {
        self.metadata
            .iter()
            .rev()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// Reads a telemetry file, line by line.
    pub fn read(path: &Path) -> Result<Trajectory, TelemetryError> {
        let name = path.display().to_string();
        let file = std::fs::File::open(path).map_err(|e| TelemetryError::Io {
            file: name.clone(),
            message: e.to_string(),
        })?;
        let lines = std::io::BufReader::new(file).split(b'\n');
        Trajectory::parse_lines(lines, &name, MAX_SAMPLES)
    }

    /// Parses telemetry text; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Trajectory, TelemetryError> {
        let lines = text.split('\n').map(|l| Ok(l.as_bytes().to_vec()));
        Trajectory::parse_lines(lines, file, MAX_SAMPLES)
    }

    /// Parses telemetry lines (without their `\n`), at most `max_samples` samples; `file`
    /// names the source in errors.
    fn parse_lines(
        lines: impl Iterator<Item = std::io::Result<Vec<u8>>>,
        file: &str,
        max_samples: usize,
    ) -> Result<Trajectory, TelemetryError> {
        let file = file.to_string();
        let mut out = Trajectory::default();
        let mut header: Option<Header> = None;
        for (i, raw) in lines.enumerate() {
            let line = i + 1;
            let raw = raw.map_err(|e| TelemetryError::Io {
                file: file.clone(),
                message: format!("line {line}: {e}"),
            })?;
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
                    out.metadata.push((k, v));
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
            let mut values = [0.0; 7];
            for (q, &(col, scale)) in columns.iter().enumerate() {
                let text = fields[col];
                let field_error =
                    |value: &str| (file.clone(), col + 1, names[col].clone(), value.to_string());
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
        }
        match header {
            None => Err(TelemetryError::Empty { file }),
            Some(Header { line, .. }) if out.times_s.is_empty() => {
                Err(TelemetryError::NoSamples { file, line })
            }
            Some(_) => Ok(out),
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

    /// Adds a `# key = value` comment (and metadata entry).
    pub fn push_metadata(&mut self, key: &str, value: &str) {
        self.comments.push(format!("{key} = {value}"));
        self.metadata.push((key.to_string(), value.to_string()));
    }
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

#[cfg(test)]
#[allow(clippy::float_cmp)] // these tests check exact values on purpose
mod tests {
    use super::*;

    const GOOD: &str = "# event = drop 1\n# mach: 0.95\n# free text\n\
        t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n\
        0,0,0,0,0,0,0\n0.005,0.1,0.2,0.3,1,2,3\n";

    fn err(text: &str) -> String {
        Trajectory::parse(text, "f.csv").unwrap_err().to_string()
    }

    #[test]
    fn reads_metadata_and_samples() {
        let t = Trajectory::parse(GOOD, "f.csv").unwrap();
        assert_eq!(t.len(), 2);
        assert_eq!(t.meta("event"), Some("drop 1"));
        assert_eq!(t.meta("mach"), Some("0.95"));
        assert_eq!(t.comments.len(), 3);
        assert_eq!(t.pos_m[1], [0.1, 0.2, 0.3]);
        assert_eq!(t.att_deg[1], [1.0, 2.0, 3.0]);
    }

    #[test]
    fn feet_are_converted_and_columns_may_be_reordered() {
        let text = "yaw_deg,t_s,x_ft,y_ft,z_ft,roll_deg,pitch_deg,mach\n3,0.5,1,2,10,1,2,0.9\n";
        let t = Trajectory::parse(text, "f.csv").unwrap();
        assert_eq!(t.times_s, vec![0.5]);
        assert_eq!(t.pos_m[0], [0.3048, 2.0 * 0.3048, 10.0 * 0.3048]);
        assert_eq!(t.att_deg[0], [1.0, 2.0, 3.0]);
    }

    #[test]
    fn write_read_round_trip_is_exact() {
        let mut t = Trajectory::parse(GOOD, "f.csv").unwrap();
        t.pos_m[1] = [0.1 + 0.2, -1.0 / 3.0, 5.780992554123456];
        t.att_deg[1] = [26.094_358_812_345_68, -1e-300, 179.999_999_999_999_97];
        let back = Trajectory::parse(&t.to_csv_string(), "g.csv").unwrap();
        assert_eq!(back, t);
    }

    #[test]
    fn every_bad_input_names_file_line_and_column() {
        assert_eq!(
            err(""),
            "f.csv: empty file: expected a header row `t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg`"
        );
        assert_eq!(err("# only a comment\n\n"), err(""));
        assert_eq!(
            err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n"),
            "f.csv: no samples after the header (line 1)"
        );
        assert_eq!(
            err("t_s,x_m,y_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0\n"),
            "f.csv: line 1: missing column for z: expected `z_m` or `z_ft`"
        );
        assert_eq!(
            err("t_s,x_km,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n"),
            "f.csv: line 1, column 2: unknown unit in `x_km`: expected `x_m` or `x_ft`"
        );
        assert_eq!(
            err("t_s,x_m,y_m,z_m,roll_rad,pitch_deg,yaw_deg\n"),
            "f.csv: line 1, column 5: unknown unit in `roll_rad`: expected `roll_deg`"
        );
        assert_eq!(
            err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,x_ft\n"),
            "f.csv: line 1, column 8: `x_ft` repeats the x column"
        );
        assert_eq!(
            err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0\n"),
            "f.csv: line 2: expected 7 fields as in the header, found 6"
        );
        assert_eq!(
            err("# c\nt_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,abc,0,0,0\n"),
            "f.csv: line 3, column 4 (`z_m`): expected a number, found `abc`"
        );
        assert_eq!(
            err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,NaN,0\n"),
            "f.csv: line 2, column 6 (`pitch_deg`): expected a finite number, found `NaN`"
        );
        assert_eq!(
            err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0,inf\n"),
            "f.csv: line 2, column 7 (`yaw_deg`): expected a finite number, found `inf`"
        );
        assert_eq!(
            err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0.1,0,0,0,0,0,0\n0.1,0,0,0,0,0,0\n"),
            "f.csv: line 3, column 1 (`t_s`): time 0.1 s is not after the previous sample's 0.1 s (times must increase strictly)"
        );
        assert_eq!(
            err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0,\n"),
            "f.csv: line 2, column 7 (`yaw_deg`): expected a number, found ``"
        );
    }

    #[test]
    fn unreadable_file_is_named() {
        let e = Trajectory::read(Path::new("/no/such/file.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("/no/such/file.csv: cannot read:"), "{e}");
    }

    #[test]
    fn spreadsheet_exports_read_and_implausible_values_are_refused_where_they_stand() {
        let bom = format!("\u{feff}{GOOD}");
        assert_eq!(Trajectory::parse(&bom, "f.csv").unwrap().len(), 2);
        let quoted = "\"t_s\",\"x_m\",\"y_m\",\"z_m\",\"roll_deg\",\"pitch_deg\",\"yaw_deg\"\r\n\"0\",0,0,0,0,0,0\r\n";
        assert_eq!(Trajectory::parse(quoted, "f.csv").unwrap().len(), 1);
        assert_eq!(
            err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,\"0,0,0,0,0\n"),
            "f.csv: line 2, column 3: unbalanced double quote in `\"0` (a quoted field must start and end with a quote)"
        );
        assert_eq!(
            err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,1e308,0,0,0,0,0\n"),
            "f.csv: line 2, column 2 (`x_m`): 1e308 is beyond the plausible bound of +-100000 m for a position"
        );
        assert_eq!(
            err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n1e6,0,0,0,0,0,0\n"),
            "f.csv: line 2, column 1 (`t_s`): 1e6 is beyond the plausible bound of +-3600 s for a sample time"
        );
        assert!(
            err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0,4000\n")
                .contains("for an angle")
        );
        let lines = GOOD.split('\n').map(|l| Ok(l.as_bytes().to_vec()));
        assert_eq!(
            Trajectory::parse_lines(lines, "f.csv", 1)
                .unwrap_err()
                .to_string(),
            "f.csv: line 6: more than 1 samples, the limit per event"
        );
        let bad_utf8 = [
            b"t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg".to_vec(),
            vec![0xff, 0xfe],
        ];
        assert_eq!(
            Trajectory::parse_lines(bad_utf8.into_iter().map(Ok), "f.csv", 10)
                .unwrap_err()
                .to_string(),
            "f.csv: line 2: not valid UTF-8 text"
        );
    }
}
