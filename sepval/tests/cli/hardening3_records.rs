//! Issue 33, items 8, 9, 10 and messages of 13: records other commands read (diagnosis.json,
//! result.json) sealed with a digest and every value read checked against its range, parse
//! errors with line and column; conditions outside the model's domain refused by `predict`,
//! `plan` and `envelope`, one far from the releases said first; sample counts that cannot give
//! the level refused; the envelope's resume refusals naming what differs. The fit and the
//! diagnosis are the fixtures of `predict` and `plan`; release build.

use std::path::{Path, PathBuf};

use sepval_common::scenario::{Scenario, hex_sha256};
use sepval_tests::{ok, refused, sepval};
use serde_json::{Value, json};

use super::plan::fixture as diagnosed;
use super::predict::fixture as fitted;

/// A copy of `from/file` (a sepval record) into a new directory `name` under `dir`, its JSON
/// changed by `edit`, then written re-sealed (a valid digest of the edited content) when
/// `seal`, else with the digest it had.
fn edited(
    dir: &Path,
    from: &str,
    file: &str,
    name: &str,
    seal: bool,
    edit: impl FnOnce(&mut Value),
) -> PathBuf {
    let text = std::fs::read_to_string(dir.join(from).join(file)).unwrap();
    let mut v: Value = serde_json::from_str(&text).unwrap();
    edit(&mut v);
    if seal {
        v.as_object_mut().unwrap().remove("digest");
        let digest = hex_sha256(&serde_json::to_vec(&v).unwrap());
        v["digest"] = json!(digest);
    }
    let out = dir.join(name);
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join(file), serde_json::to_string_pretty(&v).unwrap()).unwrap();
    out
}

/// A record directory whose `file` holds `text` as it is.
fn holding(dir: &Path, file: &str, name: &str, text: &str) {
    let out = dir.join(name);
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join(file), text).unwrap();
}

/// `sepval plan --from FROM` refused with `expected`, nothing written.
fn plan_refused(dir: &Path, from: &str, expected: &str) -> String {
    let out = format!("plan-{from}");
    let e = refused(
        &sepval(
            &[
                "plan",
                "--from",
                from,
                "--evaluator",
                "inproc",
                "--out",
                &out,
            ],
            dir,
        ),
        expected,
    );
    assert!(!dir.join(&out).exists());
    e
}

/// `sepval predict --from FROM` at the fixture's condition refused with `expected`.
fn predict_refused(dir: &Path, from: &str, scenario: &str, expected: &str) -> String {
    let out = format!("pred-{from}");
    let e = refused(
        &sepval(
            &[
                "predict",
                "--from",
                from,
                "--scenario",
                scenario,
                "--evaluator",
                "inproc",
                "--out",
                &out,
            ],
            dir,
        ),
        expected,
    );
    assert!(!dir.join(&out).exists());
    e
}

#[test]
fn an_edited_diagnosis_is_refused_by_its_digest_and_out_of_range_values_by_their_range() {
    // The source is refused before the scenario is read: cond.toml need not exist here.
    let p = diagnosed();
    let sealed = std::fs::read_to_string(p.join("diag/diagnosis.json")).unwrap();
    assert!(
        sealed.contains("\"digest\": \""),
        "diagnosis.json is sealed"
    );
    // Edited by hand to a plausible value: the digest catches it.
    edited(p, "diag", "diagnosis.json", "d-plausible", false, |v| {
        v["sigma_att_deg"] = json!(0.2);
    });
    for e in [
        plan_refused(p, "d-plausible", "does not match its digest"),
        predict_refused(p, "d-plausible", "cond.toml", "does not match its digest"),
    ] {
        assert!(e.contains("edited after `sepval diagnose` wrote it"), "{e}");
    }
    // Values out of range, even with a digest that matches: refused naming the field.
    let cases: [(&str, Value, &str); 3] = [
        (
            "sigma_att_deg",
            json!(-1.0),
            "`sigma_att_deg` = -1: expected an attitude noise in (0, 3600] deg",
        ),
        (
            "sigma_pos_m",
            json!(1e300),
            "`sigma_pos_m` = 1e300: expected a position noise in (0, 1e5] m",
        ),
        (
            "sigma_pos_m",
            json!(0.0),
            "`sigma_pos_m` = 0: expected a position noise in (0, 1e5] m",
        ),
    ];
    for (k, (field, value, expected)) in cases.into_iter().enumerate() {
        let name = format!("d-range-{k}");
        edited(p, "diag", "diagnosis.json", &name, true, |v| {
            v[field] = value;
        });
        plan_refused(p, &name, expected);
        predict_refused(p, &name, "cond.toml", expected);
    }
    // A correlation beyond 1.
    edited(p, "diag", "diagnosis.json", "d-rho", true, |v| {
        v["identifiability"]["correlation"][0][1] = json!(1.5);
    });
    plan_refused(
        p,
        "d-rho",
        "`identifiability.correlation[0][1]` = 1.5: expected a correlation in [-1, 1]",
    );
    // No digest (an earlier sepval, or deleted): refused, saying so.
    edited(p, "diag", "diagnosis.json", "d-undigested", false, |v| {
        v.as_object_mut().unwrap().remove("digest");
    });
    plan_refused(
        p,
        "d-undigested",
        "records no digest of its content (`digest`): written by an earlier sepval or edited by hand",
    );
}

