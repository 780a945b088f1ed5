//! A refusal never deletes or rewrites anything: a resume whose inputs changed keeps the later
//! generations, `--overwrite` clears nothing for a run refused over its inputs, a refused run
//! leaves no marker in the directory it was given. And the inputs of a checkpoint and of a
//! diagnosis are what they say: `rerun` takes each input not given from the checkpoint's
//! record, `--validate` refuses a copy of a `--data` file.

use std::collections::BTreeMap;
use std::path::Path;

use sepval_tests::{ok, refused, sepval};

/// A model extension of one term (docs/discovery.md).
const EXTENSION: &str = "format = \"sepval-extension/1\"\n\n[[term]]\naxis = \"CY\"\nfamily = \
                         \"step\"\nregressor = \"step\"\nt_on_s = 0.4\ncoefficient = 0.05\n";

/// A small in-process `fit --method ga --population 10 --generations G` with `extra` flags.
pub(crate) fn fit(dir: &Path, generations: &str, extra: &[&str]) -> std::process::Output {
    let mut a = vec![
        "fit",
        "--method",
        "ga",
        "--generations",
        generations,
        "--population",
        "10",
        "--evaluator",
        "inproc",
        "--no-figures",
    ];
    a.extend_from_slice(extra);
    sepval(&a, dir)
}

/// Every file under `dir` (relative path to content), the lock aside.
pub(crate) fn snapshot(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if !p.ends_with(".sepval-lock") {
                let name = p.strip_prefix(dir).unwrap().display().to_string();
                files.insert(name, std::fs::read(&p).unwrap());
            }
        }
    }
    files
}

/// A change of a file's text.
type TextEdit = fn(&str) -> String;

/// `path` with its text edited by `edit` (which must change it); returns the original text.
fn edit(path: &Path, edit: impl FnOnce(&str) -> String) -> String {
    let before = std::fs::read_to_string(path).unwrap();
    let after = edit(&before);
    assert_ne!(after, before, "{} unchanged", path.display());
    std::fs::write(path, after).unwrap();
    before
}

/// The last field of the last row of a CSV text scaled by 1.5 (a table value).
fn scale_last_value(text: &str) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let last = lines.last_mut().unwrap();
    let (head, value) = last.rsplit_once(',').unwrap();
    let v: f64 = value.trim().parse().unwrap();
    *last = format!("{head},{}", if v.abs() < 1e-9 { 0.01 } else { v * 1.5 });
    lines.join("\n") + "\n"
}

/// The last field of the last row of a CSV text moved by 0.05 (the yaw of the last sample by
/// half its noise): other data, where a change of 1.5 times would be an outlier, refused as
/// such before the checkpoint is compared (docs/model.md section 6).
fn nudge_last_value(text: &str) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let last = lines.last_mut().unwrap();
    let (head, value) = last.rsplit_once(',').unwrap();
    let v: f64 = value.trim().parse().unwrap();
    *last = format!("{head},{}", v + 0.05);
    lines.join("\n") + "\n"
}

#[test]
fn a_resume_refused_over_changed_inputs_keeps_the_later_generations_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&sepval(&["scenario", "--tables", "--out", "tab"], d));
    ok(&sepval(
        &["simulate", "--noise-seed", "3", "--out", "data.csv"],
        d,
    ));
    std::fs::write(d.join("ext.toml"), EXTENSION).unwrap();
    let inputs = [
        "--scenario",
        "tab/scenario.toml",
        "--data",
        "data.csv",
        "--extension",
        "ext.toml",
    ];
    let mut first = inputs.to_vec();
    first.extend(["--out", "F"]);
    ok(&fit(d, "4", &first));
    let before = snapshot(&d.join("F"));
    assert!(
        before.contains_key("generations/gen-0004.json"),
        "{before:?}"
    );
    let table = std::fs::read_dir(d.join("tab/tables"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|x| x == "csv"))
        .unwrap();
    let changes: [(&Path, TextEdit, &str); 3] = [
        (&table, scale_last_value, "was made with another scenario"),
        (
            &d.join("data.csv"),
            nudge_last_value,
            "was made with other data",
        ),
        (
            &d.join("ext.toml"),
            |t| t.replace("0.05", "0.06"),
            "was made with another scenario",
        ),
    ];
    for (path, change, expected) in changes {
        let original = edit(path, change);
        for overwrite in [&[][..], &["--overwrite"][..]] {
            let mut resume = inputs.to_vec();
            resume.extend(["--resume", "F/generations/gen-0002.json", "--out", "F"]);
            resume.extend_from_slice(overwrite);
            // Every input is checked before the directory is claimed (command/sequence.rs),
            // so the changed input is refused first, with --overwrite or without.
            let stderr = refused(&fit(d, "4", &resume), expected);
            assert!(!stderr.contains("removed"), "{stderr}");
            assert!(
                snapshot(&d.join("F")) == before,
                "{}{overwrite:?}: F changed",
                path.display()
            );
        }
        std::fs::write(path, original).unwrap();
    }
    // The inputs as they were: with --overwrite, F is refused as the run directory of the
    // checkpoint it resumes from (clearing it would remove the checkpoint), and stays as it was.
    let mut resume = inputs.to_vec();
    resume.extend([
        "--resume",
        "F/generations/gen-0002.json",
        "--out",
        "F",
        "--overwrite",
    ]);
    let expected = "F is the run directory F of --resume F/generations/gen-0002.json";
    let stderr = refused(&fit(d, "4", &resume), expected);
    assert!(!stderr.contains("removed"), "{stderr}");
    assert!(snapshot(&d.join("F")) == before, "F changed");
}

