//! Issue 57 (hardening round five), items 7, 10, 12 and three of 14's messages: telemetry
//! metadata given twice with different values is refused naming both lines; a grid axis of one
//! point with LO != HI is refused; a directory left by an `--overwrite` run killed outright
//! says where the earlier run is and how to put it back, and a second `--overwrite` replaces it
//! properly; a flowfield excursion is said with its unit, shuffled table rows are said to be out
//! of order at their line, and a dangling or looping link given as `--out` is named as such.

use super::hardening_on_disk::fit;
use sepval_tests::{refused, sepval};

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
