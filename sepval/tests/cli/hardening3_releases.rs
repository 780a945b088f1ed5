//! Issue 33, items 5, 6, 7, 12 and three of 13's messages: a release given twice (a copy, a
//! hard link, a copy with a comment edited) or of another store is refused in every command
//! that pools releases; an outlier is named and refused or dropped in every command that reads
//! telemetry; a line without end is refused at the line bound; a missing file is said once, a
//! refused `--scenario` by its file, a number as it was given.

use std::path::Path;
use std::sync::OnceLock;

use super::hardening_on_disk::fit as small_fit;
use sepval_tests::{ok, refused, sepval};

/// `a.csv` and `b.csv` (two releases of the default store, noise seeds 6 and 7) in a fresh
/// directory.
fn releases() -> tempfile::TempDir {
    // Under target/ (CARGO_TARGET_TMPDIR), not /tmp: the shared fixture below is a static,
    // never dropped, so its directory is never removed.
    let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    for (seed, name) in [("6", "a.csv"), ("7", "b.csv")] {
        ok(&sepval(
            &["simulate", "--noise-seed", seed, "--out", name],
            dir.path(),
        ));
    }
    dir
}

/// The text of `file` with sample `k` (0-based) moved by `dz` in z, and that sample's line.
fn with_spike(file: &Path, k: usize, dz: f64) -> (String, usize) {
    let text = std::fs::read_to_string(file).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let header = lines.iter().position(|l| !l.starts_with('#')).unwrap();
    let row = header + 1 + k;
    let mut fields: Vec<String> = lines[row].split(',').map(str::to_string).collect();
    let z: f64 = fields[3].parse().unwrap();
    fields[3] = (z + dz).to_string();
    lines[row] = fields.join(",");
    (lines.join("\n") + "\n", row + 1)
}

/// The commands that pool the releases `data` (each as `--data`), refused before anything is
/// written with `expected` in the message.
fn refused_by_every_pooling_command(d: &Path, data: &[&str], expected: &str) {
    for (i, command) in ["fit", "diagnose", "update"].into_iter().enumerate() {
        let out = format!("out-{i}");
        let mut args = vec![command, "--evaluator", "inproc"];
        for f in data {
            args.extend(["--data", f]);
        }
        args.extend(["--out", &out]);
        refused(&sepval(&args, d), expected);
        assert!(!d.join(&out).exists(), "{command} wrote {out}");
    }
}

#[test]
fn a_release_given_twice_is_refused_by_its_content_naming_both_files() {
    let dir = releases();
    let d = dir.path();
    std::fs::copy(d.join("a.csv"), d.join("copy.csv")).unwrap();
    std::fs::hard_link(d.join("a.csv"), d.join("link.csv")).unwrap();
    // A comment edited, and a metadata line that names no condition.
    let text = std::fs::read_to_string(d.join("a.csv")).unwrap();
    let edited = text
        .replacen("# sepval simulate", "# flight 2, sepval simulate", 1)
        .replacen("# effects = ", "# effects = (copied) ", 1);
    assert_ne!(edited, text);
    std::fs::write(d.join("edited.csv"), edited).unwrap();
    for copy in ["copy.csv", "link.csv", "edited.csv"] {
        refused_by_every_pooling_command(
            d,
            &["a.csv", "b.csv", copy],
            &format!(
                "--data {copy} holds the same samples as --data a.csv: give each release once"
            ),
        );
    }
    // Held out, the same: a copy of a release fitted, or of one held out already.
    refused(
        &sepval(
            &[
                "update",
                "--data",
                "a.csv",
                "--validate",
                "b.csv",
                "--validate",
                "edited.csv",
                "--out",
                "u",
            ],
            d,
        ),
        "--validate edited.csv holds the same samples as --data a.csv: a release used for \
         fitting cannot measure prediction",
    );
    assert!(!d.join("u").exists());
}

