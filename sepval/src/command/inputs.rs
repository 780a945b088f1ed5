//! Reading the inputs the flags name (scenario, factors, effects, data files) into validated
//! values, with errors that name the file and the problem.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use sepval_common::effects::EffectSet;
use sepval_common::evaluation::{Event, Job};
use sepval_common::factors::{FactorTable, Factors};
use sepval_common::scenario::Scenario;
use sepval_common::synthetic::default_flight_test;
use sepval_common::telemetry::Trajectory;
use sepval_common::telemetry::outliers::Policy;
use sepval_predict::{Source, read_source};

use super::releases::{self, Release};

/// The scenario of `--scenario FILE`, or the embedded default, extended by the terms of
/// `--extension FILE` (docs/discovery.md).
pub fn scenario(path: Option<&Path>, extension: Option<&Path>) -> Result<Scenario> {
    let mut s = match path {
        Some(p) => Scenario::load(p)?,
        None => Scenario::embedded_default(),
    };
    if let Some(e) = extension {
        let terms = sepval_common::extension::load_extension(e)?;
        s.extension
            .extend(terms.iter().map(sepval_common::extension::TermRecord::of));
        s.validate(&format!(
            "{} extended by {}",
            scenario_name(path),
            e.display()
        ))?;
    }
    Ok(s)
}

/// The factors of `--factors truth|nominal|FILE.json`, checked against `table`.
pub fn factors(spec: &str, table: &FactorTable) -> Result<Factors> {
    let factors = match spec {
        "truth" => Factors::TRUTH,
        "nominal" => Factors::NOMINAL,
        path => {
            let text = sepval_common::input_file::read_string(
                Path::new(path),
                "factors file",
                sepval_common::limits::MAX_JSON_BYTES,
            )?;
            return Factors::from_json_str(&text, table)
                .with_context(|| format!("factors file {path}"));
        }
    };
    table
        .check(&factors)
        .with_context(|| format!("the {spec} factors do not fit this scenario's factor table"))?;
    Ok(factors)
}

/// The effects of repeated `--effect ID=V1,V2,...` flags.
pub fn effects(specs: &[String]) -> Result<EffectSet> {
    let mut set = EffectSet::NONE;
    for spec in specs {
        set.push_spec(spec)
            .with_context(|| format!("--effect {spec}"))?;
    }
    Ok(set)
}

/// The measured data of `--data FILE` (several allowed), each screened for outliers by
/// `policy`, or the embedded default synthetic flight test when none is given.
pub fn data(paths: &[std::path::PathBuf], policy: Policy) -> Result<Vec<Trajectory>> {
    if paths.is_empty() {
        return Ok(vec![default_flight_test()]);
    }
    paths.iter().map(|p| releases::read(p, policy)).collect()
}

/// `paths`, each to be read with `policy`.
pub fn with_policy(
    paths: &[std::path::PathBuf],
    policy: Policy,
) -> Vec<(std::path::PathBuf, Policy)> {
    paths.iter().map(|p| (p.clone(), policy)).collect()
}

/// The job of a fit: each data file (or the embedded default flight test) with the scenario,
/// screened for outliers by `policy`, each release once and of the store fitted, and the record
/// of where they came from.
pub fn job(
    data_paths: &[std::path::PathBuf],
    scenario_path: Option<&Path>,
    extension_path: Option<&Path>,
    policy: Policy,
) -> Result<(
    sepval_common::evaluation::Job,
    sepval_fit::checkpoint::InputsRecord,
)> {
    use sepval_common::evaluation::{Event, Job};
    use sepval_common::simulation::Simulator;
    // Each release once: the same file given twice would count its samples twice.
    let absolute = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    for (i, p) in data_paths.iter().enumerate() {
        if let Some(q) = data_paths[..i].iter().find(|q| absolute(q) == absolute(p)) {
            bail!(
                "--data {} is the same file as --data {}: give each release once",
                p.display(),
                q.display()
            );
        }
    }
    let scen = scenario(scenario_path, extension_path)?;
    let data = data(data_paths, policy)?;
    let names: Vec<String> = if data_paths.is_empty() {
        vec!["embedded default synthetic flight test".to_string()]
    } else {
        data_paths.iter().map(|p| p.display().to_string()).collect()
    };
    let mut scenarios = Vec::with_capacity(data.len());
    for (name, data) in names.iter().zip(&data) {
        let scenario = event_scenario(&scen, data, name)?;
        releases::check_store(&scen, data, name, &scenario_name(scenario_path))?;
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
    releases::refuse_duplicates(&given)?;
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
    let record = sepval_fit::checkpoint::InputsRecord {
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
    base: &sepval_common::scenario::Scenario,
    data: &Trajectory,
    name: &str,
) -> Result<sepval_common::scenario::Scenario> {
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
            *field = text
                .parse()
                .with_context(|| format!("{name}: metadata `# {key} = {text}` is not a number"))?;
        }
    }
    s.validate(&format!("{name} (flight condition from its metadata)"))?;
    Ok(s)
}

