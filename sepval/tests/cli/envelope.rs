//! Clearance end to end: `sepval simulate --aircraft` (the clearance column and line),
//! `sepval predict --aircraft` (the clearance distribution), and `sepval envelope` from the fit
//! of `predict`'s fixture against the example aircraft: its files and fields, the same rows
//! over iceoryx2 workers as in process, a resumed sweep the same bits as a whole one, and the
//! refusals of bad input with nothing written. Reduced sample counts; release build.

use std::path::{Path, PathBuf};

use sepval_tests::{ok, refused, sepval};
use serde_json::Value;

use super::predict::fixture;

/// The example aircraft and store of the repository.
pub(crate) fn example(name: &str) -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/geometry")
        .join(name);
    p.canonicalize().unwrap().display().to_string()
}

/// Runs `sepval envelope` from the fixture's fit into `out` with `extra` flags; returns
/// envelope.json.
fn envelope(dir: &Path, out: &str, extra: &[&str]) -> Value {
    let aircraft = example("aircraft.toml");
    let mut args = vec![
        "envelope",
        "--from",
        "fit",
        "--aircraft",
        &aircraft,
        "--mach",
        "0.7:0.9:3",
        "--altitude-m",
        "3000:6000:2",
        "--samples",
        "400",
        "--out",
        out,
    ];
    args.extend(extra);
    if !extra.contains(&"--evaluator") {
        args.extend(["--evaluator", "inproc", "--threads", "2"]);
    }
    let stdout = ok(&sepval(&args, dir));
    assert!(stdout.contains("envelope:  Cleared at"), "{stdout}");
    for f in ["envelope.csv", "report.html", "figures/envelope.png"] {
        assert!(dir.join(out).join(f).is_file(), "{f}");
    }
    assert!(
        !dir.join(out).join("sweep").exists(),
        "the progress is removed"
    );
    let text = std::fs::read_to_string(dir.join(out).join("envelope.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn csv(dir: &Path, out: &str) -> String {
    std::fs::read_to_string(dir.join(out).join("envelope.csv")).unwrap()
}

#[test]
fn an_envelope_maps_every_condition_and_a_resumed_sweep_is_the_same_bits() {
    let p = fixture();
    let j = envelope(p, "env", &[]);
    assert_eq!(j["format"], "sepval-envelope/1");
    assert_eq!(j["conditions"], 6);
    assert_eq!(j["criterion_mm"], 25.4);
    let rows = j["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 6);
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r["index"], k);
        let p5 = r["clearance_p5_mm"].as_f64().unwrap();
        let p95 = r["clearance_p95_mm"].as_f64().unwrap();
        assert!(p5 > 0.0 && p5 <= p95, "{r}");
        let fail = r["p_fail"].as_f64().unwrap();
        assert_eq!(r["cleared"].as_bool().unwrap(), fail <= 0.05, "{r}");
    }
    assert_eq!(
        rows[1]["condition"]["altitude_m"], 6000.0,
        "altitude fastest"
    );
    let text = csv(p, "env");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 7);
    assert!(
        lines[0].starts_with("mach,altitude_m,alpha_deg"),
        "{}",
        lines[0]
    );
    let page = std::fs::read_to_string(p.join("env/report.html")).unwrap();
    assert!(page.contains("Cleared at"), "answer first");

    // An interrupted sweep: the first two rows done, then --resume.
    let sweep = p.join("env2/sweep");
    std::fs::create_dir_all(&sweep).unwrap();
    let progress = serde_json::json!({
        "format": "sepval-envelope-progress/1",
        "inputs_sha256": j["inputs_sha256"],
        "conditions": 6,
        "rows": [rows[0], rows[1]],
    });
    std::fs::write(sweep.join("progress.json"), progress.to_string()).unwrap();
    // The marker a sweep killed mid-run leaves (no manifest): a directory without one is not
    // a sepval run's, and no resume takes it.
    std::fs::write(
        p.join("env2/.sepval-run"),
        "{\"format\": \"sepval-run/2\", \"command\": \"envelope\"}\n",
    )
    .unwrap();
    let again = envelope(p, "env2", &["--resume"]);
    assert_eq!(again["resumed"], 2);
    assert_eq!(csv(p, "env2"), text, "a resumed sweep is the same bits");

    // Over two iceoryx2 workers: the same rows.
    envelope(p, "env-ipc", &["--evaluator", "ipc", "--workers", "2"]);
    assert_eq!(csv(p, "env-ipc"), text);
}

