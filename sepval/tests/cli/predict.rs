//! `sepval predict` end to end: from a `ga+lm` fit of two synthetic releases on a base that is
//! not the default truth, a release at a third condition predicted, its files and fields, the
//! post-flight check of a release flown there, the same bands bit for bit over iceoryx2
//! workers as in process; from the diagnoses of `plan`'s fixture (with and without rivals);
//! and the refusals of bad input with nothing written. Reduced budgets; release build.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use sepval_common::scenario::Scenario;
use sepval_tests::{ok, refused, sepval};
use serde_json::Value;

/// Factors of the base model of these tests (not the default truth).
const BASE: &str = r#"{"fwdfac": 0.45, "aftfac": 0.65, "xinerfac": 0.98, "yinerfac": 1.03,
 "zinerfac": 0.97, "caoff": -0.02, "cyoff": 0.04, "czoff": -0.06, "cmoff": 0.1, "cnoff": -0.08,
 "cloff": -0.05, "caintfac": 1.1, "cyintfac": 1.4, "czintfac": 0.9, "cmintfac": 1.3,
 "cnintfac": 0.8, "clintfac": 1.6}"#;

/// A scenario file of the default store at Mach `mach`, alpha `alpha` deg, beta `beta` deg.
fn condition(dir: &Path, name: &str, mach: f64, alpha: f64, beta: f64) {
    let mut s = Scenario::embedded_default();
    s.flight.mach = mach;
    s.flight.alpha_deg = alpha;
    s.flight.beta_deg = beta;
    std::fs::write(dir.join(name), s.to_toml_string()).unwrap();
}

/// A noisy release of the base at the condition of `scenario`, into `out`.
fn release(dir: &Path, scenario: &str, seed: &str, out: &str) {
    ok(&sepval(
        &[
            "simulate",
            "--scenario",
            scenario,
            "--factors",
            "base.json",
            "--noise-seed",
            seed,
            "--out",
            out,
        ],
        dir,
    ));
}

/// A directory holding two releases, `fit/` (their `ga+lm` fit), `ga/` (a fit without
/// covariance), `cond.toml` (the condition to predict) and `flown.csv` (a release flown there).
pub(crate) fn fixture() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        // Under target/ (CARGO_TARGET_TMPDIR), not /tmp: a static is never dropped, so the
        // fixture's directory is never removed.
        let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
        let p = dir.path();
        std::fs::write(p.join("base.json"), BASE).unwrap();
        condition(p, "a.toml", 0.8, 0.0, 0.0);
        condition(p, "b.toml", 0.9, 3.0, 2.0);
        condition(p, "cond.toml", 0.7, 1.5, -2.0);
        release(p, "a.toml", "1", "a.csv");
        release(p, "b.toml", "2", "b.csv");
        release(p, "cond.toml", "3", "flown.csv");
        let fit = |method: &str, out: &str| {
            ok(&sepval(
                &[
                    "fit",
                    "--data",
                    "a.csv",
                    "--data",
                    "b.csv",
                    "--method",
                    method,
                    "--generations",
                    "5",
                    "--population",
                    "40",
                    "--evaluator",
                    "inproc",
                    "--threads",
                    "2",
                    "--out",
                    out,
                ],
                p,
            ))
        };
        fit("ga+lm", "fit");
        fit("ga", "ga");
        dir
    })
    .path()
}

