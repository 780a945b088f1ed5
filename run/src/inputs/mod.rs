//! What a run reads, read into validated values: the scenario (extended by an extension
//! file), the factors and effects named, and the releases, each screened for outliers
//! ([`screen`]), flown at the condition its metadata records, of the store fitted and given
//! once, made into the [`Job`] every evaluator runs and the [`InputsRecord`] that a fit's
//! record keeps of where they came from.
//!
//! Every command that reads releases (fit, diagnose, plan, predict, envelope, update,
//! campaign, rerun, bench) reads them here, so that each refuses the same input with the same
//! message ([`InputError`], naming the flag and file). Nothing is printed: what the screening
//! leaves out is told through the `tell` callback.

pub mod error;
mod recorded;
pub mod screen;

use std::path::{Path, PathBuf};

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::{Event, Job};
use sepval_common::extension::{TermRecord, load_extension};
use sepval_common::scenario::Scenario;
use sepval_common::simulation::Simulator;
use sepval_common::synthetic::default_flight_test;
use sepval_common::telemetry::Trajectory;
use sepval_common::telemetry::outliers::Policy;
use sepval_core::factors::{FactorTable, Factors};

pub use error::{InputError, Twice};
pub use screen::{Release, Screened, check_store, read_screened, refuse_duplicates, refuse_twice};

pub use recorded::InputsRecord;

/// The job of the releases a record (`--from DIR`) was made from, read again as they were
/// read then (its data, scenario, extension and outliers policy).
pub fn recorded_job(record: &InputsRecord, tell: Tell) -> Result<Job, InputError> {
    let InputsRecord {
        data,
        scenario,
        extension,
        outliers,
    } = record;
    let (job, _) = job(
        data,
        scenario.as_deref(),
        extension.as_deref(),
        *outliers,
        tell,
    )?;
    Ok(job)
}

/// Where the words of the reading go (`--outliers drop: left out ...`).
pub type Tell<'a> = &'a mut dyn FnMut(String);

/// The scenario of `--scenario FILE`, or the embedded default, extended by the terms of
/// `--extension FILE` (docs/discovery.md).
pub fn scenario(path: Option<&Path>, extension: Option<&Path>) -> Result<Scenario, InputError> {
    let mut s = match path {
        Some(p) => Scenario::load(p)?,
        None => Scenario::embedded_default(),
    };
    if let Some(e) = extension {
        let terms = load_extension(e)?;
        s.extension.extend(terms.iter().map(TermRecord::of));
        s.validate(&format!(
            "{} extended by {}",
            scenario_name(path),
            e.display()
        ))?;
    }
    Ok(s)
}

/// The file `--factors` names, if it names one rather than `truth` or `nominal`.
pub fn factors_file(spec: &str) -> Option<&Path> {
    (!matches!(spec, "truth" | "nominal")).then(|| Path::new(spec))
}

/// The factors of `--factors truth|nominal|FILE.json`, checked against `table`.
pub fn factors(spec: &str, table: &FactorTable) -> Result<Factors, InputError> {
    if let Some(path) = factors_file(spec) {
        let text = sepval_core::input_file::read_string(
            path,
            "factors file",
            sepval_core::limits::MAX_JSON_BYTES,
        )?;
        return Factors::from_json_str(&text, table).map_err(|source| InputError::FactorsFile {
            path: spec.to_string(),
            source,
        });
    }
    let factors = if spec == "truth" {
        Factors::TRUTH
    } else {
        Factors::NOMINAL
    };
    table
        .check(&factors)
        .map_err(|source| InputError::FactorsTable {
            name: spec.to_string(),
            source,
        })?;
    Ok(factors)
}

/// The effects of repeated `--effect ID=V1,V2,...` flags.
pub fn effects(specs: &[String]) -> Result<EffectSet, InputError> {
    effects_of("--effect", specs)
}

/// [`effects`] given with `flag` (`--truth-effect`), which its errors name.
pub fn effects_of(flag: &'static str, specs: &[String]) -> Result<EffectSet, InputError> {
    let mut set = EffectSet::NONE;
    for spec in specs {
        set.push_spec(spec).map_err(|source| InputError::Effect {
            flag,
            spec: spec.clone(),
            source,
        })?;
    }
    Ok(set)
}

/// Reads the release `path` screened by `policy`, telling what the screening left out.
pub fn read(path: &Path, policy: Policy, tell: Tell) -> Result<Trajectory, InputError> {
    Ok(screen::read(path, policy)?.told(tell))
}

