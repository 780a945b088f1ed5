//! Output directories that never destroy what a run reads or what sepval did not write (issue
//! 33, items 1 and 4): an `--out` that is, holds or lies inside an input is refused whatever
//! the flags (predict, plan and envelope from their `--from`, a fit resumed into its own
//! checkpoint's directory with `--overwrite`); `--overwrite` clears only what the manifest of
//! an ended run lists, unchanged (another tool's files, a file added or edited since, an older
//! sepval's marker are refused, named); an interrupted `predict --overwrite` keeps the earlier
//! prediction; `update --free ""` is refused as the flags are parsed, with nothing on disk; a
//! lock that names no process (`0`) is taken over, said; the update's refusal of a non-empty
//! directory suggests no `--resume`.

use super::hardening_on_disk::snapshot;
use std::path::{Path, PathBuf};
use std::time::Duration;

use sepval_tests::{interrupt, ok, refused, sepval, spawn_sepval, wait_for};

/// A small in-process `fit --method ga --population 6 --generations G --no-figures` into `out`
/// with `extra` flags.
fn fit(dir: &Path, generations: &str, out: &str, extra: &[&str]) -> std::process::Output {
    let mut a = vec![
        "fit",
        "--method",
        "ga",
        "--generations",
        generations,
        "--population",
        "6",
        "--evaluator",
        "inproc",
        "--no-figures",
        "--out",
        out,
    ];
    a.extend_from_slice(extra);
    sepval(&a, dir)
}

/// A copy of the directory `from` at `to`.
fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        let target = to.join(p.file_name().unwrap());
        if p.is_dir() {
            copy_dir(&p, &target);
        } else {
            std::fs::copy(&p, &target).unwrap();
        }
    }
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

/// Runs `args` with `--out OUT` for each `OUT` that is, lies inside or holds the input `F`:
/// each refused naming both, `F` unchanged and nothing made.
fn refused_into_input(dir: &Path, args: &[&str], input: &str) {
    let before = snapshot(&dir.join("F"));
    for (out, relation) in [("F", "is"), ("F/new", "lies inside"), (".", "holds")] {
        let mut a = args.to_vec();
        a.extend(["--overwrite", "--out", out]);
        let expected = format!("{out} {relation} {input}, an input of this run");
        let stderr = refused(&sepval(&a, dir), &expected);
        assert!(stderr.contains("give another --out"), "{stderr}");
        assert!(
            snapshot(&dir.join("F")) == before,
            "{args:?} --out {out}: F changed"
        );
        assert!(!dir.join("F/new").exists());
    }
}

#[test]
fn predict_plan_and_envelope_never_write_into_their_from() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let fixture = super::predict::fixture();
    copy_dir(&fixture.join("fit"), &d.join("F"));
    std::fs::copy(fixture.join("cond.toml"), d.join("cond.toml")).unwrap();
    let predict = [
        "predict",
        "--from",
        "F",
        "--scenario",
        "cond.toml",
        "--samples",
        "400",
        "--evaluator",
        "inproc",
    ];
    refused_into_input(d, &predict, "--from F");
    let aircraft = aircraft();
    let envelope = [
        "envelope",
        "--from",
        "F",
        "--aircraft",
        &aircraft,
        "--mach",
        "0.7:0.9:2",
        "--samples",
        "400",
        "--evaluator",
        "inproc",
    ];
    refused_into_input(d, &envelope, "--from F");
    // A diagnosis: plan's fixture's, copied.
    let plans = tempfile::tempdir().unwrap();
    copy_dir(
        &super::plan::fixture().join("diag"),
        &plans.path().join("F"),
    );
    let plan = [
        "plan",
        "--from",
        "F",
        "--mach",
        "0.6:0.9",
        "--points",
        "2",
        "--evaluator",
        "inproc",
    ];
    refused_into_input(plans.path(), &plan, "--from F");
}

