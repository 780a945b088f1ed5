//! `sepval diagnose` through the binary: one catalogue effect hidden in flight data end to end
//! (the sweep over every effect runs in process, `diagnose/tests/catalogue`), a baseline that
//! cannot fit (its summary on stdout says so first), and tables left, warned of on stderr and
//! refused with `--strict-tables`. A full term budget and the public CFD trajectory are
//! diagnosed in process (`diagnose/tests/discovery`). Reduced search budgets; release build.

use std::path::Path;

use sepval_tests::{REDUCED_BUDGET, ok, refused, sepval};
use serde_json::Value;

/// Factors of the base model of these tests (not the default truth).
const BASE: &str = r#"{"fwdfac": 0.45, "aftfac": 0.65, "xinerfac": 0.98, "yinerfac": 1.03,
 "zinerfac": 0.97, "caoff": -0.02, "cyoff": 0.04, "czoff": -0.06, "cmoff": 0.1, "cnoff": -0.08,
 "cloff": -0.05, "caintfac": 1.1, "cyintfac": 1.4, "czintfac": 0.9, "cmintfac": 1.3,
 "cnintfac": 0.8, "clintfac": 1.6}"#;

/// Simulates flight data on the base with `effects` and `seed`, diagnoses it, returns the
/// diagnosis.
fn diagnose_hidden(effects: &[&str], seed: &str) -> Value {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("base.json"), BASE).unwrap();
    let mut sim = vec![
        "simulate",
        "--factors",
        "base.json",
        "--noise-seed",
        seed,
        "--out",
        "d.csv",
    ];
    for e in effects {
        sim.extend(["--effect", e]);
    }
    ok(&sepval(&sim, dir.path()));
    let head = ["diagnose", "--data", "d.csv"];
    let args = [&head[..], &REDUCED_BUDGET, &["--out", "diag"]].concat();
    ok(&sepval(&args, dir.path()));
    let d: Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("diag/diagnosis.json")).unwrap(),
    )
    .unwrap();
    let html = std::fs::read_to_string(dir.path().join("diag/report.html")).unwrap();
    assert!(html.contains(d["verdict"].as_str().unwrap().split(',').next().unwrap()));
    assert!(
        dir.path()
            .join("diag/figures/residuals_event1.png")
            .exists()
    );
    d
}

fn causes(d: &Value) -> Vec<String> {
    d["causes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap().to_string())
        .collect()
}

fn named_first(effect: &str) {
    let id = effect.split('=').next().unwrap();
    let d = diagnose_hidden(&[effect], "5");
    let c = causes(&d);
    assert_eq!(
        c.first().map(String::as_str),
        Some(id),
        "{effect}: {}",
        d["verdict"]
    );
    assert_eq!(d["explained"], true, "{effect}: {}", d["verdict"]);
    assert!(d["parameters"][id].is_array());
    assert_eq!(
        d["candidates"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|c| c["round"] == 1)
            .count(),
        11
    );
}

/// One catalogue effect end to end through the binary (fast tier): the rest of the sweep,
/// every effect, two together, null data and a cause outside the catalogue, is diagnosed in
/// process by `diagnose/tests/catalogue` (slow tier), with this command's own options.
#[test]
fn attitude_bias_is_found() {
    named_first("attitude_bias=0.02,-0.02,0.03");
}

fn sepval_scenario() -> String {
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(&["scenario", "--out", "s.toml"], dir.path()));
    let s = std::fs::read_to_string(dir.path().join("s.toml")).unwrap();
    assert!(s.contains("cm_q_per_rad = -80.0"), "{s}");
    s
}

/// Runs `sepval diagnose` on `data` in `dir` with the reduced budgets and `extra` flags.
fn diagnose_in(dir: &Path, data: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["diagnose", "--data", data];
    args.extend(REDUCED_BUDGET);
    args.extend(["--out", "diag"]);
    args.extend(extra);
    sepval(&args, dir)
}