/// `paths`, each to be read with `policy`.
pub fn with_policy(paths: &[PathBuf], policy: Policy) -> Vec<(PathBuf, Policy)> {
    paths.iter().map(|p| (p.clone(), policy)).collect()
}

/// The path as the file system resolves it (itself when it cannot be resolved).
fn absolute(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf())
}

/// The job of a fit: each data file (or the embedded default flight test) with the scenario,
/// screened for outliers by `policy`, each release once and of the store fitted, and the record
/// of where they came from.
pub fn job(
    data_paths: &[PathBuf],
    scenario_path: Option<&Path>,
    extension_path: Option<&Path>,
    policy: Policy,
    tell: Tell,
) -> Result<(Job, InputsRecord), InputError> {
    // Each release once: the same file given twice would count its samples twice.
    for (i, p) in data_paths.iter().enumerate() {
        if let Some(q) = data_paths[..i].iter().find(|q| absolute(q) == absolute(p)) {
            return Err(InputError::SameFile {
                flag: "--data",
                path: p.clone(),
                earlier_flag: "--data",
                earlier: q.clone(),
                why: Twice::GivenTwice,
            });
        }
    }
    let scen = scenario(scenario_path, extension_path)?;
    let data: Vec<Trajectory> = match data_paths.is_empty() {
        true => vec![default_flight_test()],
        false => data_paths
            .iter()
            .map(|p| read(p, policy, tell))
            .collect::<Result<_, _>>()?,
    };
    let names: Vec<String> = match data_paths.is_empty() {
        true => vec!["embedded default synthetic flight test".to_string()],
        false => data_paths.iter().map(|p| p.display().to_string()).collect(),
    };
    let mut scenarios = Vec::with_capacity(data.len());
    for (name, data) in names.iter().zip(&data) {
        let scenario = event_scenario(&scen, data, name)?;
        check_store(&scen, data, name, &scenario_name(scenario_path))?;
        scenarios.push(scenario);
    }
    let given: Vec<Release> = names
        .iter()
        .zip(&data)
        .zip(&scenarios)
        .map(|((name, data), s)| Release {
            given: format!("--data {name}"),
            data,
            flight: &s.flight,
        })
        .collect();
    refuse_duplicates(&given)?;
    let events = names
        .into_iter()
        .zip(data)
        .zip(&scenarios)
        .map(|((name, data), scenario)| Event {
            name,
            simulator: Simulator::new(scenario),
            data,
        })
        .collect();
    let record = InputsRecord {
        data: data_paths.iter().map(|p| absolute(p)).collect(),
        scenario: scenario_path.map(absolute),
        extension: extension_path.map(absolute),
        outliers: policy,
    };
    Ok((Job::new(events)?, record))
}

/// How messages name the scenario fitted: its file, or the embedded default.
pub fn scenario_name(path: Option<&Path>) -> String {
    match path {
        Some(p) => format!("scenario {}", p.display()),
        None => "the embedded default scenario".to_string(),
    }
}

/// The scenario of one event: `base` with the flight condition named in the data's `#`
/// metadata (`mach`, `altitude_m`, `alpha_deg`, `beta_deg`, `gamma_deg`; any subset), so that
/// releases of the same store at different conditions can be fitted together.
pub fn event_scenario(
    base: &Scenario,
    data: &Trajectory,
    name: &str,
) -> Result<Scenario, InputError> {
    let mut s = base.clone();
    let f = &mut s.flight;
    for (key, field) in [
        ("mach", &mut f.mach),
        ("altitude_m", &mut f.altitude_m),
        ("alpha_deg", &mut f.alpha_deg),
        ("beta_deg", &mut f.beta_deg),
        ("gamma_deg", &mut f.gamma_deg),
    ] {
        if let Some(text) = data.meta(key) {
            *field = text.parse().map_err(|_| InputError::Metadata {
                release: name.to_string(),
                key: key.to_string(),
                text: text.to_string(),
            })?;
        }
    }
    s.validate(&format!("{name} (flight condition from its metadata)"))?;
    Ok(s)
}