#[test]
fn overwrite_clears_only_what_an_ended_run_wrote_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Another tool's result.json and a README: named, kept.
    std::fs::create_dir(d.join("other")).unwrap();
    std::fs::write(d.join("other/result.json"), "{\"x\":1}").unwrap();
    std::fs::write(d.join("other/README"), "mine").unwrap();
    refused(
        &fit(d, "2", "other", &["--overwrite"]),
        "not clearing other: it is not a sepval output directory (it has no .sepval-run; it holds README, result.json)",
    );
    assert_eq!(
        std::fs::read_to_string(d.join("other/result.json")).unwrap(),
        "{\"x\":1}"
    );
    // A sepval run with a file of the user's beside it, or a file edited since.
    ok(&fit(d, "2", "run", &[]));
    let marker = std::fs::read_to_string(d.join("run/.sepval-run")).unwrap();
    assert!(marker.contains("\"result.json\": \""), "{marker}");
    std::fs::write(d.join("run/README"), "notes").unwrap();
    refused(
        &fit(d, "2", "run", &["--overwrite"]),
        "not clearing run: it holds what its run of `fit` did not write: README (not written by it)",
    );
    std::fs::remove_file(d.join("run/README")).unwrap();
    let result = d.join("run/result.json");
    let text = std::fs::read_to_string(&result).unwrap();
    std::fs::write(&result, text.replacen('{', "{\"note\": 1, ", 1)).unwrap();
    refused(
        &fit(d, "2", "run", &["--overwrite"]),
        "did not write: result.json (changed since)",
    );
    std::fs::write(&result, &text).unwrap();
    ok(&fit(d, "2", "run", &["--overwrite"]));
    // A marker copied into a directory of the user's does not make it sepval's.
    std::fs::create_dir(d.join("thesis")).unwrap();
    std::fs::copy(d.join("run/.sepval-run"), d.join("thesis/.sepval-run")).unwrap();
    std::fs::write(d.join("thesis/thesis.tex"), "x").unwrap();
    refused(
        &fit(d, "2", "thesis", &["--overwrite"]),
        "thesis.tex (not written by it)",
    );
    assert!(d.join("thesis/thesis.tex").exists());
    // An older sepval's marker lists no files: cleared by hand.
    std::fs::write(d.join("thesis/.sepval-run"), "{\"command\": \"fit\"}\n").unwrap();
    refused(
        &fit(d, "2", "thesis", &["--overwrite"]),
        "not clearing thesis: its .sepval-run (of a run of `fit`) was written by an older sepval, which listed no files, so what the run wrote cannot be told from what was added since; look at what it holds and remove it by hand (rm -r thesis)",
    );
    assert!(d.join("thesis/thesis.tex").exists());
}

#[test]
fn a_fit_resumed_with_overwrite_into_its_own_directory_keeps_its_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&fit(d, "4", "F", &[]));
    let before = snapshot(&d.join("F"));
    let ckpt = "F/generations/gen-0002.json";
    for out in ["F", "F/generations", "."] {
        let stderr = refused(
            &fit(d, "4", out, &["--resume", ckpt, "--overwrite"]),
            "an input of this run",
        );
        assert!(stderr.contains(ckpt), "{stderr}");
        assert!(snapshot(&d.join("F")) == before, "--out {out}: F changed");
    }
    // Without --overwrite it goes on in its own directory, as --resume does.
    ok(&fit(d, "4", "F", &["--resume", ckpt]));
    assert!(d.join("F/generations/gen-0002.json").is_file());
    assert!(d.join("F/generations/gen-0004.json").is_file());
}

#[test]
fn an_interrupted_predict_overwrite_keeps_the_earlier_prediction() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let fixture = super::predict::fixture();
    std::fs::copy(fixture.join("cond.toml"), d.join("cond.toml")).unwrap();
    let from = fixture.join("fit").display().to_string();
    let args = |samples: &'static str| {
        vec![
            "predict",
            "--from",
            &from,
            "--scenario",
            "cond.toml",
            "--samples",
            samples,
            "--evaluator",
            "inproc",
            "--threads",
            "1",
            "--overwrite",
            "--out",
            "P",
        ]
    };
    ok(&sepval(&args("400"), d));
    let before = snapshot(&d.join("P"));
    let mut child = spawn_sepval(&args("5000"), d);
    let lock = d.join("P/.sepval-lock");
    wait_for("the prediction's lock", Duration::from_secs(60), || {
        std::fs::read_to_string(&lock).is_ok_and(|t| t.ends_with('\n'))
    });
    interrupt(
        &mut child,
        libc::SIGINT,
        "the interrupted prediction",
        Duration::from_secs(30),
    );
    assert!(
        snapshot(&d.join("P")) == before,
        "the earlier prediction changed"
    );
    // And it is still an ended run's directory: cleared by the next --overwrite.
    ok(&sepval(&args("400"), d));
}

