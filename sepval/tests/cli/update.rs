//! `sepval update` end to end: releases of a store whose normal-force interference has a shape
//! the scenario's exponential lacks (a bump 0.6 m from carriage), made with `sepval simulate`;
//! the update writes a store that every command reads as it is, whose simulation at a release
//! never fitted is what update.json says it predicts; the same store over iceoryx2 workers as
//! in process; and the refusals of bad input, with nothing written. Reduced budgets; release
//! build.

use std::path::Path;
use std::sync::OnceLock;

use sepval_common::scenario::Scenario;
use sepval_common::table::{Axis, Table, Tabulated, Variable};
use sepval_tests::{ok, refused, sepval};
use serde_json::Value;

/// The true store at Mach `mach` and aircraft alpha `alpha` deg, written to `dir/name`.
fn truth(dir: &Path, name: &str, mach: f64, alpha: f64) {
    let mut s = Scenario::embedded_default();
    let lambda = s.interference.lambda_m;
    let d: Vec<f64> = (0..=40)
        .map(|k| 0.05 * f64::from(k))
        .chain([3.0, 9.144, 100.0])
        .collect();
    let v = d
        .iter()
        .map(|&s| {
            if s >= 9.144 {
                0.0
            } else {
                -0.6 * (-s / lambda).exp() + 0.5 * (-((s - 0.6) / 0.3).powi(2)).exp()
            }
        })
        .collect();
    let axes = vec![Axis {
        variable: Variable::Distance,
        breakpoints: d,
    }];
    s.interference.dcz0 =
        Tabulated::table(Table::new(axes, v, sepval_common::table::Kind::Interference).unwrap())
            .unwrap();
    s.flight.mach = mach;
    s.flight.alpha_deg = alpha;
    std::fs::write(dir.join(name), s.to_toml_string()).unwrap();
}

/// A directory with three releases of the true store (0.5 s each): `a.csv` and `b.csv` to
/// update from, `c.csv` never fitted; and `up/`, the update in process.
fn fixture() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        // Under target/ (CARGO_TARGET_TMPDIR), not /tmp: a static is never dropped, so the
        // fixture's directory is never removed.
        let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
        let p = dir.path();
        for (name, mach, alpha, seed) in [
            ("a", 0.8, 0.0, "1"),
            ("b", 0.95, 2.0, "2"),
            ("c", 0.88, 1.0, "3"),
        ] {
            let toml = format!("{name}.toml");
            truth(p, &toml, mach, alpha);
            ok(&sepval(
                &[
                    "simulate",
                    "--scenario",
                    &toml,
                    "--t-end",
                    "0.5",
                    "--noise-seed",
                    seed,
                    "--out",
                    &format!("{name}.csv"),
                ],
                p,
            ));
        }
        update(
            p,
            "up",
            &["--evaluator", "inproc", "--threads", "2", "--daveml"],
        );
        dir
    })
    .path()
}

/// Runs `sepval update` of a.csv and b.csv (c.csv to validate) into `out`; returns update.json.
fn update(dir: &Path, out: &str, extra: &[&str]) -> Value {
    let mut args = vec![
        "update",
        "--data",
        "a.csv",
        "--data",
        "b.csv",
        "--validate",
        "c.csv",
        "--generations",
        "20",
        "--out",
        out,
    ];
    args.extend(extra);
    let stdout = ok(&sepval(&args, dir));
    assert!(stdout.contains("update:"), "{stdout}");
    serde_json::from_str(&std::fs::read_to_string(dir.join(out).join("update.json")).unwrap())
        .unwrap()
}

