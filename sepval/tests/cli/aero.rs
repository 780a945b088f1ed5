//! `sepval aero`: the estimate's directory from a store TOML, and bad input refused with a
//! message naming what and where, exit status 2, nothing written.

use std::path::Path;

use sepval_tests::{ok, refused, sepval};

fn example_store() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/geometry/store.toml")
        .display()
        .to_string()
}

#[test]
fn aero_writes_tables_daveml_and_a_summary() {
    let dir = tempfile::tempdir().unwrap();
    let store = example_store();
    let out = sepval(
        &[
            "aero",
            "--store-shape",
            &store,
            "--mach",
            "0.4:1.4:6",
            "--out",
            "est",
        ],
        dir.path(),
    );
    let said = ok(&out);
    assert!(
        said.contains("CN_alpha") && said.contains("wrote est"),
        "{said}"
    );
    let est = dir.path().join("est");
    let toml = std::fs::read_to_string(est.join("aero.toml")).unwrap();
    assert!(
        toml.contains("[aero]") && toml.contains("cm_q_per_rad"),
        "{toml}"
    );
    let dml = std::fs::read_to_string(est.join("store.dml")).unwrap();
    assert!(
        dml.contains("<DAVEfunc") && dml.contains("uncertainty"),
        "{}",
        &dml[..200]
    );
    assert!(est.join("summary.txt").is_file());
    // The directory is new: a second run is refused and leaves the first as it was.
    let again = sepval(
        &["aero", "--store-shape", &store, "--out", "est"],
        dir.path(),
    );
    refused(&again, "exists");
    assert_eq!(
        std::fs::read_to_string(est.join("aero.toml")).unwrap(),
        toml
    );
}

#[test]
fn aero_refuses_bad_input_naming_it_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let store = example_store();
    let bad_shape = dir.path().join("bad.toml");
    let text = std::fs::read_to_string(&store)
        .unwrap()
        .replace("count = 4", "count = 5");
    std::fs::write(&bad_shape, text).unwrap();
    let unknown = dir.path().join("unknown.toml");
    let text = std::fs::read_to_string(&store)
        .unwrap()
        .replace("[fins]", "[fins]\nsweep_deg = 3");
    std::fs::write(&unknown, text).unwrap();
    let cases: [(&[&str], &str); 5] = [
        (
            &["--store-shape", &store, "--mach", "0.3:5:3"],
            "--mach 0.3:5:3: outside",
        ),
        (
            &["--store-shape", &store, "--alpha-deg", "10:-10:3"],
            "--alpha-deg 10:-10:3: LO",
        ),
        (&["--store-shape", "missing.toml"], "missing.toml"),
        (
            &["--store-shape", bad_shape.to_str().unwrap()],
            "fins.count: 5 fins",
        ),
        (&["--store-shape", unknown.to_str().unwrap()], "sweep_deg"),
    ];
    for (args, expected) in cases {
        let mut all = vec!["aero"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["--out", "est"]);
        refused(&sepval(&all, dir.path()), expected);
        assert!(
            !dir.path().join("est").exists(),
            "{args:?} left a directory"
        );
    }
}
