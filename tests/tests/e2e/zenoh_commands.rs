//! Every command that takes `--evaluator`, over zenoh on loopback with two workers started by
//! hand (`sepval-worker --connect`), against its in-process bits: `rerun`, `diagnose`, `plan`,
//! `predict`, `envelope` (two conditions: two jobs) and `update` (its baseline and its rounds:
//! several jobs); `fit` is `zenoh.rs`'s. The workers join once, serve every job of the command
//! and leave when it ends, told that the run is finished. Small budgets; release build.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Duration;

use sepval_common::scenario::Scenario;
use sepval_tests::*;
use serde_json::Value;

use super::zenoh::{free_port, start_worker};

/// A scenario file of the default store at Mach `mach` and alpha `alpha` deg.
fn condition(dir: &Path, name: &str, mach: f64, alpha: f64) {
    let mut s = Scenario::embedded_default();
    s.flight.mach = mach;
    s.flight.alpha_deg = alpha;
    std::fs::write(dir.join(name), s.to_toml_string()).unwrap();
}

/// A directory holding two half-second releases (`a.csv`, `b.csv`) at two conditions, a third
/// condition (`cond.toml`), their `ga+lm` fit (`fit/`) and the diagnosis of `a.csv` (`diag/`),
/// both in process.
fn fixture() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        // Under target/ (CARGO_TARGET_TMPDIR), not /tmp: a static is never dropped, so the
        // fixture's directory is never removed.
        let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
        let p = dir.path();
        condition(p, "a.toml", 0.8, 0.0);
        condition(p, "b.toml", 0.9, 3.0);
        condition(p, "cond.toml", 0.85, 1.5);
        for (name, seed) in [("a", "1"), ("b", "2")] {
            let toml = format!("{name}.toml");
            let csv = format!("{name}.csv");
            let args = ["simulate", "--scenario", &toml, "--t-end", "0.5"];
            ok(&sepval(
                &[&args[..], &["--noise-seed", seed, "--out", &csv]].concat(),
                p,
            ));
        }
        inproc(p, &[&FIT[..], &["--out", "fit"]].concat());
        inproc(p, &[&DIAGNOSE[..], &["--out", "diag"]].concat());
        dir
    })
    .path()
}

const FIT: [&str; 11] = [
    "fit",
    "--data",
    "a.csv",
    "--data",
    "b.csv",
    "--method",
    "ga+lm",
    "--generations",
    "5",
    "--population",
    "40",
];

const DIAGNOSE: [&str; 5] = ["diagnose", "--data", "a.csv", "--generations", "10"];

/// Runs `sepval ARGS` in process; returns its stdout.
fn inproc(dir: &Path, args: &[&str]) -> String {
    let all = [args, &["--evaluator", "inproc", "--threads", "2"]].concat();
    ok(&sepval(&all, dir))
}

/// Runs `sepval ARGS` over zenoh on a free loopback port with two workers started by hand:
/// they must join once, serve every job of the command and leave when it ends. Returns the
/// command's stdout.
fn over_zenoh(dir: &Path, args: &[&str]) -> String {
    let run = run_id("zcmd");
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let mut workers: Vec<_> = (0..2)
        .map(|_| start_worker(&[], &endpoint, &run, &[]))
        .collect();
    let zenoh = [
        "--evaluator",
        "zenoh",
        "--listen",
        endpoint.as_str(),
        "--run-id",
        run.as_str(),
    ];
    let all = [
        args,
        &zenoh[..],
        &["--workers", "2", "--join-timeout", "30"],
    ]
    .concat();
    let mut command = spawn_sepval(&all, dir);
    let what = format!("sepval {} over zenoh", args[0]);
    let out = wait_exit(&mut command, &what, Duration::from_secs(600));
    let stdout = ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.matches(" joined (").count(), 2, "{stderr}");
    for w in workers.iter_mut() {
        let out = wait_exit(w, "a worker", Duration::from_secs(30));
        let wstderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{wstderr}");
        // Told the run is finished, or (if that message lost the race with the coordinator's
        // exit) seeing its liveliness token go; never before the command's end.
        assert!(
            wstderr.contains("the run is finished") || wstderr.contains("coordinator is gone"),
            "{wstderr}"
        );
    }
    stdout
}