#[test]
fn a_record_that_is_not_json_is_refused_with_its_line_and_column() {
    // The source is refused before the scenario is read: cond.toml need not exist here.
    let p = diagnosed();
    let sealed = std::fs::read_to_string(p.join("diag/diagnosis.json")).unwrap();
    let cut = &sealed[..sealed.len() / 2];
    let cut_lines = cut.lines().count();
    let cases: [(&str, &str, String); 4] = [
        (
            "j-empty",
            "",
            "line 1, column 0: not JSON: EOF while parsing a value".into(),
        ),
        ("j-cut", cut, format!("line {cut_lines}, column")),
        (
            "j-text",
            "not json at all",
            "line 1, column 2: not JSON: expected ident".into(),
        ),
        (
            "j-nan",
            "{\"format\": \"sepval-diagnosis/2\",\n  \"sigma_pos_m\": NaN}",
            "line 2, column 18: not JSON".into(),
        ),
    ];
    for (name, text, expected) in cases {
        holding(p, "diagnosis.json", name, text);
        for e in [
            plan_refused(p, name, &expected),
            predict_refused(p, name, "cond.toml", &expected),
        ] {
            assert!(!e.contains("format none"), "{e}");
        }
    }
    // Valid JSON of no sepval format is still "another format".
    holding(p, "diagnosis.json", "j-other", "{\"x\": 1}");
    plan_refused(
        p,
        "j-other",
        "format none, expected sepval-diagnosis/2: not a record this sepval writes",
    );
}

#[test]
fn an_unknown_effect_in_a_diagnosis_is_named_once() {
    let p = diagnosed();
    edited(p, "diag", "diagnosis.json", "d-effect", true, |v| {
        v["model"]["effects"] = json!([{"id": "no_such_effect", "values": [0.1]}]);
    });
    let e = plan_refused(p, "d-effect", "unknown effect `no_such_effect`");
    assert_eq!(e.matches("no_such_effect").count(), 1, "{e}");
}

#[test]
fn an_edited_fit_result_is_refused_and_so_is_an_envelope_from_it() {
    let p = fitted();
    edited(p, "fit", "result.json", "f-plausible", false, |v| {
        v["sigma_pos_m"] = json!(0.004);
    });
    predict_refused(p, "f-plausible", "cond.toml", "does not match its digest");
    edited(p, "fit", "result.json", "f-negative", true, |v| {
        v["sigma_att_deg"] = json!(-1.0);
    });
    predict_refused(
        p,
        "f-negative",
        "cond.toml",
        "result.json: `sigma_att_deg` = -1: expected an attitude noise",
    );
    let aircraft = aircraft();
    refused(
        &sepval(
            &[
                "envelope",
                "--from",
                "f-negative",
                "--aircraft",
                &aircraft,
                "--mach",
                "0.7:0.9:2",
                "--out",
                "env-negative",
            ],
            p,
        ),
        "`sigma_att_deg` = -1",
    );
}

/// The example aircraft of the repository.
fn aircraft() -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/geometry/aircraft.toml")
        .canonicalize()
        .unwrap()
        .display()
        .to_string()
}

