//! The model extension through the binary: a malformed extension refused by `simulate`, `fit`
//! and `diagnose` with its file, line and field, nothing left behind; and an extension that
//! changes what `simulate` writes. Discovery itself, causes outside the catalogue found as
//! terms, is tested in process (`diagnose/tests/discovery`, slow tier); the binary's own run of
//! it end to end is `gust.rs`'s.

use sepval_common::telemetry::Trajectory;
use sepval_tests::{ok, sepval};

#[test]
fn a_malformed_extension_is_refused_with_file_line_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let good = "format = \"sepval-extension/1\"\n\n[[term]]\naxis = \"Cl\"\nfamily = \"rate\"\nregressor = \"p\"\ncoefficient = -0.5\n";
    for (name, text, needle) in [
        (
            "family",
            good.replace("\"rate\"", "\"gusts\""),
            "line 5, term 1, `family`",
        ),
        (
            "missing",
            good.replace("coefficient = -0.5\n", ""),
            "coefficient",
        ),
        ("nan", good.replace("-0.5", "nan"), "`coefficient`"),
        ("axis", good.replace("\"Cl\"", "\"Cq\""), "`axis`"),
        ("ejector", good.replace("\"Cl\"", "\"ejector\""), "`axis`"),
    ] {
        let file = format!("{name}.toml");
        std::fs::write(dir.path().join(&file), text).unwrap();
        for cmd in [
            vec!["simulate", "--extension", &file, "--out", "x.csv"],
            vec![
                "fit",
                "--extension",
                &file,
                "--generations",
                "2",
                "--out",
                "fit",
            ],
            vec!["diagnose", "--extension", &file, "--out", "diag"],
        ] {
            let out = sepval(&cmd, dir.path());
            assert!(!out.status.success(), "{name}: {cmd:?}");
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(err.contains(&file), "{name}: {err}");
            assert!(err.contains(needle), "{name}: {err}");
            assert!(!err.contains("panicked"), "{name}: {err}");
            for left in ["x.csv", "fit", "diag"] {
                assert!(
                    !dir.path().join(left).exists(),
                    "{name}: {left} left behind"
                );
            }
        }
    }
}

#[test]
fn an_extension_changes_the_simulation_and_fits_back() {
    let dir = tempfile::tempdir().unwrap();
    let ext = "format = \"sepval-extension/1\"\n\n[[term]]\naxis = \"CY\"\nfamily = \"step\"\nregressor = \"step\"\nt_on_s = 0.4\ncoefficient = 0.05\n";
    std::fs::write(dir.path().join("ext.toml"), ext).unwrap();
    ok(&sepval(
        &["simulate", "--factors", "truth", "--out", "plain.csv"],
        dir.path(),
    ));
    ok(&sepval(
        &[
            "simulate",
            "--factors",
            "truth",
            "--extension",
            "ext.toml",
            "--out",
            "ext.csv",
        ],
        dir.path(),
    ));
    let a = Trajectory::read(&dir.path().join("plain.csv")).unwrap();
    let b = Trajectory::read(&dir.path().join("ext.csv")).unwrap();
    let k = a.times_s.iter().position(|t| *t > 0.7).unwrap();
    assert!((a.pos_m[k][1] - b.pos_m[k][1]).abs() > 0.01);
    assert_eq!(a.pos_m[10], b.pos_m[10]);
}
