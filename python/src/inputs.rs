//! Inputs given from Python, read and checked by sepval's own readers so that bad input is
//! refused with the CLI's messages (file or name, line, column, field): telemetry (a file, or
//! the CSV text the package makes of a DataFrame or a dict of arrays), scenarios and factor sets
//! (dicts, carried as JSON), and the store where those given as values are written for the
//! commands, which take files (and record their paths, which `predict` and `plan` read again).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};
use sepval_common::scenario::{Scenario, hex_sha256};
use sepval_common::telemetry::Trajectory;
use sepval_core::atomic_file::write_atomically;
use sepval_core::factors::Factors;

/// A trajectory as the package receives it: one little-endian float64 buffer per column
/// (`t_s`, `x_m`, `y_m`, `z_m`, `roll_deg`, `pitch_deg`, `yaw_deg`), the `# key = value`
/// metadata in file order, and every comment line.
pub fn columns<'py>(py: Python<'py>, t: &Trajectory) -> PyResult<Bound<'py, PyDict>> {
    let bytes = |values: &mut dyn Iterator<Item = f64>| -> Vec<u8> {
        values.flat_map(f64::to_le_bytes).collect()
    };
    let d = PyDict::new(py);
    d.set_item(
        "t_s",
        PyBytes::new(py, &bytes(&mut t.times_s.iter().copied())),
    )?;
    for (k, name) in ["x_m", "y_m", "z_m"].into_iter().enumerate() {
        let v = bytes(&mut t.pos_m.iter().map(|p| p[k]));
        d.set_item(name, PyBytes::new(py, &v))?;
    }
    for (k, name) in ["roll_deg", "pitch_deg", "yaw_deg"].into_iter().enumerate() {
        let v = bytes(&mut t.att_deg.iter().map(|a| a[k]));
        d.set_item(name, PyBytes::new(py, &v))?;
    }
    d.set_item("metadata", PyList::new(py, &t.metadata)?)?;
    d.set_item("comments", PyList::new(py, &t.comments)?)?;
    Ok(d)
}

/// A trajectory given from Python: `("path", PATH)` or `("text", CSV, NAME)`, NAME naming it
/// in errors.
pub fn trajectory(source: &(String, String, String)) -> Result<(String, Trajectory)> {
    let (kind, value, name) = source;
    match kind.as_str() {
        "path" => Ok((value.clone(), Trajectory::read(Path::new(value))?)),
        "text" => Ok((name.clone(), Trajectory::parse(value, name)?)),
        other => Err(anyhow!("unknown kind of telemetry source `{other}`")),
    }
}

/// Telemetry texts (each with the name that errors use) checked, then each written to `dir` as
/// a telemetry file named by its content, `data-SHA256.csv` (sepval's own format: what reads
/// back is the same doubles); their paths. Nothing is written unless every text reads, nor
/// without `write` (a check: the paths they would have).
pub fn store_telemetry(
    texts: &[(String, String)],
    dir: &Path,
    write: bool,
) -> Result<Vec<PathBuf>> {
    let read: Vec<Trajectory> = texts
        .iter()
        .map(|(text, name)| Trajectory::parse(text, name))
        .collect::<Result<_, _>>()?;
    read.iter()
        .map(|t| store(dir, "data", "csv", t.to_csv_string().as_bytes(), write))
        .collect()
}

/// The scenario of `path` (the embedded default without one) as JSON of the TOML that `sepval
/// scenario` writes.
pub fn scenario_json(path: Option<&Path>) -> Result<String> {
    let scenario = sepval_run::inputs::scenario(path, None)?;
    let text = sepval_cli::command::scenario::toml_text(&scenario);
    let value: toml::Value = toml::from_str(&text).context("the scenario's TOML reads back")?;
    Ok(serde_json::to_string(&value)?)
}

/// A scenario given as a dict (carried as JSON, non-finite floats as strings marked by
/// [`NONFINITE`]), checked as `sepval` checks a scenario file (`name` names it in errors), and
/// written to `dir` as `scenario-SHA256.toml` (with `write`); its path.
pub fn store_scenario(json: &str, name: &str, dir: &Path, write: bool) -> Result<PathBuf> {
    let scenario = scenario_of_json(json, name)?;
    let canonical = sepval_cli::command::scenario::toml_text(&scenario);
    store(dir, "scenario", "toml", canonical.as_bytes(), write)
}