/// A scenario file of the default store at Mach `mach`, alpha `alpha` deg.
fn condition(dir: &Path, name: &str, mach: f64, alpha: f64) {
    let mut s = Scenario::embedded_default();
    s.flight.mach = mach;
    s.flight.alpha_deg = alpha;
    std::fs::write(dir.join(name), s.to_toml_string()).unwrap();
}

#[test]
fn conditions_outside_the_model_s_domain_are_refused_saying_the_domain() {
    let p = fitted();
    condition(p, "mach5.toml", 5.0, 0.0);
    condition(p, "alpha89.toml", 0.8, 89.0);
    predict_refused(
        p,
        "fit",
        "mach5.toml",
        "the condition's Mach = 5 is outside the model's domain (docs/model.md section 1: Mach in (0, 3], aircraft alpha and beta within +-30 deg) (0 to 3)",
    );
    predict_refused(
        p,
        "fit",
        "alpha89.toml",
        "the condition's alpha_deg = 89 is outside the model's domain",
    );
    let d = diagnosed();
    refused(
        &sepval(
            &[
                "plan",
                "--from",
                "diag",
                "--mach",
                "0.6:50",
                "--evaluator",
                "inproc",
                "--out",
                "plan-mach50",
            ],
            d,
        ),
        "--mach 0.6:50: Mach = 50 is outside the model's domain",
    );
    let aircraft = aircraft();
    refused(
        &sepval(
            &[
                "envelope",
                "--from",
                "fit",
                "--aircraft",
                &aircraft,
                "--alpha-deg",
                "0:60:3",
                "--out",
                "env-alpha60",
            ],
            p,
        ),
        "--alpha-deg 0:60: alpha_deg = 60 is outside the model's domain",
    );
    assert!(!p.join("env-alpha60").exists() && !d.join("plan-mach50").exists());
}

#[test]
fn a_prediction_far_from_every_release_says_so_first() {
    let p = fitted();
    condition(p, "mach2.toml", 2.0, 0.0);
    let stdout = ok(&sepval(
        &[
            "predict",
            "--from",
            "fit",
            "--scenario",
            "mach2.toml",
            "--evaluator",
            "inproc",
            "--threads",
            "2",
            "--samples",
            "400",
            "--out",
            "pred-far",
        ],
        p,
    ));
    let first = stdout.lines().next().unwrap();
    assert!(
        first.starts_with("warning:   Far from every release fitted, an extrapolation: Mach 2 against 0.8 to 0.9 of the releases (beyond by 1.10, more than 0.1)"),
        "{stdout}"
    );
    let j: Value =
        serde_json::from_str(&std::fs::read_to_string(p.join("pred-far/prediction.json")).unwrap())
            .unwrap();
    assert!(
        j["extrapolation"]
            .as_str()
            .unwrap()
            .starts_with("Far from every release fitted"),
        "{j:.300}"
    );
    let page = std::fs::read_to_string(p.join("pred-far/report.html")).unwrap();
    let verdict = page.find("class=\"verdict\"").unwrap();
    assert!(page[verdict..].contains("Far from every release fitted"));
}

#[test]
fn sample_counts_that_cannot_give_the_level_are_refused_with_the_rule() {
    let p = fitted();
    for (samples, level, least, remedy) in [
        ("1", "0.95", "400", "give --samples 400 or more"),
        ("100", "0.9", "200", "give --samples 200 or more"),
        // More than can be drawn: the level is what to change.
        (
            "1000",
            "0.9999",
            "200000",
            "more than the 100000 drawn at most: give a --level of at most 0.9998",
        ),
    ] {
        refused(
            &sepval(
                &[
                    "predict",
                    "--from",
                    "fit",
                    "--scenario",
                    "cond.toml",
                    "--samples",
                    samples,
                    "--level",
                    level,
                    "--out",
                    "pred-few",
                ],
                p,
            ),
            &format!(
                "--samples {samples}: bands at level {level} need at least {least} samples (20 / (1 - level), so that 20 samples fall outside the level); {remedy}"
            ),
        );
    }
    let aircraft = aircraft();
    refused(
        &sepval(
            &[
                "envelope",
                "--from",
                "fit",
                "--aircraft",
                &aircraft,
                "--mach",
                "0.7:0.9:2",
                "--samples",
                "40",
                "--out",
                "env-few",
            ],
            p,
        ),
        "--samples 40: bands at level 0.95 need at least 400 samples",
    );
    assert!(!p.join("pred-few").exists() && !p.join("env-few").exists());
}