fn json(path: PathBuf) -> Value {
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

fn text(path: PathBuf) -> String {
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

#[test]
fn rerun_over_zenoh_reproduces_a_generation() {
    let p = fixture();
    let stdout = over_zenoh(p, &["rerun", "fit/generations/gen-0003.json"]);
    assert!(
        stdout.contains("reproduce their goals bit for bit"),
        "{stdout}"
    );
}

#[test]
fn diagnose_and_plan_over_zenoh_give_the_in_process_bits() {
    let p = fixture();
    over_zenoh(p, &[&DIAGNOSE[..], &["--out", "diag-z"]].concat());
    // Everything but the wall time (and the digest, which seals it too).
    let timeless = |dir: &str| {
        let mut j = json(p.join(dir).join("diagnosis.json"));
        j.as_object_mut().unwrap().remove("wall_s");
        j.as_object_mut().unwrap().remove("digest");
        j
    };
    assert_eq!(timeless("diag"), timeless("diag-z"));
    let plan = [
        "plan", "--from", "diag", "--mach", "0.7:0.95", "--points", "3",
    ];
    inproc(p, &[&plan[..], &["--out", "plan"]].concat());
    over_zenoh(p, &[&plan[..], &["--out", "plan-z"]].concat());
    let (a, b) = (
        json(p.join("plan/plan.json")),
        json(p.join("plan-z/plan.json")),
    );
    assert_eq!(a["conditions"], b["conditions"]);
    assert_eq!(a["evaluations"], b["evaluations"]);
}

#[test]
fn predict_over_zenoh_gives_the_in_process_bands() {
    let p = fixture();
    let args = [
        "predict",
        "--from",
        "fit",
        "--scenario",
        "cond.toml",
        "--samples",
        "400",
    ];
    inproc(p, &[&args[..], &["--out", "pred"]].concat());
    over_zenoh(p, &[&args[..], &["--out", "pred-z"]].concat());
    assert_eq!(
        text(p.join("pred/bands.csv")),
        text(p.join("pred-z/bands.csv"))
    );
}

#[test]
fn an_envelope_of_two_conditions_over_zenoh_keeps_its_workers_and_the_in_process_rows() {
    let p = fixture();
    let aircraft = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/geometry/aircraft.toml")
        .canonicalize()
        .unwrap();
    let aircraft = aircraft.to_str().unwrap();
    let args = [
        "envelope",
        "--from",
        "fit",
        "--aircraft",
        aircraft,
        "--mach",
        "0.75:0.85:2",
        "--samples",
        "400",
    ];
    inproc(p, &[&args[..], &["--out", "env"]].concat());
    over_zenoh(p, &[&args[..], &["--out", "env-z"]].concat());
    let rows = text(p.join("env/envelope.csv"));
    assert_eq!(rows.lines().count(), 3, "{rows}");
    assert_eq!(rows, text(p.join("env-z/envelope.csv")));
}

#[test]
fn an_update_over_zenoh_keeps_its_workers_through_its_rounds_and_gives_the_same_store() {
    let p = fixture();
    let args = [
        "update",
        "--data",
        "a.csv",
        "--data",
        "b.csv",
        "--generations",
        "10",
    ];
    inproc(p, &[&args[..], &["--out", "up"]].concat());
    over_zenoh(p, &[&args[..], &["--out", "up-z"]].concat());
    let (a, b) = (
        json(p.join("up/update.json")),
        json(p.join("up-z/update.json")),
    );
    for key in [
        "corrections",
        "fitted",
        "cross_validation",
        "rounds",
        "verdict",
    ] {
        assert_eq!(a[key], b[key], "{key}");
    }
    assert_eq!(
        text(p.join("up/scenario.toml")),
        text(p.join("up-z/scenario.toml"))
    );
}
