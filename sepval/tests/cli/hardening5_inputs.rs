//! Issue 57 (hardening round five), items 7, 10, 12 and three of 14's messages: telemetry
//! metadata given twice with different values is refused naming both lines; a grid axis of one
//! point with LO != HI is refused; a directory left by an `--overwrite` run killed outright
//! says where the earlier run is and how to put it back, and a second `--overwrite` replaces it
//! properly; a flowfield excursion is said with its unit, shuffled table rows are said to be out
//! of order at their line, and a dangling or looping link given as `--out` is named as such.

use std::path::Path;

use super::hardening_on_disk::{fit, snapshot};
use sepval_tests::{ok, refused, sepval};

/// A telemetry file of 40 samples with `comments` above its header.
fn telemetry(comments: &str) -> String {
    let mut s = format!("{comments}t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n");
    for k in 0..40 {
        let t = f64::from(k) * 0.01;
        s.push_str(&format!("{t},0,0,{},0,{},0\n", 4.9 * t * t, 2.0 * t));
    }
    s
}

#[test]
fn metadata_given_twice_with_different_values_is_refused_naming_both_lines() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("twice.csv"),
        telemetry("# event = drop 3\n# mach = 1.2\n# alpha_deg = 2\n# mach = 0.6\n"),
    )
    .unwrap();
    let stderr = refused(
        &fit(d, "1", &["--data", "twice.csv", "--out", "F"]),
        "twice.csv: line 4: metadata `mach` is given twice with different values: `0.6` here, `1.2` at line 2",
    );
    assert!(!stderr.contains("defect"), "{stderr}");
    assert!(!d.join("F").exists());
}

#[test]
fn a_grid_axis_of_one_point_with_lo_below_hi_is_refused_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Refused as the flags are parsed: no --from needs to exist.
    let stderr = refused(
        &sepval(
            &[
                "envelope",
                "--mach",
                "0.6:1.2:1",
                "--from",
                "nowhere",
                "--aircraft",
                "a.toml",
                "--out",
                "E",
            ],
            d,
        ),
        "--mach",
    );
    assert!(
        stderr.contains(
            "N = 1 holds the axis at one value, so HI 1.2 would be dropped: give 0.6:0.6:1 to hold it at 0.6, or N of 2 or more to sweep from 0.6 to 1.2"
        ),
        "{stderr}"
    );
    assert!(!d.join("E").exists());
}

/// Turns the ended run in `f` into what a `fit --overwrite` killed outright (SIGKILL) after it
/// wrote its first checkpoint leaves: the earlier run moved whole into `f/.sepval-replaced`,
/// the killed run's marker without a manifest, one checkpoint of its own and its lock naming
/// a process that is gone.
fn kill_mid_overwrite(f: &Path) {
    let aside = f.join(".sepval-replaced");
    std::fs::create_dir(&aside).unwrap();
    for e in std::fs::read_dir(f).unwrap() {
        let name = e.unwrap().file_name();
        if name != ".sepval-replaced" {
            std::fs::rename(f.join(&name), aside.join(&name)).unwrap();
        }
    }
    std::fs::create_dir(f.join("generations")).unwrap();
    std::fs::copy(
        aside.join("generations/gen-0001.json"),
        f.join("generations/gen-0001.json"),
    )
    .unwrap();
    std::fs::write(
        f.join(".sepval-run"),
        "{\n  \"format\": \"sepval-run/2\",\n  \"command\": \"fit\"\n}\n",
    )
    .unwrap();
    std::fs::write(f.join(".sepval-lock"), "999999999\n").unwrap();
}

