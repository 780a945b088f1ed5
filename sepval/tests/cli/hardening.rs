//! Bad input and faults, as a careless or hostile user brings them: extreme values, work beyond
//! the limits, a signal during a long diagnosis, too few samples, reused and shared output
//! directories, repeated inputs. Every refusal exits with status 2 and names what was wrong and
//! where; nothing is left behind.

use std::path::Path;
use std::time::Duration;

use sepval_tests::{
    assert_run_gone, ok, processes_of_run, refused, run_id, sepval, signal, spawn_sepval,
    wait_exit, wait_for,
};

const HEADER: &str = "t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n";

/// A noisy flight test with the value of sample `sample` (0-based) in column `column`
/// (1-based) replaced; returns the line of that sample in the file.
fn with_value(dir: &Path, name: &str, sample: usize, column: usize, value: &str) -> usize {
    ok(&sepval(
        &["simulate", "--noise-seed", "1", "--out", name],
        dir,
    ));
    let text = std::fs::read_to_string(dir.join(name)).unwrap();
    let line = text.lines().position(|l| l.starts_with("t_s")).unwrap() + 2 + sample;
    let edited: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(k, l)| {
            if k + 1 == line {
                let mut f: Vec<&str> = l.split(',').collect();
                f[column - 1] = value;
                f.join(",")
            } else {
                l.to_string()
            }
        })
        .collect();
    std::fs::write(dir.join(name), edited.join("\n") + "\n").unwrap();
    line
}

#[test]
fn an_extreme_value_is_refused_where_it_stands_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let line = with_value(dir.path(), "big.csv", 10, 2, "1e308");
    for cmd in [
        vec!["diagnose", "--data", "big.csv", "--out", "d"],
        vec!["fit", "--data", "big.csv", "--out", "f"],
        vec!["goals", "--data", "big.csv", "--sim", "big.csv"],
    ] {
        refused(
            &sepval(&cmd, dir.path()),
            &format!(
                "big.csv: line {line}, column 2 (`x_m`): 1e308 is beyond the plausible bound of +-100000 m for a position"
            ),
        );
    }
    assert!(!dir.path().join("d").exists() && !dir.path().join("f").exists());
    with_value(dir.path(), "late.csv", 200, 1, "1e6");
    refused(
        &sepval(&["fit", "--data", "late.csv", "--out", "f"], dir.path()),
        "1e6 is beyond the plausible bound of +-3600 s for a sample time",
    );
}

#[test]
fn a_signal_stops_a_long_diagnosis_within_seconds_and_leaves_nothing_in_shared_memory() {
    let dir = tempfile::tempdir().unwrap();
    let run = run_id("sigterm");
    let mut d = spawn_sepval(
        &[
            "diagnose",
            "--generations",
            "400",
            "--workers",
            "2",
            "--run-id",
            &run,
            "--out",
            "d",
        ],
        dir.path(),
    );
    let ckpt = dir.path().join("d/baseline/generations/gen-0003.json");
    wait_for("the baseline fit", Duration::from_secs(60), || {
        ckpt.exists()
    });
    signal(d.id() as i32, libc::SIGTERM);
    let out = wait_exit(&mut d, "the interrupted diagnosis", Duration::from_secs(5));
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("interrupted by a signal"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_run_gone(&run);
    // The lock went with the process; the checkpoints written so far stay.
    assert!(!dir.path().join("d/.sepval-lock").exists());
    assert!(ckpt.exists());
}

#[test]
fn work_beyond_the_limits_is_refused_before_anything_is_allocated() {
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(&["scenario", "--out", "s.toml"], dir.path()));
    let s = std::fs::read_to_string(dir.path().join("s.toml")).unwrap();
    let fast = s.replace("rate_hz = 200.0", "rate_hz = 1e9");
    assert_ne!(fast, s);
    std::fs::write(dir.path().join("fast.toml"), fast).unwrap();
    refused(
        &sepval(
            &["simulate", "--scenario", "fast.toml", "--out", "o.csv"],
            dir.path(),
        ),
        "samples exceed the limit of 4000000 per event",
    );
    for (args, expected) in [
        (
            vec!["--t-end", "1e9"],
            "an event of 1000000000 s is longer than the limit of 3600 s",
        ),
        (
            vec!["--rate", "1e8"],
            "100000001 samples exceed the limit of 4000000 per event",
        ),
        (
            vec!["--t-end", "1e5"],
            "an event of 100000 s is longer than the limit of 3600 s",
        ),
    ] {
        let mut all = vec!["simulate", "--out", "o.csv"];
        all.extend(args);
        refused(&sepval(&all, dir.path()), expected);
    }
    assert!(!dir.path().join("o.csv").exists());
}