/// Runs `sepval predict` with `args` (in process unless an evaluator is given) into `out`;
/// returns prediction.json.
fn predict(dir: &Path, out: &str, args: &[&str]) -> Value {
    let mut all = vec!["predict", "--out", out, "--samples", "400"];
    all.extend(args);
    if !args.contains(&"--evaluator") {
        all.extend(["--evaluator", "inproc", "--threads", "2"]);
    }
    let stdout = ok(&sepval(&all, dir));
    assert!(stdout.contains("sources:"), "{stdout}");
    for f in ["report.html", "bands.csv", "figures/prediction.png"] {
        assert!(dir.join(out).join(f).is_file(), "{f}");
    }
    serde_json::from_str(&std::fs::read_to_string(dir.join(out).join("prediction.json")).unwrap())
        .unwrap()
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn a_fit_predicts_a_release_and_the_flown_one_is_inside_its_bands() {
    let p = fixture();
    let j = predict(
        p,
        "pred",
        &[
            "--from",
            "fit",
            "--scenario",
            "cond.toml",
            "--data",
            "flown.csv",
        ],
    );
    assert_eq!(j["format"], "sepval-prediction/1");
    assert_eq!(j["level"], 0.95);
    assert_eq!(j["samples"], 400);
    assert_eq!(j["condition"]["mach"], 0.7);
    let t = numbers(&j["t_s"]);
    assert_eq!(t.len(), 201);
    for c in ["x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg"] {
        let (lo, mid, hi) = (
            numbers(&j[c]["lo"]),
            numbers(&j[c]["mid"]),
            numbers(&j[c]["hi"]),
        );
        assert_eq!(lo.len(), t.len(), "{c}");
        assert!(
            lo.iter()
                .zip(&mid)
                .zip(&hi)
                .all(|((l, m), h)| l <= m && m <= h),
            "{c}"
        );
    }
    let s = &j["sources"];
    let total = s["factors"]["share"].as_f64().unwrap()
        + s["model_form"]["share"].as_f64().unwrap()
        + s["measurement"]["share"].as_f64().unwrap();
    assert!((total - 1.0).abs() < 1e-9, "{s}");
    assert_eq!(s["measurement_included"], true);
    // Two releases fitted: each left out in turn.
    assert_eq!(s["model_form"]["held_out"].as_array().unwrap().len(), 2);
    let check = &j["check"];
    assert_eq!(check["verdict"], "inside the predicted bands", "{check}");
    assert_eq!(check["channels"].as_array().unwrap().len(), 6);
    let csv = std::fs::read_to_string(p.join("pred/bands.csv")).unwrap();
    assert!(
        csv.lines()
            .nth(1)
            .unwrap()
            .starts_with("t_s,x_m_lo,x_m_mid,x_m_hi,")
    );
    assert_eq!(csv.lines().count(), 2 + 201);
    let html = std::fs::read_to_string(p.join("pred/report.html")).unwrap();
    let first = html.find("class=\"verdict\"").unwrap();
    assert!(html[first..].contains("predicted at"), "the answer first");
    // A second prediction into the same directory: refused, then cleared with --overwrite.
    let again = [
        "predict",
        "--from",
        "fit",
        "--scenario",
        "cond.toml",
        "--samples",
        "400",
    ];
    let mut args = again.to_vec();
    args.extend(["--evaluator", "inproc", "--out", "pred"]);
    refused(&sepval(&args, p), "is not empty");
    args.push("--overwrite");
    ok(&sepval(&args, p));
    let j: Value =
        serde_json::from_str(&std::fs::read_to_string(p.join("pred/prediction.json")).unwrap())
            .unwrap();
    assert_eq!(j["samples"], 400);
    assert!(j.get("check").is_none());
}

#[test]
fn the_same_seed_gives_the_same_bands_over_workers_as_in_process() {
    let p = fixture();
    let args = ["--from", "fit", "--scenario", "cond.toml", "--seed", "9"];
    let a = predict(p, "seed-inproc", &args);
    let mut ipc = args.to_vec();
    ipc.extend(["--evaluator", "ipc", "--workers", "2"]);
    let b = predict(p, "seed-ipc", &ipc);
    for c in ["x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg"] {
        assert_eq!(a[c], b[c], "{c}");
    }
    assert_eq!(a["sources"], b["sources"]);
    assert_eq!(a["sources"]["measurement_included"], false);
}

#[test]
fn a_diagnosis_with_rivals_weights_them_by_their_evidence() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let p = super::plan::with_rivals();
    condition(p, "cond-plan.toml", 0.9, 2.0, 3.0);
    let j = predict(
        p,
        "pred-rivals",
        &["--from", "damping/diag", "--scenario", "cond-plan.toml"],
    );
    let models = j["models"].as_array().unwrap();
    assert!(models.len() > 1, "{models:?}");
    let w: f64 = models.iter().map(|m| m["weight"].as_f64().unwrap()).sum();
    assert!((w - 1.0).abs() < 1e-9);
    let drawn: u64 = models.iter().map(|m| m["samples"].as_u64().unwrap()).sum();
    assert_eq!(drawn, 400);
    assert_eq!(j["from_kind"], "diagnosis");
    // One release fitted, none held out: the discrepancy comes from its misfit alone.
    assert!(
        j["sources"]["model_form"]["calibration"]
            .as_str()
            .unwrap()
            .starts_with("no release was held out"),
        "{}",
        j["sources"]
    );
    let j = predict(
        p,
        "pred-diag",
        &["--from", "diag", "--scenario", "cond-plan.toml"],
    );
    assert_eq!(j["models"].as_array().unwrap().len(), 1);
}

