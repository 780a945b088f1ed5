//! Releases of the tests' own generator (`generator.rs`) diagnosed in process (`command.rs`),
//! for the test binaries that discover (included by `#[path]`, beside both, in
//! `diagnose/tests/discovery` and `plan/tests/closing`); the binary's tests diagnose them
//! through `sepval diagnose` (`sepval/tests/cli/plan.rs`).

use std::path::Path;

use sepval_common::scenario::Scenario;
use sepval_common::telemetry::Trajectory;
use serde_json::Value;

use crate::command::Diagnose;
use crate::generator::write;

pub use crate::generator::{default_scenario, release};

/// Writes the releases into `dir` and diagnoses them into `dir/diag`, as `sepval diagnose`
/// with the reduced budget does (the first `fit` of them fitted, the rest given with
/// `--validate`), with `scenario` (the embedded default when `None`); returns diagnosis.json,
/// having checked that the page says its verdict and the increments are drawn.
pub fn diagnose(
    dir: &Path,
    releases: &[Trajectory],
    fit: usize,
    scenario: Option<&Scenario>,
) -> Value {
    let mut flags = Diagnose::of(Vec::new());
    for (flag, name) in write(dir, releases, fit, scenario) {
        let path = dir.join(name);
        match flag {
            "--scenario" => flags.scenario = Some(path),
            "--data" => flags.data.push(path),
            _ => flags.validate.push(path),
        }
    }
    let d = flags.record(&dir.join("diag"));
    let html = std::fs::read_to_string(dir.join("diag/report.html")).unwrap();
    assert!(html.contains(d["verdict"].as_str().unwrap().split(',').next().unwrap()));
    assert!(dir.join("diag/figures/increments.png").exists());
    d
}