#[test]
fn bad_envelope_input_is_refused_with_nothing_written() {
    let p = fixture();
    let aircraft = example("aircraft.toml");
    // A pylon that reaches into the store at carriage.
    std::fs::write(
        p.join("deep-pylon.toml"),
        "[[box]]\nname = \"pylon\"\ncentre_m = [0.0, 0.0, -0.3]\nhalf_extents_m = [0.5, 0.05, 0.1]\n",
    )
    .unwrap();
    std::fs::write(p.join("empty.stl"), "").unwrap();
    let run = |out: &str, extra: &[&str]| {
        let mut args = vec![
            "envelope",
            "--from",
            "fit",
            "--out",
            out,
            "--samples",
            "400",
        ];
        args.extend(extra);
        sepval(&args, p)
    };
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--mach", "0.7:0.9:3"], "--aircraft FILE is required"),
        (vec!["--aircraft", &aircraft], "give at least one axis"),
        (
            vec!["--aircraft", &aircraft, "--mach", "0.9:0.7:3"],
            "--mach 0.9:0.7:3",
        ),
        (
            vec!["--aircraft", &aircraft, "--altitude-m", "1000:20000:3"],
            "--altitude-m",
        ),
        (
            vec!["--aircraft", "nope.toml", "--mach", "0.7:0.9:3"],
            "nope.toml",
        ),
        (
            vec!["--aircraft", &aircraft, "--mach", "0.7:0.9:3", "--resume"],
            "progress.json",
        ),
        (
            vec!["--aircraft", "deep-pylon.toml", "--mach", "0.7:0.9:3"],
            "intersects the aircraft (deep-pylon.toml) at carriage",
        ),
        (
            vec!["--aircraft", "empty.stl", "--mach", "0.7:0.9:3"],
            "empty.stl",
        ),
        (
            vec![
                "--aircraft",
                &aircraft,
                "--mach",
                "0.7:0.9:3",
                "--clearance-mm",
                "-1",
            ],
            "--clearance-mm",
        ),
    ];
    for (k, (extra, expected)) in cases.iter().enumerate() {
        let out = format!("bad-{k}");
        refused(&run(&out, extra), expected);
        let dir = p.join(&out);
        let empty = !dir.exists() || std::fs::read_dir(&dir).unwrap().next().is_none();
        assert!(empty, "{extra:?} wrote into {}", dir.display());
    }
}

#[test]
fn simulate_and_predict_report_the_clearance() {
    let p = fixture();
    let aircraft = example("aircraft.toml");
    let store = example("store.toml");
    ok(&sepval(
        &[
            "simulate",
            "--aircraft",
            &aircraft,
            "--store-shape",
            &store,
            "--out",
            "clear.csv",
        ],
        p,
    ));
    let text = std::fs::read_to_string(p.join("clear.csv")).unwrap();
    assert!(
        text.contains("# clearance = smallest clearance"),
        "{text:.400}"
    );
    let header = text.lines().find(|l| !l.starts_with('#')).unwrap();
    assert!(header.ends_with(",clearance_m"), "{header}");
    // The file still reads as telemetry: the extra column is ignored.
    ok(&sepval(
        &["goals", "--data", "clear.csv", "--sim", "clear.csv"],
        p,
    ));

    let stdout = ok(&sepval(
        &[
            "predict",
            "--from",
            "fit",
            "--scenario",
            "cond.toml",
            "--aircraft",
            &aircraft,
            "--samples",
            "400",
            "--evaluator",
            "inproc",
            "--out",
            "pred-clear",
        ],
        p,
    ));
    assert!(stdout.contains("clearance: "), "{stdout}");
    let j: Value = serde_json::from_str(
        &std::fs::read_to_string(p.join("pred-clear/prediction.json")).unwrap(),
    )
    .unwrap();
    let c = &j["clearance"];
    assert_eq!(c["criterion_mm"], 25.4);
    assert_eq!(
        c["samples"].as_u64().unwrap() + c["diverged"].as_u64().unwrap(),
        400
    );
    let m = &c["min_clearance_mm"];
    assert!(m["p5"].as_f64().unwrap() <= m["p50"].as_f64().unwrap());
    assert!(m["p50"].as_f64().unwrap() <= m["p95"].as_f64().unwrap());
    assert!(!c["closest_parts"].as_array().unwrap().is_empty());
}

/// A made-up aircraft: a block behind and below the carriage (a tail) that a store falling
/// far enough aft before it has fallen deep enough strikes: at low altitude and high Mach
/// (high dynamic pressure, high drag) it does, high and slow it does not.
const TAIL: &str = r#"
[[box]]
name = "tail"
centre_m = [-12.5, 0.0, 8.0]
half_extents_m = [7.5, 10.0, 4.0]
"#;

