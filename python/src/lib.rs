//! `sepval._native`: the extension module under the Python package `sepval`
//! (python/python/sepval). It runs the commands of the `sepval` command line in this process
//! through the very code the binary runs (`sepval_cli`: the same configuration, the same
//! refusals, the same bits), and reads and checks the inputs Python gives with sepval's own
//! readers. The package turns keyword arguments into a command's words, and the JSON the
//! command writes into result objects; nothing here knows a command's flags.
//!
//! Errors are `SepvalError` with sepval's message (its whole cause chain, as the CLI prints it
//! after `sepval: error:`).

mod call;
mod inputs;

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

pyo3::create_exception!(
    sepval,
    SepvalError,
    pyo3::exceptions::PyException,
    "sepval refused an input or failed; the message is sepval's (file, line, field)."
);

/// An error of sepval as a `SepvalError` carrying its whole cause chain.
fn refused(e: anyhow::Error) -> PyErr {
    SepvalError::new_err(format!("{e:#}"))
}

/// Runs the command of `words` (what follows `sepval` on a command line). `progress`, when
/// given, is called with a dict for each event of progress; `worker` is the `sepval-worker`
/// executable for `--evaluator ipc`. Returns `(stdout, stderr lines)`.
#[pyfunction]
#[pyo3(signature = (words, progress=None, worker=None))]
fn run(
    py: Python<'_>,
    words: Vec<String>,
    progress: Option<Py<PyAny>>,
    worker: Option<PathBuf>,
) -> PyResult<(String, Vec<String>)> {
    let said = call::run(py, words, progress, worker)?;
    Ok((said.out, said.err))
}

/// Reads a telemetry file: a dict of column buffers (float64, little-endian), `metadata` and
/// `comments`.
#[pyfunction]
fn read_telemetry<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let t = py
        .detach(|| sepval_common::telemetry::Trajectory::read(&path))
        .map_err(|e| refused(e.into()))?;
    inputs::columns(py, &t)
}

/// Parses telemetry text (`name` names it in errors) as `read_telemetry` reads a file.
#[pyfunction]
fn parse_telemetry<'py>(py: Python<'py>, text: &str, name: &str) -> PyResult<Bound<'py, PyDict>> {
    let t =
        sepval_common::telemetry::Trajectory::parse(text, name).map_err(|e| refused(e.into()))?;
    inputs::columns(py, &t)
}

/// Checks telemetry texts (each `(text, name)`) and, with `write`, writes each to `dir`,
/// named by its content, once all read; their paths.
#[pyfunction]
fn store_telemetry(
    py: Python<'_>,
    texts: Vec<(String, String)>,
    dir: PathBuf,
    write: bool,
) -> PyResult<Vec<PathBuf>> {
    py.detach(|| inputs::store_telemetry(&texts, &dir, write))
        .map_err(refused)
}

/// J_pos \[m\] and J_att \[deg\] of `sim` against `data`, each `("path", PATH, "")` or
/// `("text", CSV, NAME)`.
#[pyfunction]
fn goals(data: (String, String, String), sim: (String, String, String)) -> PyResult<(f64, f64)> {
    let (data_name, data) = inputs::trajectory(&data).map_err(refused)?;
    let (sim_name, sim) = inputs::trajectory(&sim).map_err(refused)?;
    let g = sepval_cli::command::goals::between((&data_name, &data), (&sim_name, &sim))
        .map_err(refused)?;
    Ok((g.j_pos_m, g.j_att_deg))
}

/// The scenario of `path` (the embedded default without one), as JSON.
#[pyfunction]
#[pyo3(signature = (path=None))]
fn scenario_json(path: Option<PathBuf>) -> PyResult<String> {
    inputs::scenario_json(path.as_deref()).map_err(refused)
}

/// Checks a scenario given as JSON and, with `write`, writes it to `dir` as TOML; its path.
#[pyfunction]
fn store_scenario(json: &str, name: &str, dir: PathBuf, write: bool) -> PyResult<PathBuf> {
    inputs::store_scenario(json, name, &dir, write).map_err(refused)
}

/// Checks a factor set given as JSON against the factor table of the scenario (a file, a dict
/// as JSON, or the embedded default without either) and, with `write`, writes it to `dir`; its
/// path.
#[pyfunction]
#[pyo3(signature = (json, name, dir, write, scenario_path=None, scenario_json=None))]
fn store_factors(
    json: &str,
    name: &str,
    dir: PathBuf,
    write: bool,
    scenario_path: Option<PathBuf>,
    scenario_json: Option<String>,
) -> PyResult<PathBuf> {
    let scenario = match (scenario_path, scenario_json) {
        (Some(p), _) => inputs::ScenarioGiven::File(p),
        (None, Some(j)) => inputs::ScenarioGiven::Dict(j),
        (None, None) => inputs::ScenarioGiven::Default,
    };
    inputs::store_factors(json, name, &scenario, &dir, write).map_err(refused)
}

/// The effect catalogue.
#[pyfunction]
fn effects(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    inputs::effects(py)
}

/// The version of sepval this module was built from.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

/// sepval's commands in this process.
#[pymodule]
mod _native {
    #[pymodule_export]
    use super::{
        SepvalError, effects, goals, parse_telemetry, read_telemetry, run, scenario_json,
        store_factors, store_scenario, store_telemetry, version,
    };

    use pyo3::prelude::*;

    /// The files of an output directory that are its bookkeeping, not outputs: the lock and
    /// the marker.
    #[pymodule_init]
    fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
        use sepval_run::out_dir::{LOCK_FILE, MARKER_FILE};
        m.add("BOOKKEEPING", (LOCK_FILE, MARKER_FILE))
    }
}