#[test]
fn a_short_record_fits_when_the_noise_is_given_and_says_what_is_missing_otherwise() {
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(
        &[
            "simulate",
            "--t-end",
            "0.015",
            "--noise-seed",
            "4",
            "--out",
            "short.csv",
        ],
        dir.path(),
    ));
    let fit = |extra: &[&str], out: &str| {
        let mut a = vec![
            "fit",
            "--data",
            "short.csv",
            "--method",
            "ga",
            "--generations",
            "2",
            "--population",
            "6",
            "--evaluator",
            "inproc",
            "--no-figures",
            "--out",
            out,
        ];
        a.extend_from_slice(extra);
        sepval(&a, dir.path())
    };
    ok(&fit(
        &["--sigma-pos-m", "0.003", "--sigma-att-deg", "0.1"],
        "a",
    ));
    let stderr = refused(
        &fit(&["--sigma-pos-m", "0.003"], "b"),
        "4 samples are too few to estimate the noise (5 at least)",
    );
    assert!(stderr.contains("--sigma-att-deg"), "{stderr}");
}

#[test]
fn an_output_directory_is_used_by_one_run_and_never_silently_reused() {
    let dir = tempfile::tempdir().unwrap();
    let fit = |out: &str, extra: &[&str]| {
        let mut a = vec![
            "fit",
            "--method",
            "ga",
            "--generations",
            "2",
            "--population",
            "6",
            "--evaluator",
            "inproc",
            "--no-figures",
            "--out",
            out,
        ];
        a.extend_from_slice(extra);
        sepval(&a, dir.path())
    };
    ok(&fit("r", &[]));
    refused(&fit("r", &[]), "r is not empty (it holds generations)");
    ok(&fit("r", &["--overwrite"]));
    // A directory sepval did not make is never cleared.
    std::fs::create_dir(dir.path().join("notes")).unwrap();
    std::fs::write(dir.path().join("notes/todo.txt"), "x").unwrap();
    refused(
        &fit("notes", &["--overwrite"]),
        "not clearing notes: it is not a sepval output directory",
    );
    assert!(dir.path().join("notes/todo.txt").exists());
    // A live holder of the lock: the run is refused, naming it.
    std::fs::write(
        dir.path().join("r/.sepval-lock"),
        format!("{}\n", std::process::id()),
    )
    .unwrap();
    refused(
        &fit("r", &["--overwrite"]),
        &format!("r is in use by sepval process {}", std::process::id()),
    );
    std::fs::remove_file(dir.path().join("r/.sepval-lock")).unwrap();
    // A file where a directory should be: refused before any worker starts.
    std::fs::write(dir.path().join("plain"), "x").unwrap();
    let run = run_id("outfile");
    let mut a = vec![
        "fit",
        "--method",
        "ga",
        "--generations",
        "2",
        "--population",
        "6",
        "--no-figures",
        "--out",
        "plain",
        "--run-id",
    ];
    a.push(&run);
    refused(
        &sepval(&a, dir.path()),
        "plain exists and is not a directory",
    );
    assert!(processes_of_run(&run).is_empty());
    assert_run_gone(&run);
}

#[test]
fn two_runs_into_one_directory_the_second_is_refused_naming_the_first() {
    let dir = tempfile::tempdir().unwrap();
    let mut first = spawn_sepval(
        &[
            "fit",
            "--method",
            "ga",
            "--generations",
            "400",
            "--population",
            "20",
            "--evaluator",
            "inproc",
            "--threads",
            "1",
            "--no-figures",
            "--out",
            "shared",
        ],
        dir.path(),
    );
    let lock = dir.path().join("shared/.sepval-lock");
    wait_for("the first run's lock", Duration::from_secs(30), || {
        std::fs::read_to_string(&lock).is_ok_and(|t| t.ends_with('\n'))
    });
    let second = sepval(
        &[
            "fit",
            "--method",
            "ga",
            "--generations",
            "2",
            "--evaluator",
            "inproc",
            "--no-figures",
            "--overwrite",
            "--out",
            "shared",
        ],
        dir.path(),
    );
    refused(
        &second,
        &format!("shared is in use by sepval process {}", first.id()),
    );
    signal(first.id() as i32, libc::SIGTERM);
    let out = wait_exit(&mut first, "the first run", Duration::from_secs(10));
    assert_eq!(out.status.code(), Some(130));
}