fn diagnosis_in(dir: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(dir.join("diag/diagnosis.json")).unwrap()).unwrap()
}

/// Issue 21, item 4: a store 45 % lighter than the scenario's cannot be fitted by the 17
/// factors (the baseline stays at about 140 sigma in position); the refits then reach the
/// noise with nonsense terms. The diagnosis says first that its baseline failed, names nothing
/// as explained, and marks the answer unreliable in diagnosis.json, the page and the summary.
#[test]
fn a_baseline_that_cannot_fit_makes_the_answer_unreliable() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let light = sepval_scenario().replace("mass_kg = 907.18474", "mass_kg = 500.0");
    std::fs::write(dir.path().join("light.toml"), light).unwrap();
    ok(&sepval(
        &[
            "simulate",
            "--scenario",
            "light.toml",
            "--noise-seed",
            "3",
            "--out",
            "d.csv",
        ],
        dir.path(),
    ));
    let stdout = ok(&diagnose_in(dir.path(), "d.csv", &[]));
    let d = diagnosis_in(dir.path());
    let verdict = d["verdict"].as_str().unwrap();
    assert!(
        verdict.starts_with("unreliable: the baseline fit did not reach near the noise"),
        "{verdict}"
    );
    assert_eq!(d["baseline_converged"], false);
    assert!(
        d["baseline_unreliable"]
            .as_str()
            .unwrap()
            .contains("the limit is 20 sigma")
    );
    assert_eq!(d["explained"], false);
    if d["extension"].is_object() {
        assert_eq!(d["extension"]["explained"], false, "{}", d["extension"]);
    }
    assert!(
        stdout.starts_with("UNRELIABLE: the baseline fit failed"),
        "{stdout}"
    );
    assert!(stdout.contains("explained: no"), "{stdout}");
    let html = std::fs::read_to_string(dir.path().join("diag/report.html")).unwrap();
    let (unreliable, verdict_at) = (
        html.find("<b>Unreliable:</b>").unwrap(),
        html.find("class=\"verdict\">unreliable").unwrap(),
    );
    assert!(unreliable < verdict_at);
}

/// Issue 21, item 11: the tabulated store at Mach 5 leaves its Mach tables. `diagnose` reports
/// it as simulate and fit do, and with `--strict-tables` refuses after the baseline fit,
/// before any other work, writing no diagnosis.
#[test]
fn tables_left_are_reported_and_refused_with_strict_tables() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let example =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/tabulated-store/scenario.toml");
    let scenario = std::fs::read_to_string(&example)
        .unwrap()
        .replace("mach = 0.85", "mach = 5.0");
    let tables = example.parent().unwrap().join("tables");
    std::fs::write(
        dir.path().join("s.toml"),
        scenario.replace("\"tables/", &format!("\"{}/", tables.display())),
    )
    .unwrap();
    let sim = [
        "simulate",
        "--scenario",
        "s.toml",
        "--noise-seed",
        "3",
        "--out",
        "d.csv",
    ];
    ok(&sepval(&sim, dir.path()));
    let out = diagnose_in(dir.path(), "d.csv", &["--scenario", "s.toml"]);
    ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("warning: baseline, d.csv: left table `aero.cm`"),
        "{stderr}"
    );
    let d = diagnosis_in(dir.path());
    assert!(
        d["tables_left"].to_string().contains("mach by up to"),
        "{d}"
    );
    let earlier = std::fs::read(dir.path().join("diag/diagnosis.json")).unwrap();
    let out = diagnose_in(
        dir.path(),
        "d.csv",
        &["--scenario", "s.toml", "--strict-tables", "--overwrite"],
    );
    refused(
        &out,
        "--strict-tables: the baseline fit d.csv: left table `aero.",
    );
    // The refused run put back the diagnosis it was to replace (before 2026-11-29 it was gone).
    assert_eq!(
        std::fs::read(dir.path().join("diag/diagnosis.json")).unwrap(),
        earlier
    );
    assert!(!dir.path().join("diag/.sepval-replaced").exists());
}