#[test]
fn the_updated_store_is_written_and_predicts_as_its_record_says() {
    let p = fixture();
    let up = p.join("up");
    let j: Value =
        serde_json::from_str(&std::fs::read_to_string(up.join("update.json")).unwrap()).unwrap();
    assert_eq!(j["format"], "sepval-update/1");
    for f in [
        "scenario.toml",
        "factors.json",
        "report.html",
        "figures/corrections.png",
    ] {
        assert!(up.join(f).is_file(), "{f}");
    }
    let corrections = j["corrections"].as_array().unwrap();
    assert!(
        corrections
            .iter()
            .any(|c| c["field"] == "interference.dcz0"),
        "{}",
        j["verdict"]
    );
    assert!(up.join("tables/interference_dcz0.csv").is_file());
    // The store at c's condition, simulated with the factors fitted with it, is the update's
    // prediction of c.
    let mut s = Scenario::load(&up.join("scenario.toml")).unwrap();
    assert!(s.correction.is_empty());
    s.flight.mach = 0.88;
    s.flight.alpha_deg = 1.0;
    let text = std::fs::read_to_string(up.join("scenario.toml")).unwrap();
    let at_c = text.replacen("mach = 0.95", "mach = 0.88", 1);
    let at_c = at_c.replacen("alpha_deg = 0.0", "alpha_deg = 1.0", 1);
    std::fs::write(up.join("at_c.toml"), &at_c).unwrap();
    assert_eq!(Scenario::load(&up.join("at_c.toml")).unwrap(), s);
    ok(&sepval(
        &[
            "simulate",
            "--scenario",
            "up/at_c.toml",
            "--factors",
            "up/factors.json",
            "--t-end",
            "0.5",
            "--out",
            "pred_c.csv",
        ],
        p,
    ));
    let goals = ok(&sepval(
        &["goals", "--data", "c.csv", "--sim", "pred_c.csv"],
        p,
    ));
    let v = &j["validation"][0]["updated"];
    let (jp, ja) = (
        v["j_pos_m"].as_f64().unwrap(),
        v["j_att_deg"].as_f64().unwrap(),
    );
    let numbers: Vec<f64> = goals
        .split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect();
    assert!(
        numbers.iter().any(|g| (g - jp).abs() < 1e-6)
            && numbers.iter().any(|g| (g - ja).abs() < 1e-4),
        "goals {goals} against the record's {jp} m, {ja} deg"
    );
    // It predicts the release never fitted better than the factors alone.
    let fo = &j["validation"][0]["factors_only"];
    assert!(jp < fo["j_pos_m"].as_f64().unwrap() || ja < fo["j_att_deg"].as_f64().unwrap());
    let page = std::fs::read_to_string(up.join("report.html")).unwrap();
    assert!(page.contains("Updated:"), "{page}");
    // --daveml: the updated store as DAVE-ML, the corrected table with its standard deviation,
    // the releases named; read back, it is the same store (docs/daveml.md).
    let dml = std::fs::read_to_string(up.join("store.dml")).unwrap();
    assert!(
        dml.contains("<griddedTableDef name=\"dCZ_table\"")
            && dml.contains("<normalPDF numSigmas=\"1\">")
            && dml.contains("the releases a.csv, b.csv"),
        "{dml}"
    );
    ok(&sepval(
        &[
            "scenario",
            "--scenario",
            "up/scenario.toml",
            "--from-daveml",
            "up/store.dml",
            "--out",
            "up_back",
        ],
        p,
    ));
    let back = Scenario::load(&p.join("up_back/scenario.toml")).unwrap();
    let store = Scenario::load(&up.join("scenario.toml")).unwrap();
    assert_eq!(back, store);
}

#[test]
fn ipc_workers_update_the_store_as_the_process_does() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let p = fixture();
    let ipc = update(p, "up_ipc", &["--evaluator", "ipc", "--workers", "2"]);
    let inproc: Value =
        serde_json::from_str(&std::fs::read_to_string(p.join("up").join("update.json")).unwrap())
            .unwrap();
    for key in [
        "corrections",
        "fitted",
        "cross_validation",
        "rounds",
        "validation",
        "verdict",
    ] {
        assert_eq!(ipc[key], inproc[key], "{key}");
    }
    assert_eq!(
        std::fs::read_to_string(p.join("up_ipc/scenario.toml")).unwrap(),
        std::fs::read_to_string(p.join("up/scenario.toml")).unwrap()
    );
}

#[test]
fn bad_input_is_refused_with_nothing_written() {
    let p = fixture();
    let run = |args: &[&str]| sepval(args, p);
    refused(
        &run(&["update", "--out", "x1"]),
        "--data FILE.csv is required",
    );
    refused(
        &run(&[
            "update",
            "--data",
            "a.csv",
            "--free",
            "fwdfac,wingfac",
            "--out",
            "x2",
        ]),
        "--free wingfac: not one of the 17 factors",
    );
    refused(
        &run(&[
            "update",
            "--data",
            "a.csv",
            "--free",
            "fwdfac,fwdfac",
            "--out",
            "x3",
        ]),
        "--free fwdfac: given twice",
    );
    refused(
        &run(&["update", "--data", "missing.csv", "--out", "x4"]),
        "missing.csv",
    );
    refused(
        &run(&[
            "update", "--data", "a.csv", "--data", "a.csv", "--out", "x5",
        ]),
        "is the same file as --data a.csv",
    );
    refused(
        &run(&[
            "update",
            "--data",
            "a.csv",
            "--validate",
            "a.csv",
            "--out",
            "x6",
        ]),
        "a release used for fitting cannot measure prediction",
    );
    for d in ["x1", "x2", "x3", "x4", "x5", "x6"] {
        assert!(!p.join(d).exists(), "{d} was written");
    }
    // An earlier update is not overwritten without --overwrite, and stays whole.
    let before = std::fs::read(p.join("up/update.json")).unwrap();
    refused(&run(&["update", "--data", "a.csv", "--out", "up"]), "--out");
    assert_eq!(std::fs::read(p.join("up/update.json")).unwrap(), before);
}