/// Fails unless `sepval predict` with `args` is refused with `expected` and writes nothing.
fn refused_predict(args: &[&str], expected: &str) {
    let out: PathBuf = fixture().join("refused");
    let mut all = vec!["predict", "--out", "refused", "--evaluator", "inproc"];
    all.extend(args);
    refused(&sepval(&all, fixture()), expected);
    assert!(!out.exists(), "{args:?} wrote {}", out.display());
}

#[test]
fn bad_inputs_are_refused_naming_what_and_nothing_is_written() {
    let p = fixture();
    let good = ["--from", "fit", "--scenario", "cond.toml"];
    let with = |extra: &[&str]| -> Vec<String> {
        good.iter().chain(extra).map(|s| s.to_string()).collect()
    };
    let run = |args: Vec<String>, expected: &str| {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        refused_predict(&args, expected);
    };
    run(
        vec![
            "--from".into(),
            ".".into(),
            "--scenario".into(),
            "cond.toml".into(),
        ],
        "holds neither result.json nor diagnosis.json",
    );
    run(
        vec![
            "--from".into(),
            "a.csv".into(),
            "--scenario".into(),
            "cond.toml".into(),
        ],
        "not a directory",
    );
    run(
        vec![
            "--from".into(),
            "ga".into(),
            "--scenario".into(),
            "cond.toml".into(),
        ],
        "the fit ran --method ga, which estimates no covariance of the factors; fit with --method ga+lm",
    );
    run(
        with(&["--level", "1.5"]),
        "--level 1.5: expected a number between 0 and 1",
    );
    run(with(&["--level", "0"]), "--level 0:");
    run(
        with(&["--samples", "0"]),
        "--samples 0: bands at level 0.95 need at least 400 samples (20 / (1 - level)",
    );
    run(
        with(&["--samples", "1000000000"]),
        "--samples 1000000000: expected at most 100000",
    );
    let mut heavy = Scenario::embedded_default();
    heavy.store.mass_kg *= 1.2;
    std::fs::write(p.join("heavy.toml"), heavy.to_toml_string()).unwrap();
    run(
        vec![
            "--from".into(),
            "fit".into(),
            "--scenario".into(),
            "heavy.toml".into(),
        ],
        "differs from that of the releases fitted",
    );
    // A store spinning at 10 000 deg/s at release tumbles at once: every sample diverges.
    let mut spin = Scenario::embedded_default();
    spin.initial.rates_deg_s = [10_000.0, 0.0, 0.0];
    std::fs::write(p.join("spin.toml"), spin.to_toml_string()).unwrap();
    run(
        vec![
            "--from".into(),
            "fit".into(),
            "--scenario".into(),
            "spin.toml".into(),
        ],
        "every one of the 1000 samples diverged or failed at this condition",
    );
    run(
        with(&["--data", "a.csv"]),
        "--data a.csv: its metadata says it was flown at Mach 0.8",
    );
}
