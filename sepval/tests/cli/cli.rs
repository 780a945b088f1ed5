//! The `sepval` command line, run as a user runs it.

use sepval_common::telemetry::Trajectory;
use sepval_tests::{ok, refused, sepval};

#[test]
fn simulate_truth_reproduces_the_conformance_table() {
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(
        &["simulate", "--factors", "truth", "--out", "t.csv"],
        dir.path(),
    ));
    let t = Trajectory::read(&dir.path().join("t.csv")).unwrap();
    assert_eq!(t.len(), 201);
    // docs/model.md section 8 at t = 1.0 s.
    let last = t.len() - 1;
    assert!((t.pos_m[last][2] - 5.780992554).abs() < 1e-9);
    assert!((t.att_deg[last][0] - 26.0943588).abs() < 1e-7);
    assert_eq!(t.meta("noise"), Some("none"));
}

#[test]
fn noise_is_seeded() {
    let dir = tempfile::tempdir().unwrap();
    for (name, seed) in [("a.csv", "7"), ("b.csv", "7"), ("c.csv", "8")] {
        ok(&sepval(
            &["simulate", "--noise-seed", seed, "--out", name],
            dir.path(),
        ));
    }
    let read = |n: &str| std::fs::read_to_string(dir.path().join(n)).unwrap();
    assert_eq!(read("a.csv"), read("b.csv"));
    assert_ne!(read("a.csv"), read("c.csv"));
    let out = sepval(&["goals", "--data", "a.csv", "--sim", "c.csv"], dir.path());
    ok(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    let j_pos: f64 = text
        .lines()
        .next()
        .unwrap()
        .split_whitespace()
        .nth(2)
        .unwrap()
        .parse()
        .unwrap();
    // Two independent noises: RMS difference sqrt(2) sigma.
    assert!(
        (j_pos / (0.003 * 2f64.sqrt()) - 1.0).abs() < 0.15,
        "{j_pos}"
    );
}

#[test]
fn t_end_rate_and_effects_are_honoured() {
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(
        &[
            "simulate",
            "--t-end",
            "0.5",
            "--rate",
            "100",
            "--effect",
            "roll_due_to_sideslip=-0.3",
            "--effect",
            "release_rates=0,0.1,0",
            "--out",
            "e.csv",
        ],
        dir.path(),
    ));
    let t = Trajectory::read(&dir.path().join("e.csv")).unwrap();
    assert_eq!(t.len(), 51);
    assert_eq!(
        t.meta("effects"),
        Some("roll_due_to_sideslip=-0.3 release_rates=0,0.1,0")
    );
}

#[test]
fn bad_factors_files_are_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let truth = r#"{"fwdfac":0.25,"aftfac":0.8,"xinerfac":1.04,"yinerfac":0.96,"zinerfac":1.02,
        "caoff":0.03,"cyoff":-0.05,"czoff":0.08,"cmoff":-0.14,"cnoff":0.1,"cloff":0.03,
        "caintfac":1.3,"cyintfac":0.8,"czintfac":1.5,"cmintfac":0.7,"cnintfac":1.2,"clintfac":0.6}"#;
    let cases = [
        (
            truth.replace("\"fwdfac\"", "\"fwd\""),
            "unknown factor `fwd`",
        ),
        (
            truth.replace(",\"clintfac\":0.6}", "}"),
            "factor `clintfac` is missing",
        ),
        (
            truth.replace("\"aftfac\":0.8", "\"aftfac\":1.8"),
            "factor `aftfac` = 1.8 is outside its bounds [0.2, 1]",
        ),
        (
            truth.replace("\"aftfac\":0.8", "\"aftfac\":null"),
            "factor `aftfac`: expected a number, found null",
        ),
        (
            "[1, 2]".to_string(),
            "expected a JSON object mapping the 17 factor names to numbers",
        ),
    ];
    for (k, (text, expected)) in cases.iter().enumerate() {
        let f = format!("f{k}.json");
        std::fs::write(dir.path().join(&f), text).unwrap();
        let out = sepval(&["simulate", "--factors", &f, "--out", "o.csv"], dir.path());
        refused(&out, expected);
        refused(&out, &format!("factors file {f}"));
        assert!(!dir.path().join("o.csv").exists());
    }
    let out = sepval(
        &["simulate", "--factors", "missing.json", "--out", "o.csv"],
        dir.path(),
    );
    refused(&out, "missing.json: cannot read factors file");
}

