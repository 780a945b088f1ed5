//! `sepval fit` and `sepval rerun` end to end, with reduced budgets.

use sepval_tests::{deterministic_part, ok, sepval};
use serde_json::Value;

const SMALL: [&str; 8] = [
    "--generations",
    "12",
    "--population",
    "20",
    "--hill-budget",
    "120",
    "--no-figures",
    "--seed",
];

#[test]
fn a_reduced_fit_improves_on_the_nominal_start_by_a_wide_margin() {
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(
        &[
            "fit",
            "--generations",
            "25",
            "--population",
            "40",
            "--hill-budget",
            "500",
            "--seed",
            "7",
            "--out",
            "run",
        ],
        dir.path(),
    ));
    let r = deterministic_part(&dir.path().join("run/result.json"));
    // The nominal factors' weighted goal on the default data, for comparison.
    ok(&sepval(
        &["simulate", "--factors", "nominal", "--out", "nominal.csv"],
        dir.path(),
    ));
    ok(&sepval(
        &["simulate", "--noise-seed", "20260101", "--out", "data.csv"],
        dir.path(),
    ));
    let g = ok(&sepval(
        &["goals", "--data", "data.csv", "--sim", "nominal.csv"],
        dir.path(),
    ));
    let nums: Vec<f64> = g
        .lines()
        .map(|l| l.split_whitespace().nth(2).unwrap().parse().unwrap())
        .collect();
    let (sp, sa) = (
        r["sigma_pos_m"].as_f64().unwrap(),
        r["sigma_att_deg"].as_f64().unwrap(),
    );
    let nominal = nums[0] / sp + nums[1] / sa;
    for method in ["ga", "hill"] {
        let best = &r["methods"][method]["best"];
        let w = best["weighted"].as_f64().unwrap();
        assert!(w < nominal / 4.0, "{method}: {w} vs nominal {nominal}");
        assert_eq!(best["factors"].as_object().unwrap().len(), 17);
    }
    assert_eq!(r["methods"]["ga"]["best"]["evaluations"], 1000);
    assert!(
        r["methods"]["hill"]["best"]["evaluations"]
            .as_u64()
            .unwrap()
            <= 500
    );
    assert_eq!(r["methods"]["ga"]["history"].as_array().unwrap().len(), 25);
    assert!(
        !r["methods"]["ga"]["pareto_front"]
            .as_array()
            .unwrap()
            .is_empty()
    );
    assert!(
        r["truth"].is_object(),
        "the default data's truth is reported"
    );
    for f in [
        "fig1_pitch",
        "fig2_yaw",
        "fig3_roll",
        "fig4_downrange",
        "fig5_crossrange",
        "fig6_altitude",
        "fig7_factors",
        "pareto_front",
        "convergence",
    ] {
        let png = std::fs::read(dir.path().join(format!("run/figures/{f}.png"))).unwrap();
        assert_eq!(&png[1..4], b"PNG", "{f}");
    }
    for g in 1..=25 {
        assert!(
            dir.path()
                .join(format!("run/generations/gen-{g:04}.json"))
                .exists()
        );
    }
}

#[test]
fn resuming_gives_the_uninterrupted_result_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let mut full = vec!["fit"];
    full.extend(SMALL);
    full.extend(["3", "--out", "full"]);
    ok(&sepval(&full, dir.path()));
    ok(&sepval(
        &[
            "fit",
            "--resume",
            "full/generations/gen-0005.json",
            "--no-figures",
            "--out",
            "resumed",
        ],
        dir.path(),
    ));
    assert_eq!(
        deterministic_part(&dir.path().join("full/result.json")),
        deterministic_part(&dir.path().join("resumed/result.json"))
    );
    // Neither does the evaluator: in-process on one thread against worker processes.
    let mut one = full.clone();
    *one.last_mut().unwrap() = "one-thread";
    one.extend(["--evaluator", "inproc", "--threads", "1"]);
    ok(&sepval(&one, dir.path()));
    assert_eq!(
        deterministic_part(&dir.path().join("full/result.json")),
        deterministic_part(&dir.path().join("one-thread/result.json"))
    );
}

