//! The store's aerodynamics as DAVE-ML end to end (docs/daveml.md): `scenario --to-daveml` and
//! `--from-daveml` round trip to the same simulation bytes, a file as another tool writes it
//! read with its map, and bad files refused (exit 2) with nothing written.

use std::path::{Path, PathBuf};

use sepval_tests::{ok, refused, sepval};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../daveml/tests/fixtures")
        .join(name)
}

/// The entries of `d`, sorted (to show that nothing, not even a temporary, was left).
fn entries(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn daveml_round_trip_simulates_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&sepval(
        &[
            "scenario",
            "--tables",
            "--interference-tables",
            "--out",
            "t",
        ],
        d,
    ));
    ok(&sepval(
        &[
            "scenario",
            "--scenario",
            "t/scenario.toml",
            "--to-daveml",
            "--out",
            "t.dml",
        ],
        d,
    ));
    let text = std::fs::read_to_string(d.join("t.dml")).unwrap();
    assert!(text.starts_with("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<DAVEfunc xmlns=\"http://daveml.org/2010/DAVEML\">"));
    assert!(text.contains("<checkData>"));
    // Read back into the scenario it came from (its store, flight and description).
    let said = ok(&sepval(
        &[
            "scenario",
            "--scenario",
            "t/scenario.toml",
            "--from-daveml",
            "t.dml",
            "--out",
            "back",
        ],
        d,
    ));
    assert!(said.contains("check outputs matched"), "{said}");
    assert!(d.join("back/tables/ca0.csv").exists());
    for (scenario, out) in [
        ("t/scenario.toml", "t.csv"),
        ("back/scenario.toml", "back.csv"),
    ] {
        ok(&sepval(
            &["simulate", "--scenario", scenario, "--out", out],
            d,
        ));
    }
    assert!(
        std::fs::read(d.join("t.csv")).unwrap() == std::fs::read(d.join("back.csv")).unwrap(),
        "the round trip changed the simulation (or the scenario's hash)"
    );
}

#[test]
fn daveml_from_another_tool_reads_with_its_map() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = fixture("other_tool.dml");
    let map = fixture("other_tool.toml");
    let out = sepval(
        &[
            "scenario",
            "--from-daveml",
            model.to_str().unwrap(),
            "--map",
            map.to_str().unwrap(),
            "--out",
            "store",
        ],
        d,
    );
    let said = ok(&out);
    assert!(said.contains("aero.cz, aero.cm, aero.cl_p_per_rad, interference.dcz0, aero.ca0 (9 check outputs matched)"), "{said}");
    let notes = String::from_utf8_lossy(&out.stderr);
    assert!(notes.contains("uniformPDF"), "{notes}");
    ok(&sepval(
        &[
            "simulate",
            "--scenario",
            "store/scenario.toml",
            "--out",
            "s.csv",
        ],
        d,
    ));
}

#[test]
fn daveml_bad_files_are_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("not.dml"), "alpha,CN\n0,0\n").unwrap();
    refused(
        &sepval(&["scenario", "--from-daveml", "not.dml", "--out", "x"], d),
        "not.dml: not XML: ",
    );
    let wrong = std::fs::read_to_string(fixture("other_tool.dml"))
        .unwrap()
        .replace(
            "<signalValue>-0.055</signalValue>",
            "<signalValue>-0.056</signalValue>",
        );
    std::fs::write(d.join("wrong.dml"), wrong).unwrap();
    let map = fixture("other_tool.toml");
    refused(
        &sepval(
            &[
                "scenario",
                "--from-daveml",
                "wrong.dml",
                "--map",
                map.to_str().unwrap(),
                "--out",
                "x",
            ],
            d,
        ),
        "wrong.dml line 112, <signal>: check case `inside`: Cm is -0.055 through the imported tables, -0.056 in the file",
    );
    refused(
        &sepval(&["scenario", "--from-daveml", "wrong.dml", "--out", "x"], d),
        "line 82, <independentVarRef>: the function's input `dist_ft` is not in the map",
    );
    // A gigabyte (sparse: no disk used) is refused by its size before it is read.
    std::fs::File::create(d.join("big.dml"))
        .unwrap()
        .set_len(1 << 30)
        .unwrap();
    refused(
        &sepval(&["scenario", "--from-daveml", "big.dml", "--out", "x"], d),
        "big.dml: the DAVE-ML file is 1073741824 bytes, more than the limit of 268435456 bytes",
    );
    assert_eq!(
        entries(d),
        ["big.dml", "not.dml", "wrong.dml"],
        "nothing written"
    );
    // An output directory that exists is never written into.
    std::fs::create_dir(d.join("x")).unwrap();
    ok(&sepval(&["scenario", "--to-daveml", "--out", "t.dml"], d));
    refused(
        &sepval(&["scenario", "--from-daveml", "t.dml", "--out", "x"], d),
        "exists; choose a new directory (nothing was written)",
    );
    assert!(entries(&d.join("x")).is_empty());
    // --map belongs to --from-daveml.
    let out = sepval(&["scenario", "--map", "m.toml", "--out", "y"], d);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        entries(d),
        ["big.dml", "not.dml", "t.dml", "wrong.dml", "x"]
    );
}

#[test]
fn daveml_entity_declarations_are_refused_before_parsing() {
    // An entity of 10 kB used 2000 times (20 MB once expanded; the review's 1 MB file expanded
    // to 4 GB and aborted): refused at its declaration with exit 2, nothing written.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let text = std::fs::read_to_string(fixture("other_tool.dml"))
        .unwrap()
        .replacen(
            "<DAVEfunc",
            &format!(
                "<!DOCTYPE DAVEfunc [<!ENTITY big \"{}\">]>\n<DAVEfunc",
                "x".repeat(10_000)
            ),
            1,
        )
        .replacen(
            "<fileVersion>Rev A",
            &format!("<fileVersion>{}", "&big;".repeat(2_000)),
            1,
        );
    std::fs::write(d.join("amp.dml"), text).unwrap();
    let map = fixture("other_tool.toml");
    let args = [
        "scenario",
        "--from-daveml",
        "amp.dml",
        "--map",
        map.to_str().unwrap(),
        "--out",
        "x",
    ];
    refused(
        &sepval(&args, d),
        "amp.dml line 7: the DOCTYPE declares the entity `big`: sepval reads DAVE-ML without entity declarations",
    );
    assert_eq!(entries(d), ["amp.dml"], "nothing written");
}