#[test]
fn releases_of_another_store_are_not_pooled_and_the_field_is_named() {
    let dir = releases();
    let d = dir.path();
    let text = std::fs::read_to_string(d.join("b.csv")).unwrap();
    let heavy = format!("# store.mass_kg = 500\n# store.diameter_m = 0.3\n{text}");
    std::fs::write(d.join("heavy.csv"), heavy).unwrap();
    refused_by_every_pooling_command(
        d,
        &["a.csv", "heavy.csv"],
        "heavy.csv: its metadata records another store than the one fitted (the embedded \
         default scenario): store.mass_kg is 500, not 907.18474; releases of different stores \
         are not pooled: fit each store with its own --scenario",
    );
    // The key may be given without `store.`; a value that is the store's is accepted.
    std::fs::write(d.join("thin.csv"), format!("# diameter_m = 0.3\n{text}")).unwrap();
    refused(
        &sepval(
            &["fit", "--data", "a.csv", "--data", "thin.csv", "--out", "f"],
            d,
        ),
        "store.diameter_m is 0.3, not",
    );
    std::fs::write(d.join("same.csv"), format!("# mass_kg = 907.18474\n{text}")).unwrap();
    ok(&small_fit(
        d,
        "2",
        &["--data", "a.csv", "--data", "same.csv", "--out", "f"],
    ));
}

/// A fit to `a.csv` and `b.csv` that `predict` accepts (`--method ga+lm`, small budgets), and a
/// condition `cond.toml` of its store.
fn source() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = releases();
        let d = dir.path();
        ok(&sepval(
            &[
                "fit",
                "--data",
                "a.csv",
                "--data",
                "b.csv",
                "--method",
                "ga+lm",
                "--generations",
                "3",
                "--population",
                "20",
                "--lm-budget",
                "200",
                "--evaluator",
                "inproc",
                "--no-figures",
                "--out",
                "fit",
            ],
            d,
        ));
        ok(&sepval(&["scenario", "--out", "cond.toml"], d));
        let cond = std::fs::read_to_string(d.join("cond.toml")).unwrap();
        let heavy = cond.replacen("mass_kg = 907.18474", "mass_kg = 1000", 1);
        assert_ne!(heavy, cond);
        std::fs::write(d.join("heavy.toml"), heavy).unwrap();
        dir
    })
    .path()
}

#[test]
fn outliers_are_named_with_file_line_channel_and_size_then_refused_or_dropped() {
    let dir = releases();
    let d = dir.path();
    let (spiky, line) = with_spike(&d.join("a.csv"), 60, 10.0);
    std::fs::write(d.join("spiky.csv"), spiky).unwrap();
    let named = format!(
        "spiky.csv: 1 outlier(s), sample(s) far from the trend of their neighbours (docs/model.md section 6): line {line}, z_m = "
    );
    let remedy = "m from the trend (threshold 0.5 m); correct the file, or give --outliers \
                  drop to leave out the rows that hold one";
    for args in [
        vec!["fit", "--data", "spiky.csv", "--out", "o"],
        vec!["diagnose", "--data", "spiky.csv", "--out", "o"],
        vec!["update", "--data", "spiky.csv", "--out", "o"],
        vec![
            "diagnose",
            "--data",
            "b.csv",
            "--validate",
            "spiky.csv",
            "--out",
            "o",
        ],
        vec!["goals", "--data", "spiky.csv", "--sim", "a.csv"],
    ] {
        let err = refused(&sepval(&args, d), &named);
        assert!(err.contains(remedy), "{err}");
        assert!(!d.join("o").exists(), "{args:?}");
    }
    // Dropped: the row goes (said on stderr), from both files of `goals`.
    let out = sepval(
        &[
            "goals",
            "--data",
            "spiky.csv",
            "--sim",
            "a.csv",
            "--outliers",
            "drop",
        ],
        d,
    );
    ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(&format!(
            "--outliers drop: left out 1 row(s) of spiky.csv holding an outlier: line {line}, z_m = "
        )),
        "{stderr}"
    );
    assert!(
        stderr.contains("--outliers drop: left out 1 row(s) of a.csv"),
        "{stderr}"
    );
    // A fit that dropped it records so; rerun reads its data the same way.
    ok(&small_fit(
        d,
        "2",
        &[
            "--data",
            "spiky.csv",
            "--outliers",
            "drop",
            "--out",
            "dropped",
        ],
    ));
    let result: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("dropped/result.json")).unwrap()).unwrap();
    assert_eq!(result["inputs"]["outliers"], "drop");
    ok(&sepval(
        &[
            "rerun",
            "dropped/generations/gen-0002.json",
            "--evaluator",
            "inproc",
        ],
        d,
    ));
}