/// The events of `--validate FILE` (none: `None`), each with the outlier policy it is read
/// with, read like `--data` with the same scenario and extension; a release given both to fit
/// and to validate is refused, as is one given twice to validate: the same file by its path, a
/// copy by its samples and condition (`fitted`, the job of the `--data` files, holds theirs).
pub fn validation_job(
    held: &[(std::path::PathBuf, Policy)],
    data_paths: &[std::path::PathBuf],
    fitted: &sepval_common::evaluation::Job,
    scenario_path: Option<&Path>,
    extension_path: Option<&Path>,
) -> Result<Option<sepval_common::evaluation::Job>> {
    use sepval_common::evaluation::{Event, Job};
    use sepval_common::simulation::Simulator;
    if held.is_empty() {
        return Ok(None);
    }
    let absolute = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    for (i, (p, _)) in held.iter().enumerate() {
        if let Some(q) = data_paths.iter().find(|q| absolute(q) == absolute(p)) {
            bail!(
                "--validate {} is the same file as --data {}: a release used for fitting cannot measure prediction",
                p.display(),
                q.display()
            );
        }
        if let Some((q, _)) = held[..i].iter().find(|(q, _)| absolute(q) == absolute(p)) {
            bail!(
                "--validate {} is the same file as --validate {}: give each release once",
                p.display(),
                q.display()
            );
        }
    }
    let scen = scenario(scenario_path, extension_path)?;
    let fitted_releases: Vec<Release> = fitted
        .events()
        .iter()
        .map(|e| Release {
            given: match data_paths.is_empty() {
                true => format!("the data fitted ({})", e.name),
                false => format!("--data {}", e.name),
            },
            data: &e.data,
            flight: &e.simulator.scenario().flight,
        })
        .collect();
    let mut read = Vec::with_capacity(held.len());
    for (p, policy) in held {
        let name = p.display().to_string();
        let data = releases::read(p, *policy).with_context(|| format!("--validate {name}"))?;
        let scenario = event_scenario(&scen, &data, &name)?;
        releases::check_store(&scen, &data, &name, &scenario_name(scenario_path))?;
        read.push((name, data, scenario));
    }
    let validating: Vec<Release> = read
        .iter()
        .map(|(name, data, s)| Release {
            given: format!("--validate {name}"),
            data,
            flight: &s.flight,
        })
        .collect();
    for (i, r) in validating.iter().enumerate() {
        releases::refuse_twice(
            &fitted_releases,
            r,
            "a release used for fitting cannot measure prediction",
        )?;
        releases::refuse_twice(&validating[..i], r, "give each release once")?;
    }
    let events: Vec<Event> = read
        .into_iter()
        .map(|(name, data, scenario)| Event {
            name,
            simulator: Simulator::new(&scenario),
            data,
        })
        .collect();
    Ok(Some(Job::new(events)?))
}

/// The baseline fit of a diagnosis or an update ([`sepval_fit::FitOptions::baseline`]),
/// written to `out`/baseline.
pub fn baseline_fit(
    ga: sepval_solve::ga::GaSettings,
    sigma: sepval_fit::sigma::Sigma,
    lm: &sepval_solve::lm::LmSettings,
    out: &Path,
    inputs: sepval_fit::checkpoint::InputsRecord,
) -> sepval_fit::FitOptions {
    sepval_fit::FitOptions::baseline(ga, sigma, lm, &out.join("baseline"), inputs)
}

/// The source of `--from` read and checked, the releases it was fitted to, and the releases held
/// out (`--validate`, read with `policy`, then those the source records, read as its fit read
/// its data).
pub fn source_inputs(
    from: &Path,
    extension: Option<&Path>,
    validate: &[PathBuf],
    policy: sepval_common::telemetry::outliers::Policy,
) -> Result<(Source, Job, Vec<Event>)> {
    let source = read_source(from)?;
    let record = source.inputs.clone();
    let extension = extension
        .map(Path::to_path_buf)
        .or(record.extension.clone());
    let (fitted, _) = job(
        &record.data,
        record.scenario.as_deref(),
        extension.as_deref(),
        record.outliers,
    )
    .with_context(|| format!("--from {}: the releases it was fitted to", from.display()))?;
    let mut held = with_policy(validate, policy);
    let recorded = source
        .held_out
        .iter()
        .filter(|p| !validate.contains(p))
        .map(|p| (p.clone(), record.outliers));
    held.extend(recorded.collect::<Vec<_>>());
    let held_out: Vec<Event> = validation_job(
        &held,
        &record.data,
        &fitted,
        record.scenario.as_deref(),
        extension.as_deref(),
    )?
    .map(|j| j.events().to_vec())
    .unwrap_or_default();
    Ok((source, fitted, held_out))
}