#[test]
fn update_refuses_an_empty_free_name_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&sepval(
        &["simulate", "--noise-seed", "1", "--out", "a.csv"],
        d,
    ));
    for (free, shown) in [
        ("", "\"\""),
        (",", ","),
        ("cmoff,", "cmoff,"),
        (" , cnoff", " , cnoff"),
    ] {
        refused(
            &sepval(
                &["update", "--data", "a.csv", "--free", free, "--out", "U"],
                d,
            ),
            &format!("--free {shown}: an empty factor name: expected names separated by commas"),
        );
        assert!(!d.join("U").exists(), "--free {free:?} wrote U");
    }
    // A directory that is not empty: the refusal suggests only what update can do.
    std::fs::create_dir(d.join("busy")).unwrap();
    std::fs::write(d.join("busy/notes.txt"), "x").unwrap();
    let stderr = refused(
        &sepval(&["update", "--data", "a.csv", "--out", "busy"], d),
        "busy is not empty (it holds notes.txt); give another directory, or clear it (--overwrite)",
    );
    assert!(!stderr.contains("resume"), "{stderr}");
}

#[test]
fn a_lock_that_names_no_process_is_taken_over_and_said() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (k, text) in ["0", "-1", "4294967295"].into_iter().enumerate() {
        let out = format!("L{k}");
        std::fs::create_dir(d.join(&out)).unwrap();
        std::fs::write(d.join(&out).join(".sepval-lock"), format!("{text}\n")).unwrap();
        let run = fit(d, "2", &out, &[]);
        ok(&run);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(
            stderr.contains(&format!(
                "sepval: took over the lock {out}/.sepval-lock: it holds `{text}`, which is no process id (1 to 2147483647), so it names no running process"
            )),
            "{stderr}"
        );
        assert!(!d.join(&out).join(".sepval-lock").exists());
        assert!(d.join(&out).join("result.json").is_file());
    }
}

/// A file `--out` (simulate's trajectory, scenario's TOML or DAVE-ML) that is the scenario
/// read, a table file the scenario names, or one of them by another name (`..`, a hard link),
/// is refused before any work, naming both, and every input is left as it was; a file that is
/// none of them is written.
#[test]
fn simulate_and_scenario_never_write_over_what_they_read() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let example = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/flowfield-store");
    for f in ["grid.toml", "field-grid.csv"] {
        std::fs::copy(example.join(f), d.join(f)).unwrap();
    }
    std::fs::create_dir(d.join("sub")).unwrap();
    std::fs::hard_link(d.join("field-grid.csv"), d.join("linked.csv")).unwrap();
    let read = |f: &str| std::fs::read(d.join(f)).unwrap();
    let before = [read("grid.toml"), read("field-grid.csv")];
    let table = "the table field-grid.csv that --scenario grid.toml names";
    for (out, input) in [
        ("grid.toml", "--scenario grid.toml"),
        ("sub/../grid.toml", "--scenario grid.toml"),
        ("field-grid.csv", table),
        ("linked.csv", table),
    ] {
        let expected = format!("--out {out}: {out} is {input}, an input of this run");
        for args in [
            vec!["simulate", "--scenario", "grid.toml", "--out", out],
            vec!["scenario", "--scenario", "grid.toml", "--out", out],
            vec![
                "scenario",
                "--scenario",
                "grid.toml",
                "--to-daveml",
                "--out",
                out,
            ],
        ] {
            let stderr = refused(&sepval(&args, d), &expected);
            assert!(stderr.contains("give another --out"), "{stderr}");
            assert_eq!(
                [read("grid.toml"), read("field-grid.csv")],
                before,
                "{args:?}"
            );
        }
    }
    let factors = "{}";
    std::fs::write(d.join("f.json"), factors).unwrap();
    refused(
        &sepval(&["simulate", "--factors", "f.json", "--out", "f.json"], d),
        "--out f.json: f.json is --factors f.json, an input of this run",
    );
    assert_eq!(std::fs::read_to_string(d.join("f.json")).unwrap(), factors);
    // A directory is no file name (`.` was "Device or resource busy").
    for out in [".", "sub"] {
        refused(
            &sepval(&["simulate", "--out", out], d),
            &format!("--out {out}: {out} is a directory: give the name of the file to write"),
        );
    }
    ok(&sepval(
        &["simulate", "--scenario", "grid.toml", "--out", "t.csv"],
        d,
    ));
}