#[test]
fn bad_flags_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    refused(
        &sepval(
            &["simulate", "--effect", "cg_offset=1,2", "--out", "o.csv"],
            dir.path(),
        ),
        "effect `cg_offset` takes 1 parameter(s) (dx_cg [m]), 2 given",
    );
    refused(
        &sepval(&["simulate", "--rate", "0", "--out", "o.csv"], dir.path()),
        "--rate = 0",
    );
    refused(
        &sepval(
            &["simulate", "--t-end", "NaN", "--out", "o.csv"],
            dir.path(),
        ),
        "--t-end = NaN: expected a finite number > 0",
    );
    refused(
        &sepval(&["simulate", "--out", "no/such/dir/o.csv"], dir.path()),
        "cannot write no/such/dir/o.csv",
    );
    assert!(!dir.path().join("o.csv").exists());
}

#[test]
fn goals_refuse_bad_csv_with_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(&["simulate", "--out", "good.csv"], dir.path()));
    std::fs::write(
        dir.path().join("bad.csv"),
        "t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0,0\n0.005,0,0,zz,0,0,0\n",
    )
    .unwrap();
    refused(
        &sepval(
            &["goals", "--data", "bad.csv", "--sim", "good.csv"],
            dir.path(),
        ),
        "bad.csv: line 3, column 4 (`z_m`): expected a number, found `zz`",
    );
    std::fs::write(
        dir.path().join("short.csv"),
        "t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0,0\n",
    )
    .unwrap();
    refused(
        &sepval(
            &["goals", "--data", "short.csv", "--sim", "good.csv"],
            dir.path(),
        ),
        "the trajectories have 1 and 201 samples",
    );
    let out = sepval(
        &["goals", "--data", "good.csv", "--sim", "good.csv"],
        dir.path(),
    );
    ok(&out);
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "J_pos = 0.000000000 m\nJ_att = 0.000000000 deg\n"
    );
}

#[test]
fn effects_lists_the_catalogue() {
    let dir = tempfile::tempdir().unwrap();
    let out = sepval(&["effects"], dir.path());
    ok(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    for id in [
        "roll_due_to_sideslip",
        "cg_offset",
        "tracked_point_offset",
        "telemetry_time_offset",
    ] {
        assert!(text.contains(id), "{id}");
    }
    assert!(text.contains("dt_tm     [s]"));
}

#[test]
fn a_written_scenario_reproduces_the_default() {
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(&["scenario", "--out", "s.toml"], dir.path()));
    ok(&sepval(
        &["simulate", "--scenario", "s.toml", "--out", "a.csv"],
        dir.path(),
    ));
    ok(&sepval(&["simulate", "--out", "b.csv"], dir.path()));
    let a = Trajectory::read(&dir.path().join("a.csv")).unwrap();
    let b = Trajectory::read(&dir.path().join("b.csv")).unwrap();
    assert_eq!(a.pos_m, b.pos_m);
    assert_eq!(a.att_deg, b.att_deg);
    std::fs::write(dir.path().join("bad.toml"), "name = 3\n").unwrap();
    refused(
        &sepval(
            &["simulate", "--scenario", "bad.toml", "--out", "c.csv"],
            dir.path(),
        ),
        "scenario bad.toml:",
    );
}

#[test]
fn selftest_zdt_prints_a_hypervolume() {
    let dir = tempfile::tempdir().unwrap();
    let out = sepval(
        &[
            "selftest",
            "zdt",
            "--problem",
            "zdt1",
            "--evaluations",
            "4000",
            "--seed",
            "3",
        ],
        dir.path(),
    );
    ok(&out);
    let hv: f64 = String::from_utf8_lossy(&out.stdout).trim().parse().unwrap();
    assert!(hv > 0.0 && hv < 0.8767, "{hv}");
    // Same seed, same answer.
    let again = sepval(
        &[
            "selftest",
            "zdt",
            "--problem",
            "zdt1",
            "--evaluations",
            "4000",
            "--seed",
            "3",
        ],
        dir.path(),
    );
    assert_eq!(again.stdout, out.stdout);
    refused(
        &sepval(&["selftest", "zdt", "--problem", "zdt9"], dir.path()),
        "--problem zdt9: expected zdt1, zdt2 or zdt3",
    );
}

#[test]
fn help_shows_units_as_written() {
    // Doc comments are the help text; markdown escapes meant for rustdoc must not leak into it.
    let dir = tempfile::tempdir().unwrap();
    for command in [&["fit", "--help"][..], &["simulate", "--help"], &["--help"]] {
        let help = ok(&sepval(command, dir.path()));
        assert!(!help.contains('\\'), "{command:?}:\n{help}");
    }
    let fit = ok(&sepval(&["fit", "--help"], dir.path()));
    assert!(
        fit.contains("How long to wait for workers to join [s]"),
        "{fit}"
    );
}