#[test]
fn envelope_resume_refusals_say_what_differs_and_that_a_sweep_is_finished() {
    let p = fitted();
    let aircraft = aircraft();
    let args = |out: &'static str, extra: &[&'static str]| -> Vec<String> {
        let mut a: Vec<String> = [
            "envelope",
            "--from",
            "fit",
            "--aircraft",
            &aircraft,
            "--mach",
            "0.8:0.9:2",
            "--samples",
            "400",
            "--seed",
            "1",
            "--evaluator",
            "inproc",
            "--out",
            out,
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let run = |a: Vec<String>| {
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        sepval(&a, p)
    };
    ok(&run(args("env-done", &[])));
    refused(
        &run(args("env-done", &["--resume"])),
        "holds a finished sweep (envelope.json is written and no sweep/progress.json is left): there is nothing to resume",
    );
    // An interrupted sweep of another seed: the refusal names it.
    let sha = |path: PathBuf| hex_sha256(&std::fs::read(path).unwrap());
    let sweep = p.join("env-other/sweep");
    std::fs::create_dir_all(&sweep).unwrap();
    let progress = json!({
        "format": "sepval-envelope-progress/1",
        "inputs_sha256": "0".repeat(64),
        "inputs": {
            "the source's result.json": sha(p.join("fit/result.json")),
            "the --aircraft file": sha(PathBuf::from(&aircraft)),
            "--samples": "400",
            "--seed": "7",
            "--clearance-mm": "25.4",
            "--mach": "0.8:0.9:2",
        },
        "conditions": 2,
        "rows": [],
    });
    std::fs::write(sweep.join("progress.json"), progress.to_string()).unwrap();
    refused(
        &run(args("env-other", &["--resume"])),
        "it records a sweep of other inputs (--seed was 7, now 1): give the same inputs to --resume",
    );
}

#[test]
fn a_prediction_from_a_fit_whose_releases_changed_is_refused() {
    // Before 2026-11-29 predict re-read the releases a fit records and went on with whatever
    // they held now, so its bands were of a fit that never was.
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path();
    let release = |seed: &str| {
        ok(&sepval(
            &["simulate", "--noise-seed", seed, "--out", "d.csv"],
            p,
        ))
    };
    // The fit into `fit` (the earlier one cleared), with `extra` flags.
    let fit = |extra: &[&str]| {
        let mut a = vec![
            "fit",
            "--data",
            "d.csv",
            "--method",
            "ga+lm",
            "--generations",
            "3",
            "--population",
            "10",
            "--evaluator",
            "inproc",
            "--no-figures",
            "--overwrite",
            "--out",
            "fit",
        ];
        a.extend(extra);
        ok(&sepval(&a, p))
    };
    release("3");
    fit(&[]);
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../common/scenarios/eglin_default.toml")
        .display()
        .to_string();
    let predict = |out: &str| {
        sepval(
            &[
                "predict",
                "--from",
                "fit",
                "--scenario",
                &scenario,
                "--samples",
                "400",
                "--evaluator",
                "inproc",
                "--out",
                out,
            ],
            p,
        )
    };
    ok(&predict("before"));
    release("4");
    refused(
        &predict("after"),
        "--from fit: the releases it was fitted to (",
    );
    let e = String::from_utf8_lossy(&predict("after").stderr).into_owned();
    assert!(
        e.contains("d.csv) have changed since (their SHA-256 was "),
        "{e}"
    );
    assert!(!p.join("after").exists());
    // A fit of one sample determines no standard error: its bands would be of nothing.
    let text = std::fs::read_to_string(p.join("d.csv")).unwrap();
    let header = text.lines().position(|l| !l.starts_with('#')).unwrap();
    let one: Vec<&str> = text.lines().take(header + 2).collect();
    std::fs::write(p.join("d.csv"), one.join("\n") + "\n").unwrap();
    fit(&["--sigma-pos-m", "0.003", "--sigma-att-deg", "0.1"]);
    refused(
        &predict("after"),
        "result.json: determines the standard error of none of its 17 parameters",
    );
    assert!(!p.join("after").exists());
}