#[test]
fn overwrite_clears_nothing_for_a_run_refused_over_its_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&fit(d, "2", &["--out", "F"]));
    let before = snapshot(&d.join("F"));
    std::fs::write(d.join("bad.csv"), "t_s,x_m\n0,0\n").unwrap();
    for cmd in [
        vec!["fit", "--data", "bad.csv", "--overwrite", "--out", "F"],
        vec!["fit", "--data", "missing.csv", "--overwrite", "--out", "F"],
        vec!["diagnose", "--data", "bad.csv", "--overwrite", "--out", "F"],
        vec![
            "diagnose",
            "--validate",
            "missing.csv",
            "--overwrite",
            "--out",
            "F",
        ],
    ] {
        let out = sepval(&cmd, d);
        assert_eq!(out.status.code(), Some(2), "{cmd:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains("bad.csv") || stderr.contains("missing.csv"),
            "{cmd:?}: {stderr}"
        );
        assert!(snapshot(&d.join("F")) == before, "{cmd:?}: F changed");
    }
    // A directory of the user's, empty: a refused run leaves no marker in it.
    std::fs::create_dir(d.join("empty")).unwrap();
    refused(
        &fit(d, "2", &["--data", "bad.csv", "--out", "empty"]),
        "bad.csv",
    );
    assert_eq!(std::fs::read_dir(d.join("empty")).unwrap().count(), 0);
}

#[test]
fn rerun_takes_each_input_not_given_from_the_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&sepval(
        &["simulate", "--noise-seed", "5", "--out", "data.csv"],
        d,
    ));
    std::fs::write(d.join("ext.toml"), EXTENSION).unwrap();
    ok(&fit(
        d,
        "2",
        &[
            "--data",
            "data.csv",
            "--extension",
            "ext.toml",
            "--out",
            "F",
        ],
    ));
    let ckpt = "F/generations/gen-0002.json";
    for given in [
        vec!["--extension", "ext.toml"],
        vec!["--data", "data.csv"],
        vec![],
    ] {
        let mut a = vec!["rerun", ckpt, "--evaluator", "inproc"];
        a.extend_from_slice(&given);
        let stdout = ok(&sepval(&a, d));
        assert!(
            stdout.contains("reproduce their goals bit for bit"),
            "{given:?}: {stdout}"
        );
    }
    // A given input still has to be the recorded one.
    std::fs::write(d.join("other.toml"), EXTENSION.replace("0.05", "0.07")).unwrap();
    refused(
        &sepval(
            &[
                "rerun",
                ckpt,
                "--evaluator",
                "inproc",
                "--extension",
                "other.toml",
            ],
            d,
        ),
        "was made with another extension: --extension other.toml is not the one it was made with",
    );
}

#[test]
fn validate_refuses_a_copy_of_a_data_file_naming_both() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&sepval(
        &["simulate", "--noise-seed", "6", "--out", "a.csv"],
        d,
    ));
    ok(&sepval(
        &["simulate", "--noise-seed", "7", "--out", "b.csv"],
        d,
    ));
    std::fs::copy(d.join("a.csv"), d.join("copy.csv")).unwrap();
    let text = std::fs::read_to_string(d.join("b.csv")).unwrap();
    std::fs::write(d.join("b-again.csv"), format!("# a comment\n{text}")).unwrap();
    for (args, expected) in [
        (
            vec!["--data", "a.csv", "--validate", "copy.csv"],
            "--validate copy.csv holds the same samples as --data a.csv: a release used for \
             fitting cannot measure prediction",
        ),
        (
            vec![
                "--data",
                "a.csv",
                "--validate",
                "b.csv",
                "--validate",
                "b-again.csv",
            ],
            "--validate b-again.csv holds the same samples as --validate b.csv: give each \
             release once",
        ),
    ] {
        let mut a = vec!["diagnose"];
        a.extend_from_slice(&args);
        a.extend(["--out", "diag"]);
        refused(&sepval(&a, d), expected);
        assert!(!d.join("diag").exists(), "{args:?}");
    }
}