/// The scenario of a dict carried as JSON, checked.
fn scenario_of_json(json: &str, name: &str) -> Result<Scenario> {
    let value: serde_json::Value =
        serde_json::from_str(json).with_context(|| format!("scenario {name}: not a scenario"))?;
    let toml::Value::Table(table) = toml_value(value, "", name)? else {
        bail!("scenario {name}: expected a dict of the scenario's sections");
    };
    let text = toml::to_string(&table)
        .with_context(|| format!("scenario {name}: cannot be written as TOML"))?;
    Ok(Scenario::from_toml_str(&text, name)?)
}

/// The mark of a float JSON cannot carry (`nan`, `inf`, `-inf` follow it).
const NONFINITE: &str = "__sepval_nonfinite__:";

/// A JSON value of the scenario `name` as TOML (`at` says where it is, for errors, as the
/// scenario's own messages say it: `flight.mach`).
fn toml_value(v: serde_json::Value, at: &str, name: &str) -> Result<toml::Value> {
    use serde_json::Value as J;
    use toml::Value as T;
    let here = || format!("scenario {name}: `{at}`");
    Ok(match v {
        J::Null => bail!("{}: None, where the scenario needs a value", here()),
        J::Bool(b) => T::Boolean(b),
        J::Number(n) => match n.as_i64() {
            Some(i) => T::Integer(i),
            None => T::Float(n.as_f64().with_context(|| format!("{} = {n}", here()))?),
        },
        J::String(s) => match s.strip_prefix(NONFINITE) {
            Some(x) => T::Float(x.parse().with_context(|| format!("{} = {x}", here()))?),
            None => T::String(s),
        },
        J::Array(items) => T::Array(
            items
                .into_iter()
                .enumerate()
                .map(|(k, v)| toml_value(v, &format!("{at}[{k}]"), name))
                .collect::<Result<_>>()?,
        ),
        J::Object(fields) => T::Table(
            fields
                .into_iter()
                .map(|(k, v)| {
                    let path = if at.is_empty() {
                        k.clone()
                    } else {
                        format!("{at}.{k}")
                    };
                    let inner = toml_value(v, &path, name)?;
                    Ok((k, inner))
                })
                .collect::<Result<_>>()?,
        ),
    })
}

/// Where the scenario of a factor set is: a file, a dict carried as JSON (`(a dict)` in
/// errors), or the embedded default.
pub enum ScenarioGiven {
    /// A scenario file.
    File(PathBuf),
    /// A dict, as JSON.
    Dict(String),
    /// The embedded default.
    Default,
}

/// A factor set given as a dict (carried as JSON), checked against the factor table of the
/// scenario as `--factors FILE.json` is, and written to `dir` as `factors-SHA256.json` (with
/// `write`); its path.
pub fn store_factors(
    json: &str,
    name: &str,
    scenario: &ScenarioGiven,
    dir: &Path,
    write: bool,
) -> Result<PathBuf> {
    let s = match scenario {
        ScenarioGiven::File(p) => sepval_run::inputs::scenario(Some(p), None)?,
        ScenarioGiven::Dict(j) => scenario_of_json(j, "(a dict)")?,
        ScenarioGiven::Default => Scenario::embedded_default(),
    };
    Factors::from_json_str(json, &s.factors).with_context(|| format!("factors {name}"))?;
    store(dir, "factors", "json", json.as_bytes(), write)
}

/// Writes `bytes` to `dir/KIND-SHA256.EXT` unless that file is already there (or `write` is
/// false); its path.
fn store(dir: &Path, kind: &str, ext: &str, bytes: &[u8], write: bool) -> Result<PathBuf> {
    let path = dir.join(format!("{kind}-{}.{ext}", hex_sha256(bytes)));
    if !write {
        return Ok(path);
    }
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let same = std::fs::read(&path).is_ok_and(|held| held == bytes);
    if !same {
        write_atomically(&path, bytes)?;
    }
    Ok(path)
}

/// The effect catalogue: id, what it adds, and its parameters (name, unit, neutral value,
/// fit range), as `sepval effects` lists it.
pub fn effects<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
    let list = PyList::empty(py);
    for e in sepval_common::effects::CATALOGUE.iter() {
        let d = PyDict::new(py);
        d.set_item("id", e.id())?;
        d.set_item("adds", e.adds())?;
        let params = PyList::empty(py);
        for p in e.params() {
            let q = PyDict::new(py);
            q.set_item("name", p.name)?;
            q.set_item("unit", p.unit)?;
            q.set_item("neutral", p.neutral)?;
            q.set_item("min", p.min)?;
            q.set_item("max", p.max)?;
            params.append(q)?;
        }
        d.set_item("params", params)?;
        list.append(d)?;
    }
    Ok(list)
}