/// The smallest clearance [mm] that `sepval simulate --aircraft` gives the base model at
/// `mach` and `altitude_m` (its `# clearance = smallest clearance X mm ...` line).
fn true_clearance_mm(dir: &Path, mach: f64, altitude_m: f64) -> f64 {
    let mut s = sepval_common::scenario::Scenario::embedded_default();
    s.flight.mach = mach;
    s.flight.altitude_m = altitude_m;
    let name = format!("truth-{mach}-{altitude_m}");
    std::fs::write(dir.join(format!("{name}.toml")), s.to_toml_string()).unwrap();
    let scenario = format!("{name}.toml");
    let out = format!("{name}.csv");
    ok(&sepval(
        &[
            "simulate",
            "--scenario",
            &scenario,
            "--factors",
            "base.json",
            "--aircraft",
            "tail.toml",
            "--out",
            &out,
        ],
        dir,
    ));
    let text = std::fs::read_to_string(dir.join(&out)).unwrap();
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix("# clearance = smallest clearance "))
        .unwrap();
    line.split(' ').next().unwrap().parse().unwrap()
}

#[test]
fn the_envelope_clears_where_the_true_store_misses_a_tail_and_not_where_it_strikes() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let p = fixture();
    std::fs::write(p.join("tail.toml"), TAIL).unwrap();
    ok(&sepval(
        &[
            "envelope",
            "--from",
            "fit",
            "--aircraft",
            "tail.toml",
            "--mach",
            "0.6:0.95:4",
            "--altitude-m",
            "1000:9000:3",
            "--samples",
            "400",
            "--evaluator",
            "inproc",
            "--out",
            "env-tail",
        ],
        p,
    ));
    let j: Value =
        serde_json::from_str(&std::fs::read_to_string(p.join("env-tail/envelope.json")).unwrap())
            .unwrap();
    let (mut clear, mut strike) = (0, 0);
    for r in j["rows"].as_array().unwrap() {
        let c = &r["condition"];
        let (mach, alt) = (
            c["mach"].as_f64().unwrap(),
            c["altitude_m"].as_f64().unwrap(),
        );
        let truth = true_clearance_mm(p, mach, alt);
        let cleared = r["cleared"].as_bool().unwrap();
        if truth >= 150.0 {
            clear += 1;
            assert!(
                cleared,
                "Mach {mach}, {alt} m: the store misses by {truth} mm: {r}"
            );
        } else if truth <= 0.0 {
            strike += 1;
            assert!(
                !cleared,
                "Mach {mach}, {alt} m: the store strikes the tail: {r}"
            );
        }
    }
    assert!(
        clear >= 3 && strike >= 3,
        "{clear} clear and {strike} strikes"
    );
}

#[test]
fn fit_and_diagnose_record_the_clearance_of_their_best_trajectories() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let p = fixture();
    let aircraft = example("aircraft.toml");
    let common = [
        "--data",
        "a.csv",
        "--evaluator",
        "inproc",
        "--threads",
        "2",
        "--aircraft",
        aircraft.as_str(),
    ];
    let mut fit = vec![
        "fit",
        "--method",
        "ga+lm",
        "--generations",
        "3",
        "--population",
        "20",
        "--out",
        "fit-clear",
    ];
    fit.extend(common);
    let stdout = ok(&sepval(&fit, p));
    assert!(stdout.contains("clearance: a.csv: smallest"), "{stdout}");
    let mut diagnose = vec!["diagnose", "--out", "diag-clear"];
    diagnose.extend(common);
    ok(&sepval(&diagnose, p));
    for (dir, file) in [
        ("fit-clear", "result.json"),
        ("diag-clear", "diagnosis.json"),
    ] {
        let j: Value =
            serde_json::from_str(&std::fs::read_to_string(p.join(dir).join(file)).unwrap())
                .unwrap();
        let c = &j["clearance"][0];
        assert_eq!(c["release"], "a.csv", "{dir}: {j:.300}");
        let mm = c["min_clearance_mm"].as_f64().unwrap();
        assert!(
            mm > 25.4,
            "{dir}: the benchmark store clears the pylon: {c}"
        );
        assert_eq!(c["clears"], true);
        assert_eq!(c["free_flight_reached"], true);
        let csv = std::fs::read_to_string(p.join(dir).join("clearance.csv")).unwrap();
        assert!(
            csv.starts_with("release,t_s,clearance_m\na.csv,0,"),
            "{csv:.80}"
        );
        assert_eq!(csv.lines().count(), 202, "{dir}: one row per sample");
        assert!(p.join(dir).join("figures/clearance.png").is_file());
    }
}