#[test]
fn predict_names_outliers_stores_and_the_scenario_file() {
    let d = source();
    let (spiky, line) = with_spike(&d.join("b.csv"), 90, -10.0);
    std::fs::write(d.join("spiky-b.csv"), spiky).unwrap();
    let base = [
        "predict",
        "--from",
        "fit",
        "--evaluator",
        "inproc",
        "--out",
        "p",
    ];
    let with = |extra: &[&str]| {
        let mut a = base.to_vec();
        a.extend_from_slice(extra);
        sepval(&a, d)
    };
    refused(
        &with(&["--scenario", "cond.toml", "--validate", "spiky-b.csv"]),
        &format!(
            "--validate spiky-b.csv: spiky-b.csv: 1 outlier(s), sample(s) far from the trend of their neighbours (docs/model.md section 6): line {line}, z_m = "
        ),
    );
    refused(
        &with(&["--scenario", "cond.toml", "--data", "spiky-b.csv"]),
        "--data spiky-b.csv: spiky-b.csv: 1 outlier(s)",
    );
    refused(
        &with(&["--scenario", "heavy.toml"]),
        "--scenario heavy.toml: its store differs from that of the releases fitted (eglin-benchmark-store): store.mass_kg is 1000, not 907.18474",
    );
    refused(
        &with(&["--scenario", "cond.toml", "--level", "1e308"]),
        "--level 1e308: expected a number between 0 and 1",
    );
    assert!(!d.join("p").exists());
}

#[test]
fn a_line_without_end_is_refused_after_the_line_bound() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A gigabyte of NUL bytes that takes no disk (a sparse file).
    let zeros = std::fs::File::create(d.join("zeros.csv")).unwrap();
    zeros.set_len(1 << 30).unwrap();
    for args in [
        vec!["fit", "--data", "zeros.csv", "--out", "o"],
        vec!["goals", "--data", "zeros.csv", "--sim", "zeros.csv"],
    ] {
        refused(
            &sepval(&args, d),
            "zeros.csv: line 1 is longer than 65536 bytes, the limit of a telemetry line \
             (sepval_core::limits; a row is a few hundred bytes): is it a telemetry file?",
        );
    }
    assert!(!d.join("o").exists());
}

#[test]
fn messages_say_a_missing_file_once_and_numbers_as_given() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let err = refused(
        &sepval(
            &["simulate", "--aircraft", "missing.toml", "--out", "x.csv"],
            d,
        ),
        "missing.toml: cannot read the geometry file: No such file or directory (os error 2)",
    );
    assert_eq!(err.matches("os error 2").count(), 1, "{err}");
    let err = refused(
        &sepval(&["fit", "--data", "missing.csv", "--out", "o"], d),
        "missing.csv",
    );
    assert_eq!(err.matches("os error 2").count(), 1, "{err}");
    refused(
        &sepval(&["simulate", "--t-end", "1e308", "--out", "x.csv"], d),
        "--t-end 1e308: an event of 1e308 s is longer than the limit of 3600 s",
    );
    refused(
        &sepval(&["fit", "--worker-timeout", "1e308", "--out", "o"], d),
        "--worker-timeout = 1e308: expected at most 32 000 000 s (a year)",
    );
    assert!(!d.join("x.csv").exists() && !d.join("o").exists());
}