/// What a run holds out to validate: the releases to read, each with the outlier policy it is
/// read with, and what they are checked against.
pub struct HeldOut<'a> {
    /// The releases held out, each with its policy.
    pub held: &'a [(PathBuf, Policy)],
    /// The files of the releases fitted (`--data`; none: the embedded default).
    pub data_paths: &'a [PathBuf],
    /// The job of the releases fitted.
    pub fitted: &'a Job,
    /// The scenario fitted (`None`: the embedded default).
    pub scenario_path: Option<&'a Path>,
    /// The extension fitted.
    pub extension_path: Option<&'a Path>,
}

/// The events of `--validate FILE` (none: `None`), read like `--data` with the same scenario
/// and extension; a release given both to fit and to validate is refused, as is one given twice
/// to validate: the same file by its path, a copy by its samples and condition.
pub fn validation_job(h: &HeldOut, tell: Tell) -> Result<Option<Job>, InputError> {
    if h.held.is_empty() {
        return Ok(None);
    }
    for (i, (p, _)) in h.held.iter().enumerate() {
        let earlier = |flag, q: &PathBuf, why| InputError::SameFile {
            flag: "--validate",
            path: p.clone(),
            earlier_flag: flag,
            earlier: q.clone(),
            why,
        };
        if let Some(q) = h.data_paths.iter().find(|q| absolute(q) == absolute(p)) {
            return Err(earlier("--data", q, Twice::Fitted));
        }
        if let Some((q, _)) = h.held[..i].iter().find(|(q, _)| absolute(q) == absolute(p)) {
            return Err(earlier("--validate", q, Twice::GivenTwice));
        }
    }
    let scen = scenario(h.scenario_path, h.extension_path)?;
    let fitted_releases: Vec<Release> = h
        .fitted
        .events()
        .iter()
        .map(|e| Release {
            given: match h.data_paths.is_empty() {
                true => format!("the data fitted ({})", e.name),
                false => format!("--data {}", e.name),
            },
            data: &e.data,
            flight: &e.simulator.scenario().flight,
        })
        .collect();
    let mut held_read = Vec::with_capacity(h.held.len());
    for (p, policy) in h.held {
        let name = p.display().to_string();
        let data = read(p, *policy, tell).map_err(|e| e.given(format!("--validate {name}")))?;
        let scenario = event_scenario(&scen, &data, &name)?;
        check_store(&scen, &data, &name, &scenario_name(h.scenario_path))?;
        held_read.push((name, data, scenario));
    }
    let validating: Vec<Release> = held_read
        .iter()
        .map(|(name, data, s)| Release {
            given: format!("--validate {name}"),
            data,
            flight: &s.flight,
        })
        .collect();
    for (i, r) in validating.iter().enumerate() {
        refuse_twice(&fitted_releases, r, Twice::Fitted)?;
        refuse_twice(&validating[..i], r, Twice::GivenTwice)?;
    }
    let events: Vec<Event> = held_read
        .into_iter()
        .map(|(name, data, scenario)| Event {
            name,
            simulator: Simulator::new(&scenario),
            data,
        })
        .collect();
    Ok(Some(Job::new(events)?))
}

/// The releases of a command that fits them before it works (diagnose, update): those fitted
/// (`--data`; none: the embedded default) and those held out (`--validate`), each read with
/// one policy against the same scenario and extension.
#[derive(Debug, Clone, Copy)]
pub struct Releases<'a> {
    /// `--data`.
    pub data: &'a [PathBuf],
    /// `--validate`.
    pub validate: &'a [PathBuf],
    /// `--scenario`.
    pub scenario: Option<&'a Path>,
    /// `--extension`.
    pub extension: Option<&'a Path>,
    /// `--outliers`.
    pub policy: Policy,
}

/// [`Releases`] read and checked.
#[derive(Debug)]
pub struct ReadReleases {
    /// The releases fitted.
    pub job: Job,
    /// Where they came from, as the fit's record keeps it.
    pub record: InputsRecord,
    /// The releases held out, if any.
    pub validation: Option<Job>,
}

impl Releases<'_> {
    /// Reads the releases fitted ([`job`]) and those held out ([`validation_job`]).
    pub fn read(&self, tell: Tell) -> Result<ReadReleases, InputError> {
        let (job, record) = job(self.data, self.scenario, self.extension, self.policy, tell)?;
        let held = with_policy(self.validate, self.policy);
        let held_out = HeldOut {
            held: &held,
            data_paths: self.data,
            fitted: &job,
            scenario_path: self.scenario,
            extension_path: self.extension,
        };
        let validation = validation_job(&held_out, tell)?;
        Ok(ReadReleases {
            job,
            record,
            validation,
        })
    }
}