#[test]
fn after_a_killed_overwrite_every_message_names_the_earlier_run_and_overwrite_replaces_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&fit(d, "2", &["--out", "F"]));
    let earlier = snapshot(&d.join("F"));
    kill_mid_overwrite(&d.join("F"));
    let killed = snapshot(&d.join("F"));
    let put_back = "to put it back, remove everything in F but .sepval-replaced, then move what \
                    F/.sepval-replaced holds (its .sepval-run too) into F and remove it";
    // A fresh run, a resume of the killed run and the advice of each: where the earlier run is
    // and how to put it back, never `rm -r F`.
    for (extra, expected) in [
        (
            &[][..],
            "F is not empty: an --overwrite run of `fit` into it was killed before it ended, and the earlier run it was replacing is whole in F/.sepval-replaced; give --overwrite to discard the killed run and replace the earlier one",
        ),
        (
            &["--resume", "F/generations/gen-0001.json"][..],
            "not resuming in F: an --overwrite run of `fit` into it was killed before it ended, and the earlier run it was replacing is whole in F/.sepval-replaced; to resume the killed run, remove the earlier one first (rm -r F/.sepval-replaced)",
        ),
    ] {
        let stderr = refused(&fit(d, "2", &[&["--out", "F"], extra].concat()), expected);
        assert!(stderr.contains(put_back), "{stderr}");
        assert!(!stderr.contains("rm -r F "), "{stderr}");
        assert!(snapshot(&d.join("F")) == killed, "{extra:?}: F changed");
    }
    // A second --overwrite discards the killed run and replaces the earlier one.
    ok(&fit(d, "2", &["--out", "F", "--overwrite"]));
    let after = snapshot(&d.join("F"));
    assert!(!d.join("F/.sepval-replaced").exists());
    assert!(after.contains_key("result.json"), "{:?}", after.keys());
    let marker = String::from_utf8_lossy(&after[".sepval-run"]).into_owned();
    assert!(marker.contains("\"result.json\": \""), "{marker}");
    assert_eq!(
        after.keys().collect::<Vec<_>>(),
        earlier.keys().collect::<Vec<_>>()
    );
}

#[test]
fn a_flowfield_excursion_is_said_with_its_unit_and_shuffled_rows_by_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/flowfield-store");
    std::fs::copy(examples.join("grid.toml"), d.join("grid.toml")).unwrap();
    let grid = std::fs::read_to_string(examples.join("field-grid.csv")).unwrap();
    std::fs::write(d.join("field-grid.csv"), &grid).unwrap();
    let args = ["simulate", "--scenario", "grid.toml", "--strict-tables"];
    let stderr = refused(
        &sepval(&[&args[..], &["--out", "s.csv"]].concat(), d),
        "x_m by up to 2.27",
    );
    assert!(
        stderr.contains(" m beyond [-3, 3] m (nothing written)"),
        "{stderr}"
    );
    // Line 10 (the second row, z = 0.5) swapped with line 20 (y = 0): z seems to have one
    // breakpoint, but the rows are out of order, and that is what is said.
    let mut lines: Vec<&str> = grid.lines().collect();
    assert!(lines[9].starts_with("-3.0,-1.0,0.5,"), "{}", lines[9]);
    lines.swap(9, 19);
    std::fs::write(d.join("field-grid.csv"), lines.join("\n") + "\n").unwrap();
    let stderr = refused(
        &sepval(
            &["simulate", "--scenario", "grid.toml", "--out", "s.csv"],
            d,
        ),
        "field-grid.csv: line 10, column",
    );
    assert!(stderr.contains("the rows are out of order"), "{stderr}");
    assert!(!stderr.contains("has 1 breakpoint"), "{stderr}");
    assert!(!d.join("s.csv").exists());
}

#[test]
fn a_dangling_or_looping_link_as_out_is_named_and_not_written_through() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::os::unix::fs::symlink("nowhere", d.join("dangling")).unwrap();
    std::os::unix::fs::symlink("loop", d.join("loop")).unwrap();
    for (out, what) in [
        (
            "dangling",
            "dangling is a symbolic link to nowhere, which does not exist (a dangling link)",
        ),
        (
            "loop",
            "loop is a symbolic link that never resolves (a link loop)",
        ),
    ] {
        let stderr = refused(&fit(d, "1", &["--out", out]), what);
        assert!(
            stderr.contains("sepval will not write through it"),
            "{stderr}"
        );
        assert!(!stderr.contains("File exists"), "{stderr}");
    }
    assert!(!d.join("nowhere").exists());
}