#[test]
fn bench_and_a_failed_overwrite_leave_what_was_there() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // `bench --out` is a run directory: a directory of the user's files is refused, their
    // bench.csv as it was (before 2026-11-29 it was written over).
    std::fs::write(dir.join("bench.csv"), "my data").unwrap();
    let bench = |out: &str, extra: &[&str]| {
        let mut a = vec![
            "bench",
            "--workers",
            "1",
            "--evals",
            "20",
            "--repeat",
            "1",
            "--transports",
            "single",
            "--out",
            out,
        ];
        a.extend(extra);
        sepval(&a, dir)
    };
    refused(&bench(".", &[]), ". is not empty (it holds bench.csv)");
    assert_eq!(
        std::fs::read_to_string(dir.join("bench.csv")).unwrap(),
        "my data"
    );
    ok(&bench("b", &[]));
    refused(&bench("b", &[]), "clear it (--overwrite)");
    ok(&bench("b", &["--overwrite"]));
    // A fit with --overwrite that fails once it has cleared (its hill climber's start diverges
    // on this release) puts the earlier fit back as it was.
    ok(&fit(dir, "2", "keep", &[]));
    let before = snapshot(&dir.join("keep"));
    ok(&sepval(
        &[
            "simulate",
            "--t-end",
            "60",
            "--rate",
            "5",
            "--noise-seed",
            "1",
            "--out",
            "long.csv",
        ],
        dir,
    ));
    let failed = sepval(
        &[
            "fit",
            "--data",
            "long.csv",
            "--outliers",
            "drop",
            "--generations",
            "2",
            "--population",
            "6",
            "--evaluator",
            "inproc",
            "--no-figures",
            "--overwrite",
            "--out",
            "keep",
        ],
        dir,
    );
    refused(&failed, "diverges");
    assert_eq!(
        snapshot(&dir.join("keep")),
        before,
        "the earlier fit is gone"
    );
}

#[test]
fn a_closed_output_stream_is_no_defect() {
    use std::os::fd::FromRawFd;
    use std::process::{Command, Stdio};
    // `sepval effects | true`: the reader gone before the table is written. Before 2026-11-29
    // the broken pipe was an "internal error" (exit 2), and 101 with stderr closed too.
    let tmp = tempfile::tempdir().unwrap();
    // A pipe whose read end is closed before sepval starts: its first write is refused.
    let closed = || {
        let mut fds = [0; 2];
        // SAFETY: `fds` has room for the two descriptors `pipe` writes.
        assert_eq!(unsafe { libc::pipe(fds.as_mut_ptr()) }, 0);
        // SAFETY: the read end is ours and used nowhere else; the write end is owned by the
        // File from here on.
        unsafe {
            libc::close(fds[0]);
            Stdio::from(std::fs::File::from_raw_fd(fds[1]))
        }
    };
    let run = |args: &[&str], stderr: Stdio| {
        Command::new(sepval_tests::binary("sepval"))
            .args(args)
            .current_dir(tmp.path())
            .stdout(closed())
            .stderr(stderr)
            .output()
            .expect("run sepval")
    };
    let effects = run(&["effects"], Stdio::piped());
    assert_eq!(effects.status.code(), Some(0), "{effects:?}");
    assert!(effects.stderr.is_empty(), "{effects:?}");
    std::fs::write(tmp.path().join("bad.json"), "{\"factors\": 1}").unwrap();
    let refused = run(
        &["simulate", "--factors", "bad.json", "--out", "o.csv"],
        closed(),
    );
    assert_eq!(
        refused.status.code(),
        Some(2),
        "a refusal's status, not a panic's"
    );
    assert!(!tmp.path().join("o.csv").exists());
}
