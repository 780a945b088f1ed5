//! The checks every command that reads releases makes on them (issue 33, items 5 to 7): each
//! file screened for outliers (refused or dropped, docs/model.md section 6), each release's
//! recorded store compared with the store fitted, and no release given twice, whatever its
//! file: the same samples at the same flight condition are the same release.

use std::path::Path;

use sepval_common::scenario::{Flight, Scenario};
use sepval_common::telemetry::outliers::{self, CHANNELS, Outlier, Policy};
use sepval_common::telemetry::{Numbered, Trajectory};

use super::error::{InputError, Twice};

/// The outliers named in a message before "and N more".
const NAMED: usize = 5;

/// A release read and screened for outliers, and what the screening left out, in words for
/// the user (`None`: nothing).
#[derive(Debug, Clone)]
pub struct Screened {
    /// The samples kept.
    pub trajectory: Trajectory,
    /// `--outliers drop: left out 3 row(s) of a.csv holding an outlier: ...`.
    pub dropped: Option<String>,
}

impl Screened {
    /// The samples kept, what the screening left out told to `tell`.
    pub fn told(self, tell: super::Tell) -> Trajectory {
        if let Some(said) = self.dropped {
            tell(said);
        }
        self.trajectory
    }
}

/// Reads the telemetry file `path`, screened for outliers by `policy`: refused naming them, or
/// their rows left out.
pub fn read(path: &Path, policy: Policy) -> Result<Screened, InputError> {
    let (numbered, found) = read_screened(path)?;
    screen(path, numbered, &found, &found, policy)
}

/// Reads the telemetry file `path` with the line of each sample and its outliers.
pub fn read_screened(path: &Path) -> Result<(Numbered, Vec<Outlier>), InputError> {
    let numbered = Trajectory::read_numbered(path)?;
    let found = outliers::find(&numbered.trajectory);
    Ok((numbered, found))
}

/// The trajectory of `path` (`numbered`) whose outliers are `found`: refused naming them, or
/// with the rows of `left_out` (its outliers' rows, and maybe others') left out.
pub fn screen(
    path: &Path,
    numbered: Numbered,
    found: &[Outlier],
    left_out: &[Outlier],
    policy: Policy,
) -> Result<Screened, InputError> {
    if left_out.is_empty() {
        return Ok(Screened {
            trajectory: numbered.trajectory,
            dropped: None,
        });
    }
    let file = path.display();
    let named: Vec<String> = found
        .iter()
        .take(NAMED)
        .map(|o| describe(o, numbered.lines[o.sample]))
        .collect();
    let more = match found.len() {
        n if n > NAMED => format!(", and {} more", n - NAMED),
        _ => String::new(),
    };
    match policy {
        Policy::Refuse if !found.is_empty() => Err(InputError::Outliers {
            path: path.to_path_buf(),
            count: found.len(),
            named: format!("{}{more}", named.join("; ")),
        }),
        Policy::Refuse => Ok(Screened {
            trajectory: numbered.trajectory,
            dropped: None,
        }),
        Policy::Drop => {
            let kept = outliers::without(&numbered.trajectory, left_out);
            let dropped = numbered.trajectory.len() - kept.len();
            let said = match found.is_empty() {
                true => format!("--outliers drop: left out {dropped} row(s) of {file}"),
                false => format!(
                    "--outliers drop: left out {dropped} row(s) of {file} holding an outlier: {}{more}",
                    named.join("; ")
                ),
            };
            Ok(Screened {
                trajectory: kept,
                dropped: Some(said),
            })
        }
    }
}

/// `line 60, z_m = 10.57 m, 10 m from the trend (threshold 0.5 m)`.
fn describe(o: &Outlier, line: usize) -> String {
    let unit = o.unit();
    format!(
        "line {line}, {} = {} {unit}, {:.3} {unit} from the trend (threshold {} {unit})",
        CHANNELS[o.channel],
        sepval_core::number_text::Shown(o.value),
        o.departure,
        o.threshold
    )
}

/// Refuses a release whose metadata records another store than `base`'s: any `[store]` field
/// given as `# store.mass_kg = 500` (or `# mass_kg = 500`) must agree with the scenario within
/// one part in a million. The fields compared and the message are predict's
/// ([`Scenario::store_difference`]).
pub fn check_store(
    base: &Scenario,
    data: &Trajectory,
    name: &str,
    base_name: &str,
) -> Result<(), InputError> {
    let mut recorded = base.clone();
    for (field, value) in recorded.store.fields_mut() {
        let key = format!("store.{field}");
        let Some((key, text)) = data
            .meta(&key)
            .map(|t| (key.as_str(), t))
            .or_else(|| data.meta(field).map(|t| (field, t)))
        else {
            continue;
        };
        let Ok(v) = text.parse::<f64>() else {
            return Err(InputError::Metadata {
                release: name.to_string(),
                key: key.to_string(),
                text: text.to_string(),
            });
        };
        if (v - *value).abs() > 1e-6 * value.abs().max(v.abs()) || !v.is_finite() {
            *value = v;
        }
    }
    match base.store_difference(&recorded) {
        Some(difference) => Err(InputError::OtherStore {
            release: name.to_string(),
            fitted: base_name.to_string(),
            difference,
        }),
        None => Ok(()),
    }
}

/// One release as the duplicate check sees it.
pub struct Release<'a> {
    /// How it was given (`--data a.csv`, `--validate b.csv`, `the data fitted (...)`).
    pub given: String,
    /// Its samples.
    pub data: &'a Trajectory,
    /// Its flight condition.
    pub flight: &'a Flight,
}

/// Whether two releases are the same: the same samples bit for bit at the same flight
/// condition, whatever their files' names, comments and other metadata.
fn same(a: &Release, b: &Release) -> bool {
    fn bits<'a>(x: impl Iterator<Item = &'a f64>, y: impl Iterator<Item = &'a f64>) -> bool {
        x.zip(y).all(|(u, v)| u.to_bits() == v.to_bits())
    }
    let (x, y) = (a.data, b.data);
    let flight = |f: &Flight| [f.mach, f.altitude_m, f.alpha_deg, f.beta_deg, f.gamma_deg];
    x.len() == y.len()
        && bits(flight(a.flight).iter(), flight(b.flight).iter())
        && bits(x.times_s.iter(), y.times_s.iter())
        && bits(x.pos_m.iter().flatten(), y.pos_m.iter().flatten())
        && bits(x.att_deg.iter().flatten(), y.att_deg.iter().flatten())
}

/// Refuses `new` when it is one of `earlier`, naming both; `why` ends the message.
pub fn refuse_twice(earlier: &[Release], new: &Release, why: Twice) -> Result<(), InputError> {
    match earlier.iter().find(|e| same(e, new)) {
        Some(e) => Err(InputError::SameSamples {
            given: new.given.clone(),
            earlier: e.given.clone(),
            why,
        }),
        None => Ok(()),
    }
}

/// Refuses a release given twice among `releases`, naming both.
pub fn refuse_duplicates(releases: &[Release]) -> Result<(), InputError> {
    for (i, r) in releases.iter().enumerate() {
        refuse_twice(&releases[..i], r, Twice::GivenTwice)?;
    }
    Ok(())
}