#[test]
fn rerun_reproduces_a_generation_and_reports_any_member_that_does_not() {
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(
        &[
            "fit",
            "--method",
            "ga",
            "--generations",
            "3",
            "--population",
            "10",
            "--no-figures",
            "--out",
            "r",
        ],
        dir.path(),
    ));
    let ckpt = dir.path().join("r/generations/gen-0003.json");
    let out = ok(&sepval(&["rerun", ckpt.to_str().unwrap()], dir.path()));
    assert!(
        out.contains("generation 3: all 10 population and")
            && out.contains("archive members reproduce their goals bit for bit"),
        "{out}"
    );

    // Tamper with one member's goal: rerun must name it and fail (the digest sees it first;
    // edits sealed again with a matching digest: tests/cli/checkpoint.rs).
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(&ckpt).unwrap()).unwrap();
    let j = v["state"]["population"][4]["outcome"]["j_pos_m"]
        .as_f64()
        .unwrap();
    v["state"]["population"][4]["outcome"]["j_pos_m"] = Value::from(j * (1.0 + 1e-15));
    let bad = dir.path().join("tampered.json");
    std::fs::write(&bad, serde_json::to_string(&v).unwrap()).unwrap();
    let out = sepval(&["rerun", bad.to_str().unwrap()], dir.path());
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&format!(
            "checkpoint {}: its content does not match its digest: edited by hand? (changed: \
             state.population[4])",
            bad.display()
        )),
        "{err}"
    );
}

#[test]
fn a_checkpoint_with_other_data_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(
        &[
            "fit",
            "--method",
            "ga",
            "--generations",
            "2",
            "--population",
            "10",
            "--no-figures",
            "--out",
            "r",
        ],
        dir.path(),
    ));
    ok(&sepval(
        &["simulate", "--noise-seed", "99", "--out", "other.csv"],
        dir.path(),
    ));
    let ckpt = "r/generations/gen-0002.json";
    for args in [
        vec!["rerun", ckpt, "--data", "other.csv"],
        vec!["fit", "--resume", ckpt, "--data", "other.csv", "--out", "x"],
    ] {
        let out = sepval(&args, dir.path());
        assert_eq!(out.status.code(), Some(2));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("was made with other data"), "{err}");
    }
    std::fs::write(dir.path().join("junk.json"), "{\"format\": 1}").unwrap();
    let out = sepval(&["rerun", "junk.json"], dir.path());
    assert!(
        String::from_utf8_lossy(&out.stderr)
            .contains("checkpoint junk.json is not a sepval checkpoint")
    );
}

#[test]
fn bad_fit_settings_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    for (args, expected) in [
        (
            vec!["--population", "7"],
            "GA setting population = 7: expected an even number >= 2",
        ),
        (
            vec!["--p-jump", "1.5"],
            "GA setting p_jump = 1.5: expected a probability in [0, 1]",
        ),
        (
            vec!["--method", "anneal"],
            "--method anneal: expected ga, hill, both, ga+lm or hill+lm",
        ),
        (
            vec!["--evaluator", "carrier-pigeon"],
            "--evaluator carrier-pigeon",
        ),
        (
            vec!["--evaluator", "inproc", "--threads", "0"],
            "--threads 0: expected at least 1",
        ),
        (vec!["--workers", "0"], "--workers 0: expected at least 1"),
    ] {
        let mut all = vec!["fit", "--out", "x", "--no-figures"];
        all.extend(args);
        let out = sepval(&all, dir.path());
        assert_eq!(out.status.code(), Some(2));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(expected), "{err}");
    }
}

#[test]
fn a_hill_start_that_does_not_simulate_is_named_as_such() {
    // A wildly unstable store (roll damping of the wrong sign and a tiny roll inertia): the
    // nominal factors, where the hill climber starts, diverge.
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(&["scenario", "--out", "s.toml"], dir.path()));
    ok(&sepval(&["simulate", "--out", "d.csv"], dir.path()));
    let s = std::fs::read_to_string(dir.path().join("s.toml")).unwrap();
    let wild = s
        .replace("cl_p_per_rad = -40.0", "cl_p_per_rad = 400.0")
        .replace("ixx_kg_m2 = 27.116358966628006", "ixx_kg_m2 = 0.1");
    assert_ne!(wild, s);
    std::fs::write(dir.path().join("wild.toml"), wild).unwrap();
    let out = sepval(
        &[
            "fit",
            "--scenario",
            "wild.toml",
            "--data",
            "d.csv",
            "--method",
            "hill",
            "--no-figures",
            "--evaluator",
            "inproc",
            "--out",
            "run",
        ],
        dir.path(),
    );
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("the hill climber's start, the nominal factors (clamped to their bounds), does not simulate: it diverges at t = "),
        "{err}"
    );
    assert!(err.contains("--method ga or ga+lm"), "{err}");
}