#[test]
fn small_mistakes_are_named() {
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(
        &["simulate", "--noise-seed", "2", "--out", "a.csv"],
        dir.path(),
    ));
    refused(
        &sepval(
            &["fit", "--data", "a.csv", "--data", "./a.csv", "--out", "x"],
            dir.path(),
        ),
        "--data ./a.csv is the same file as --data a.csv: give each release once",
    );
    // A spreadsheet export: byte-order mark and quoted fields.
    let text = std::fs::read_to_string(dir.path().join("a.csv")).unwrap();
    let quoted: String = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            l.split(',')
                .map(|f| format!("\"{f}\""))
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect::<Vec<_>>()
        .join("\r\n");
    std::fs::write(
        dir.path().join("excel.csv"),
        format!("\u{feff}{quoted}\r\n"),
    )
    .unwrap();
    let out = ok(&sepval(
        &["goals", "--data", "excel.csv", "--sim", "a.csv"],
        dir.path(),
    ));
    assert_eq!(out, "J_pos = 0.000000000 m\nJ_att = 0.000000000 deg\n");
    std::fs::write(
        dir.path().join("stray.csv"),
        format!("{HEADER}0,0,\"0,0,0,0,0\n"),
    )
    .unwrap();
    refused(
        &sepval(
            &["goals", "--data", "stray.csv", "--sim", "a.csv"],
            dir.path(),
        ),
        "stray.csv: line 2, column 3: unbalanced double quote",
    );
    // A cause is printed once, not repeated by its context.
    std::fs::write(dir.path().join("f.json"), "{\"fwdfac\": 0.3,").unwrap();
    let stderr = refused(
        &sepval(
            &["simulate", "--factors", "f.json", "--out", "o.csv"],
            dir.path(),
        ),
        "factors file f.json",
    );
    assert_eq!(stderr.matches("EOF while parsing").count(), 1, "{stderr}");
}

/// The goals `sepval goals` prints: J_pos \[m\], J_att \[deg\].
fn goals_printed(stdout: &str) -> [f64; 2] {
    let value = |key: &str| -> f64 {
        let line = stdout.lines().find(|l| l.starts_with(key)).unwrap();
        line.split_whitespace().nth(2).unwrap().parse().unwrap()
    };
    [value("J_pos"), value("J_att")]
}

/// Issue 21, item 5: DIR/extension.toml holds every term of the answer's model, the one given
/// with `--extension` included, so that the guide's recipe (`simulate --factors
/// DIR/factors.json --extension DIR/extension.toml`) reproduces the answer's goals.
#[test]
fn the_extension_written_reproduces_the_answer_with_the_users_terms() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let term = |axis: &str, regressor_lines: &str, c: f64| {
        format!("\n[[term]]\naxis = \"{axis}\"\n{regressor_lines}coefficient = {c}\n")
    };
    let given = term("Cl", "family = \"rate\"\nregressor = \"p\"\n", -0.5);
    let hidden = term(
        "CY",
        "family = \"step\"\nregressor = \"step\"\nt_on_s = 0.43\n",
        0.2,
    );
    let head = "format = \"sepval-extension/1\"\n";
    std::fs::write(dir.path().join("given.toml"), format!("{head}{given}")).unwrap();
    std::fs::write(
        dir.path().join("both.toml"),
        format!("{head}{given}{hidden}"),
    )
    .unwrap();
    ok(&sepval(
        &[
            "simulate",
            "--extension",
            "both.toml",
            "--noise-seed",
            "6",
            "--out",
            "d.csv",
        ],
        dir.path(),
    ));
    ok(&sepval(
        &[
            "diagnose",
            "--data",
            "d.csv",
            "--extension",
            "given.toml",
            "--generations",
            "20",
            "--evaluator",
            "inproc",
            "--threads",
            "2",
            "--out",
            "diag",
        ],
        dir.path(),
    ));
    let d: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("diag/diagnosis.json")).unwrap())
            .unwrap();
    assert_eq!(d["extension"]["answer"], true, "{}", d["verdict"]);
    let written = std::fs::read_to_string(dir.path().join("diag/extension.toml")).unwrap();
    assert!(written.contains("regressor = \"p\""), "{written}");
    assert!(written.contains("given with --extension"), "{written}");
    assert!(written.contains("family = \"step\""), "{written}");
    ok(&sepval(
        &[
            "simulate",
            "--factors",
            "diag/factors.json",
            "--extension",
            "diag/extension.toml",
            "--out",
            "again.csv",
        ],
        dir.path(),
    ));
    let printed = ok(&sepval(
        &["goals", "--data", "d.csv", "--sim", "again.csv"],
        dir.path(),
    ));
    let [jp, ja] = goals_printed(&printed);
    let model = &d["extension"]["model"];
    let (ep, ea) = (
        model["j_pos_m"].as_f64().unwrap(),
        model["j_att_deg"].as_f64().unwrap(),
    );
    // The same model simulated again: equal to the printed digits (1e-9 m, 1e-9 deg).
    assert!(
        (jp - ep).abs() < 1e-8 && (ja - ea).abs() < 1e-8,
        "{jp} {ja} vs {ep} {ea}"
    );
}
